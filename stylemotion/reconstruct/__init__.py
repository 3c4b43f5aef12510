"""Data-driven reconstruction on the motion database (Krüger §2.5.2, §4.2): full poses from a few markers, motion
completion and texturing."""

from stylemotion.reconstruct.markers import (
    DEFAULT_MARKERS,
    MarkerGapWarning,
    MarkerInputError,
    MarkerTracks,
    fill_gaps,
    read_markers,
    tracks_from_positions,
    write_marker_csv,
)
from stylemotion.reconstruct.sparse import (
    RECONSTRUCT_FEATURE_SETS,
    Reconstruction,
    SparseReconstructor,
    joint_errors_cm,
    marker_frames,
    reconstruct,
)
from stylemotion.reconstruct.texture import (
    LEG_JOINTS,
    MotionTexturer,
    TextureInputError,
    TextureResult,
    key_spline,
    texture_motion,
)

__all__ = [
    "LEG_JOINTS", "MotionTexturer", "TextureInputError", "TextureResult", "key_spline", "texture_motion",
    "DEFAULT_MARKERS", "MarkerGapWarning", "MarkerInputError", "MarkerTracks", "RECONSTRUCT_FEATURE_SETS",
    "Reconstruction", "SparseReconstructor", "fill_gaps", "joint_errors_cm", "marker_frames", "read_markers",
    "reconstruct", "tracks_from_positions", "write_marker_csv",
]
