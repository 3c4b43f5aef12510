"""Data-driven reconstruction on the motion database (Krüger §2.5.2, §4.2, §4.3): full poses from a few markers,
motion completion and texturing, motion from a few keyframes (dynamic motion graphs)."""

from stylemotion.reconstruct.keyframes import (
    DynamicMotionGraph,
    FarKeyframeWarning,
    Keyframe,
    KeyframeError,
    KeyframeResult,
    NoConnectionError,
    keys_from_motion,
)
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
    "DynamicMotionGraph", "FarKeyframeWarning", "Keyframe", "KeyframeError", "KeyframeResult", "NoConnectionError",
    "keys_from_motion",
    "LEG_JOINTS", "MotionTexturer", "TextureInputError", "TextureResult", "key_spline", "texture_motion",
    "DEFAULT_MARKERS", "MarkerGapWarning", "MarkerInputError", "MarkerTracks", "RECONSTRUCT_FEATURE_SETS",
    "Reconstruction", "SparseReconstructor", "fill_gaps", "joint_errors_cm", "marker_frames", "read_markers",
    "reconstruct", "tracks_from_positions", "write_marker_csv",
]
