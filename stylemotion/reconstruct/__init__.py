"""Data-driven reconstruction on the motion database (Krüger §2.5.2, §4.2, §4.3): full poses from a few markers,
motion completion and texturing, motion from a few keyframes (dynamic motion graphs).

The names below load from their submodules on first use (PEP 562, :func:`stylemotion.lazy_exports`), so a light
submodule of the package loads without the heavy ones.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from stylemotion import lazy_exports

if TYPE_CHECKING:
    from stylemotion.reconstruct.capture import read_c3d, read_capture, resample_tracks
    from stylemotion.reconstruct.keyframes import (
        DynamicMotionGraph,
        FarKeyframeWarning,
        Keyframe,
        KeyframeError,
        KeyframeResult,
        NoConnectionError,
        keys_from_motion,
    )
    from stylemotion.reconstruct.marker_set import SKIN_MARKERS, MarkerSet, SkinMarker, virtual_markers
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
    from stylemotion.reconstruct.subject import Subject, subject_from_motion
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
    "SKIN_MARKERS", "MarkerSet", "SkinMarker", "virtual_markers", "read_c3d", "read_capture", "resample_tracks",
    "Subject", "subject_from_motion",
]

__getattr__, __dir__ = lazy_exports(__name__, {
    "DynamicMotionGraph": "keyframes",
    "FarKeyframeWarning": "keyframes",
    "Keyframe": "keyframes",
    "KeyframeError": "keyframes",
    "KeyframeResult": "keyframes",
    "NoConnectionError": "keyframes",
    "keys_from_motion": "keyframes",
    "DEFAULT_MARKERS": "markers",
    "MarkerGapWarning": "markers",
    "MarkerInputError": "markers",
    "MarkerTracks": "markers",
    "fill_gaps": "markers",
    "read_markers": "markers",
    "tracks_from_positions": "markers",
    "write_marker_csv": "markers",
    "SKIN_MARKERS": "marker_set",
    "MarkerSet": "marker_set",
    "SkinMarker": "marker_set",
    "virtual_markers": "marker_set",
    "read_c3d": "capture",
    "read_capture": "capture",
    "resample_tracks": "capture",
    "Subject": "subject",
    "subject_from_motion": "subject",
    "RECONSTRUCT_FEATURE_SETS": "sparse",
    "Reconstruction": "sparse",
    "SparseReconstructor": "sparse",
    "joint_errors_cm": "sparse",
    "marker_frames": "sparse",
    "reconstruct": "sparse",
    "LEG_JOINTS": "texture",
    "MotionTexturer": "texture",
    "TextureInputError": "texture",
    "TextureResult": "texture",
    "key_spline": "texture",
    "texture_motion": "texture",
})
