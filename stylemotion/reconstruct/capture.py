"""Marker tracks of a skin-marker set from a capture: a C3D file, a CSV at any frame rate, or a complete motion
(BVH, NPZ) on which the set's markers are put virtually — resampled to the database's rate.

C3D files are read with ``ezc3d`` (``POINT:LABELS``, ``POINT:RATE``, ``POINT:UNITS``; a point whose residual is
negative or whose coordinates are NaN is a gap). Units become metres (mm, cm, m), the file's up axis (``z`` for
most capture systems, ``y``) becomes Y up. ``names`` maps a set's marker to the file's label (default: the same
name, matched without case and without a ``Subject:`` prefix). Gaps are filled as
:func:`stylemotion.reconstruct.markers.fill_gaps` fills them (a warning naming marker and frames; a gap at an end
is an error naming marker and frame). Format details: docs/reconstruct.md.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from stylemotion.reconstruct.marker_set import MarkerSet, virtual_markers
from stylemotion.reconstruct.markers import (
    MarkerInputError,
    MarkerTracks,
    fill_gaps,
    read_marker_csv,
    read_markers,
)
from stylemotion.skeleton import CANONICAL_JOINTS

#: Largest C3D file read, bytes (ezc3d holds all of it in memory as float64).
MAX_C3D_BYTES = 256 * 2**20
#: Largest number of points and of frames a C3D may declare.
MAX_C3D_POINTS, MAX_C3D_FRAMES = 1000, 2_000_000
_UNITS = {"mm": 0.001, "cm": 0.01, "m": 1.0}
#: Suffixes :func:`read_capture` reads.
CAPTURE_FORMATS = (".c3d", ".csv", ".bvh", ".npz")


def _label(text: str) -> str:
    return text.strip().rpartition(":")[2].strip().lower()


def _column_of(labels: list[str], marker: str, names: Mapping[str, str] | None, path: Path) -> int:
    wanted = (names or {}).get(marker, marker)
    found = [i for i, label in enumerate(labels) if _label(label) == _label(wanted)]
    if not found:
        raise MarkerInputError(f"{path}: marker {marker}: no point labelled {wanted!r} (labels: {labels[:12]}"
                               f"{'…' if len(labels) > 12 else ''}); map it with names={{{marker}: <label>}}")
    if len(found) > 1:
        raise MarkerInputError(f"{path}: marker {marker}: {len(found)} points are labelled {wanted!r}")
    return found[0]


def _parameter(c3d, group: str, name: str, path: Path):
    try:
        return c3d["parameters"][group][name]["value"]
    except (KeyError, TypeError):
        raise MarkerInputError(f"{path}: no {group}:{name} parameter") from None


def read_c3d(path: str | Path, marker_set: MarkerSet, names: Mapping[str, str] | None = None,
             up_axis: str = "z") -> MarkerTracks:
    """The markers of ``marker_set`` from a C3D file at its own rate → :class:`MarkerTracks` (metres, Y up).

    Raises:
        MarkerInputError: a missing, oversized or unreadable file, an unknown unit or axis, a marker without a
            point, a point that is never tracked or missing at an end (naming file, marker and frame).
    """
    path = Path(path)
    if up_axis not in ("y", "z"):
        raise MarkerInputError(f"{path}: up_axis={up_axis!r} must be 'y' or 'z'")
    if not path.is_file():
        raise MarkerInputError(f"markers={path}: no such file")
    size = path.stat().st_size
    if size > MAX_C3D_BYTES:
        raise MarkerInputError(f"{path}: {size:,} bytes, more than the {MAX_C3D_BYTES:,} a C3D may have here")
    import ezc3d

    try:
        c3d = ezc3d.c3d(str(path), extract_forceplat_data=False)
    except (RuntimeError, ValueError, OSError, IndexError) as exc:
        raise MarkerInputError(f"{path}: not a readable C3D file ({str(exc).strip() or type(exc).__name__})") \
            from None
    labels = [str(s) for s in _parameter(c3d, "POINT", "LABELS", path)]
    rate = float(np.asarray(_parameter(c3d, "POINT", "RATE", path)).reshape(-1)[0])
    units = [str(u) for u in np.atleast_1d(_parameter(c3d, "POINT", "UNITS", path))]
    unit = units[0].strip().lower() if units else "mm"
    if unit not in _UNITS:
        raise MarkerInputError(f"{path}: POINT:UNITS {unit!r} is not one of {list(_UNITS)}")
    if not (np.isfinite(rate) and rate > 0):
        raise MarkerInputError(f"{path}: POINT:RATE {rate} must be a positive number")
    points = np.asarray(c3d["data"]["points"], dtype=np.float64)  # (4, points, frames)
    if points.ndim != 3 or points.shape[0] < 3 or points.shape[1] != len(labels):
        raise MarkerInputError(f"{path}: points {points.shape} do not match the {len(labels)} POINT:LABELS")
    if points.shape[1] > MAX_C3D_POINTS or points.shape[2] > MAX_C3D_FRAMES or points.shape[2] < 1:
        raise MarkerInputError(f"{path}: {points.shape[1]} points × {points.shape[2]} frames; at most "
                               f"{MAX_C3D_POINTS} × {MAX_C3D_FRAMES} and at least one frame")
    columns = [_column_of(labels, m, names, path) for m in marker_set.names]
    xyz = np.moveaxis(points[:3, columns], 0, -1).copy()  # (markers, frames, 3)
    residuals = c3d["data"].get("meta_points", {}).get("residuals") if isinstance(c3d["data"], dict) else None
    if residuals is not None:
        residuals = np.asarray(residuals, dtype=np.float64).reshape(-1, points.shape[1], points.shape[2])[0]
        xyz[residuals[columns] < 0] = np.nan
    from stylemotion.datasets.canonical import UP_TO_Y

    positions = np.swapaxes(xyz, 0, 1) * _UNITS[unit] @ UP_TO_Y[up_axis].T
    first = int(np.asarray(c3d["header"]["points"].get("first_frame", 0)))
    filled_positions, filled = fill_gaps(positions, marker_set.names, str(path), first)
    return MarkerTracks(marker_set.names, filled_positions, rate, str(path), None, filled)


def resample_tracks(tracks: MarkerTracks, fps: float) -> MarkerTracks:
    """``tracks`` at ``fps`` (linear interpolation in time over the same span; unchanged at the same rate).
    ``full`` (complete motions) is resampled alike."""
    if abs(tracks.fps - fps) < 1e-9 * fps or tracks.num_frames < 2:
        return MarkerTracks(tracks.joints, tracks.positions, float(fps), tracks.source, tracks.full, tracks.filled)
    from scipy.interpolate import interp1d

    times = np.arange(tracks.num_frames) / tracks.fps
    new = np.arange(int(np.floor(times[-1] * fps + 1e-6)) + 1) / fps

    def at(values: np.ndarray | None) -> np.ndarray | None:
        return None if values is None else interp1d(times, values, axis=0, assume_sorted=True)(new)

    return MarkerTracks(tracks.joints, at(tracks.positions), float(fps), tracks.source, at(tracks.full),
                        tracks.filled)


def tracks_on_motion(positions: np.ndarray, marker_set: MarkerSet, fps: float, source: str = "motion"
                     ) -> MarkerTracks:
    """The set's virtual markers on a complete motion ``(frames, 21, 3)`` metres (``full`` kept for errors)."""
    positions = np.asarray(positions, dtype=np.float64)
    if positions.ndim != 3 or positions.shape[1:] != (len(CANONICAL_JOINTS), 3) or not np.isfinite(positions).all():
        raise MarkerInputError(f"{source}: a complete motion must be finite (frames, {len(CANONICAL_JOINTS)}, 3), "
                               f"got {positions.shape}")
    return MarkerTracks(marker_set.names, virtual_markers(positions, marker_set), float(fps), source, positions, {})


def read_capture(path: str, marker_set: MarkerSet, fps: float, *, names: Mapping[str, str] | None = None,
                 up_axis: str | None = None, capture_fps: float | None = None,
                 conversion: Mapping | None = None) -> MarkerTracks:
    """Tracks of ``marker_set``'s markers from ``path``, at ``fps`` (the database's rate).

    ``.c3d``: :func:`read_c3d` (``up_axis`` default ``z``). ``.csv``: columns ``<marker>_x,_y,_z`` in metres, Y up,
    at its ``# fps:`` line's rate or ``capture_fps`` (default ``fps``). ``.bvh``/``.npz``: a complete motion
    (``conversion`` as for :func:`~stylemotion.reconstruct.markers.read_markers`), the markers put on it
    virtually (:func:`tracks_on_motion`).
    """
    text = str(path)
    suffix = Path(text.split("::")[0]).suffix.lower()
    if suffix not in CAPTURE_FORMATS and ":" in Path(text).name:
        suffix = Path(text.rpartition(":")[0]).suffix.lower()
    if suffix == ".c3d":
        tracks = read_c3d(text, marker_set, names, up_axis or "z")
    elif suffix == ".csv":
        file = Path(text)
        if not file.is_file():
            raise MarkerInputError(f"markers={text}: no such file")
        tracks = read_marker_csv(file, marker_set.names, capture_fps or fps, valid=marker_set.names)
    elif suffix in (".bvh", ".npz") or "::" in text:
        full = read_markers(text, CANONICAL_JOINTS, fps, dict(conversion or {}))
        return tracks_on_motion(full.positions, marker_set, full.fps, full.source)
    else:
        raise MarkerInputError(f"markers={text}: the file must end in one of {list(CAPTURE_FORMATS)}")
    return resample_tracks(tracks, fps)
