"""Marker sets and marker tracks for reconstruction from sparse markers (Krüger §2.5.2).

A marker is a canonical joint (:data:`stylemotion.skeleton.CANONICAL_JOINTS`) whose position is known per
frame. Tracks are read from

* a BVH (any skeleton a joint map names), converted as datasets convert theirs
  (:func:`stylemotion.datasets.user_motion.convert_example`); the markers are its canonical joints;
* an NPZ as ``stylemotion-convert`` writes it: ``positions`` ``(frames, 21, 3)`` metres, ``fps``,
  ``joint_names``;
* a CSV of marker tracks (:func:`write_marker_csv` writes one)::

      # fps: 30
      frame,Hand_L_x,Hand_L_y,Hand_L_z,Hips_x,Hips_y,Hips_z
      0,0.31,0.92,0.05,0.00,0.95,0.00
      1,,,,0.00,0.95,0.01

  metres, Y up, one row per frame (``frame``: whole numbers, increasing; a missing row or an empty or
  ``nan`` cell is a gap), the optional ``# fps:`` first line giving the rate (else the caller's).

Gaps (NaN) with a tracked frame on both sides are filled by linear interpolation, with a
:class:`MarkerGapWarning` naming the joint and the frames; a gap at the start or end of a track cannot be
filled and raises :class:`MarkerInputError` naming the joint and frame.
"""

from __future__ import annotations

import csv
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stylemotion.io.errors import UserInputError
from stylemotion.io.npzfile import NpzFileError, load_npz
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX

#: Table 2.3's six markers: the 4 end effectors (wrists, ankles), the head and the root.
DEFAULT_MARKERS = ("Hand_L", "Hand_R", "Foot_L", "Foot_R", "Head", "Hips")
#: File suffixes :func:`read_markers` reads.
MARKER_FORMATS = (".bvh", ".npz", ".csv")
#: Largest marker CSV read, bytes.
MAX_CSV_BYTES = 512 * 2**20


class MarkerInputError(UserInputError, ValueError):
    """Marker input that cannot be used; the message names the joint, frame, column or value."""


class MarkerGapWarning(UserWarning):
    """Gaps in a marker track were filled by linear interpolation (the message names joint and frames)."""


def check_joint_names(joints: Sequence[str], what: str, error: type[ValueError], empty: str) -> tuple[str, ...]:
    """Canonical joint names as a tuple; ``error`` for none (message ``empty``), a repeat, or a name not on the
    skeleton, each message calling the names ``what`` (e.g. ``marker``)."""
    names = tuple(str(j) for j in joints)
    if not names:
        raise error(empty)
    for name in names:
        if name not in JOINT_INDEX:
            raise error(f"{what} {name!r} is not a joint of the canonical skeleton; valid: {list(CANONICAL_JOINTS)}")
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise error(f"{what}(s) {repeated} named more than once")
    return names


def check_marker_names(joints: Sequence[str]) -> tuple[str, ...]:
    """The marker names as a tuple; MarkerInputError for none, a repeat, or a name not on the skeleton."""
    return check_joint_names(joints, "marker", MarkerInputError,
                             "the marker set is empty; name at least one canonical joint")


@dataclass(frozen=True)
class MarkerTracks:
    """Marker positions of a motion.

    Attributes:
        joints: marker names (canonical joints).  positions: ``(frames, markers, 3)`` float64 metres, Y up,
        gaps filled.  fps: frames per second.  source: where they came from.  full: ``(frames, 21, 3)``
        all joints when the input was a complete motion (BVH, NPZ), for error figures; else None.
        filled: joint → the frames that were filled by interpolation.
    """

    joints: tuple[str, ...]
    positions: np.ndarray
    fps: float
    source: str = ""
    full: np.ndarray | None = None
    filled: dict[str, list[int]] | None = None

    @property
    def num_frames(self) -> int:
        return int(self.positions.shape[0])


def _runs(frames: np.ndarray) -> str:
    """Frame numbers as ``a-b`` runs: ``[3, 4, 5, 9]`` → ``"3-5, 9"``."""
    parts, start = [], None
    for i, f in enumerate(frames):
        start = f if start is None else start
        if i + 1 == len(frames) or frames[i + 1] != f + 1:
            parts.append(f"{start}" if start == f else f"{start}-{f}")
            start = None
    return ", ".join(parts)


def fill_gaps(positions: np.ndarray, joints: Sequence[str], source: str = "markers",
              first_frame: int = 0) -> tuple[np.ndarray, dict[str, list[int]]]:
    """Fill NaN gaps of marker tracks by linear interpolation between the tracked frames around them.

    Args:
        positions: ``(frames, markers, 3)`` metres; a frame of a marker is missing when any coordinate is NaN.
        joints: marker names, for messages.  source, first_frame: named in messages (frame numbers are
            ``first_frame + index``).

    Returns:
        The filled ``(frames, markers, 3)`` float64 and joint → filled frame indices (warned as
        :class:`MarkerGapWarning`).

    Raises:
        MarkerInputError: an infinite value, or a gap at a track's start or end (no neighbour on one side).
    """
    out = np.array(positions, dtype=np.float64)
    if out.ndim != 3 or out.shape[1:] != (len(joints), 3) or out.shape[0] < 1:
        raise MarkerInputError(f"{source}: marker positions must be (frames ≥ 1, {len(joints)}, 3), got {out.shape}")
    filled: dict[str, list[int]] = {}
    for m, joint in enumerate(joints):
        bad = np.isinf(out[:, m]).any(axis=1)
        if bad.any():
            raise MarkerInputError(f"{source}: marker {joint} is infinite at frame {first_frame + int(np.argmax(bad))}")
        missing = np.isnan(out[:, m]).any(axis=1)
        if not missing.any():
            continue
        known = np.flatnonzero(~missing)
        if known.size == 0:
            raise MarkerInputError(f"{source}: marker {joint} has no tracked frame at all")
        gaps = np.flatnonzero(missing)
        edge = gaps[(gaps < known[0]) | (gaps > known[-1])]
        if edge.size:
            raise MarkerInputError(f"{source}: marker {joint} is missing at frame {first_frame + int(edge[0])} "
                                   f"(frames {_runs(first_frame + edge)}), with no tracked frame on one side to "
                                   f"interpolate from")
        for axis in range(3):
            out[gaps, m, axis] = np.interp(gaps, known, out[known, m, axis])
        filled[joint] = [int(first_frame + g) for g in gaps]
        warnings.warn(f"{source}: marker {joint} missing at frames {_runs(first_frame + gaps)}; filled by linear "
                      f"interpolation", MarkerGapWarning, stacklevel=2)
    return out, filled


def tracks_from_positions(positions: np.ndarray, joints: Sequence[str], fps: float, source: str = "motion",
                          ) -> MarkerTracks:
    """The markers ``joints`` of a complete motion ``(frames, 21, 3)`` metres (``full`` kept when finite)."""
    joints = check_marker_names(joints)
    positions = np.asarray(positions, dtype=np.float64)
    if positions.ndim != 3 or positions.shape[1:] != (len(CANONICAL_JOINTS), 3):
        raise MarkerInputError(f"{source}: positions must be (frames, {len(CANONICAL_JOINTS)}, 3), "
                               f"got {positions.shape}")
    picked, filled = fill_gaps(positions[:, [JOINT_INDEX[j] for j in joints]], joints, source)
    full = positions if np.all(np.isfinite(positions)) else None
    return MarkerTracks(joints, picked, float(fps), source, full, filled)


def _read_npz(path: Path, joints: Sequence[str]) -> MarkerTracks:
    try:
        npz = load_npz(path, "marker NPZ")
    except NpzFileError as exc:
        raise MarkerInputError(str(exc)) from None
    try:
        positions, fps = np.asarray(npz["positions"]), float(npz["fps"])
        names = [str(n) for n in np.asarray(npz["joint_names"]).reshape(-1)] if "joint_names" in npz \
            else list(CANONICAL_JOINTS)
    except (TypeError, ValueError, KeyError) as exc:
        raise MarkerInputError(f"{path}: not an NPZ with 'positions' and 'fps' ({exc})") from None
    if names != list(CANONICAL_JOINTS):
        raise MarkerInputError(f"{path}: joint_names are not the canonical joints (got {names[:4]}…)")
    if not fps > 0:
        raise MarkerInputError(f"{path}: fps={fps} must be positive")
    return tracks_from_positions(positions, joints, fps, str(path))


def _read_bvh(text: str, joints: Sequence[str], fps: float, conversion: dict | None) -> MarkerTracks:
    from stylemotion.datasets.loading import ConversionSettings
    from stylemotion.datasets.user_motion import UserMotionError, convert_example, parse_example

    try:
        spec = parse_example(text, key="markers")
        settings = ConversionSettings(fps=fps, **{k: v for k, v in (conversion or {}).items() if v is not None})
        example = convert_example(spec, settings)
    except UserMotionError as exc:
        raise MarkerInputError(str(exc)) from None
    return tracks_from_positions(example.positions, joints, example.fps, text)


def _float(cell: str, path: Path, row: int, column: str) -> float:
    cell = cell.strip()
    if cell == "" or cell.lower() == "nan":
        return float("nan")
    try:
        return float(cell)
    except ValueError:
        raise MarkerInputError(f"{path}: line {row}, column {column}: {cell!r} is not a number") from None


def _csv_header(path: Path, header: list[str], valid: Sequence[str] | None = None) -> list[str]:
    """The marker names of a CSV header ``frame,<joint>_x,<joint>_y,<joint>_z,...`` (canonical joints, or any of
    ``valid`` when given)."""
    if not header or header[0].strip() != "frame" or (len(header) - 1) % 3:
        raise MarkerInputError(f"{path}: the header must be frame,<joint>_x,<joint>_y,<joint>_z,…, got {header[:4]}")
    names = []
    for c in range(1, len(header), 3):
        cols = [h.strip() for h in header[c:c + 3]]
        joint = cols[0][:-2]
        if [col[-2:] for col in cols] != ["_x", "_y", "_z"] or cols[1][:-2] != joint or cols[2][:-2] != joint:
            raise MarkerInputError(f"{path}: columns {cols} must be <joint>_x,<joint>_y,<joint>_z")
        names.append(joint)
    if valid is None:
        return list(check_marker_names(names))
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise MarkerInputError(f"{path}: marker(s) {repeated} have more than one set of columns")
    return names


def read_marker_csv(path: Path, joints: Sequence[str] | None, fps: float,
                    valid: Sequence[str] | None = None) -> MarkerTracks:
    """Marker tracks of a CSV (module docstring); ``joints``: the markers to keep (None: all); ``valid``: the
    marker names allowed besides canonical joints' (a skin-marker set's; columns of other names are ignored)."""
    if path.stat().st_size > MAX_CSV_BYTES:
        raise MarkerInputError(f"{path}: {path.stat().st_size:,} bytes, more than the {MAX_CSV_BYTES:,} a marker "
                               f"CSV may have")
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise MarkerInputError(f"{path}: cannot read this marker CSV ({exc})") from None
    if lines and lines[0].startswith("#"):
        comment = lines.pop(0).lstrip("#").strip()
        key, _, value = comment.partition(":")
        if key.strip() == "fps":
            fps = _float(value, path, 1, "fps")
            if not fps > 0:
                raise MarkerInputError(f"{path}: line 1: fps {value.strip()!r} must be a positive number")
    rows = list(csv.reader(lines))
    if len(rows) < 2:
        raise MarkerInputError(f"{path}: no marker rows")
    names = _csv_header(path, rows[0], valid)
    if joints is not None:
        wanted = check_marker_names(joints) if valid is None else tuple(joints)
    else:
        wanted = tuple(names)
    absent = [j for j in wanted if j not in names]
    if absent:
        raise MarkerInputError(f"{path}: no columns for marker(s) {absent}; the file has {names}")
    frames, values = [], []
    for r, row in enumerate(rows[1:], start=2):
        if len(row) != len(rows[0]):
            raise MarkerInputError(f"{path}: line {r} has {len(row)} cells, the header {len(rows[0])}")
        f = _float(row[0], path, r, "frame")
        if not (np.isfinite(f) and f == int(f) and f >= 0):
            raise MarkerInputError(f"{path}: line {r}: frame {row[0]!r} must be a whole number ≥ 0")
        if frames and f <= frames[-1]:
            raise MarkerInputError(f"{path}: line {r}: frame {int(f)} does not follow frame {frames[-1]}")
        if len(frames) and f - frames[0] > 10 * len(rows) + 1000:
            raise MarkerInputError(f"{path}: line {r}: frame {int(f)} leaves a gap of more than ten times the file's "
                                   f"{len(rows) - 1} rows after frame {frames[0]}")
        frames.append(int(f))
        values.append([_float(cell, path, r, rows[0][c]) for c, cell in enumerate(row[1:], start=1)])
    table = np.full((frames[-1] - frames[0] + 1, len(names), 3), np.nan)
    table[np.asarray(frames) - frames[0]] = np.asarray(values).reshape(len(frames), len(names), 3)
    picked = table[:, [names.index(j) for j in wanted]]
    positions, filled = fill_gaps(picked, wanted, str(path), frames[0])
    return MarkerTracks(wanted, positions, float(fps), str(path), None, filled)


def read_markers(path: str | Path, joints: Sequence[str] | None = None, fps: float = 30.0,
                 conversion: dict | None = None) -> MarkerTracks:
    """Marker tracks of a BVH (``file.bvh[:start-end]``, also ``archive.zip::member.bvh``), NPZ or CSV file.

    Args:
        path: the file (module docstring for the formats).
        joints: the markers; None = :data:`DEFAULT_MARKERS` (BVH, NPZ) or every marker of the CSV.
        fps: the rate a BVH is converted to, and a CSV's rate when it has no ``# fps:`` line.
        conversion: ``joint_map``, ``unit_scale``, ``up_axis`` for a BVH (as ``stylemotion-search``'s).

    Raises:
        MarkerInputError: an unknown marker name, a missing file or column, a bad cell, an unfillable gap.
    """
    text = str(path)
    file = Path(text.split("::")[0]) if "::" in text else Path(text)
    suffix = file.suffix.lower()
    if suffix not in MARKER_FORMATS and ":" in file.name and "::" not in text:
        suffix = Path(text.rpartition(":")[0]).suffix.lower()  # file.bvh:start-end
    if suffix not in MARKER_FORMATS and "::" not in text:
        raise MarkerInputError(f"markers={text}: the file must end in one of {list(MARKER_FORMATS)}")
    if suffix == ".bvh" or "::" in text:
        return _read_bvh(text, DEFAULT_MARKERS if joints is None else joints, fps, conversion)
    if not file.is_file():
        raise MarkerInputError(f"markers={text}: no such file")
    if suffix == ".npz":
        return _read_npz(file, DEFAULT_MARKERS if joints is None else joints)
    return read_marker_csv(file, joints, fps)


def write_marker_csv(path: str | Path, joints: Sequence[str], positions: np.ndarray, fps: float) -> Path:
    """Write marker tracks ``(frames, markers, 3)`` metres as the CSV :func:`read_markers` reads (NaN → empty)."""
    joints = check_marker_names(joints)
    positions = np.asarray(positions, dtype=np.float64)
    header = ["frame"] + [f"{j}_{a}" for j in joints for a in "xyz"]
    lines = [f"# fps: {fps:g}", ",".join(header)]
    for f, frame in enumerate(positions.reshape(len(positions), -1)):
        lines.append(",".join([str(f)] + ["" if np.isnan(v) else f"{v:.6f}" for v in frame]))
    path = Path(path)
    path.write_text("\n".join(lines) + "\n")
    return path
