"""Skin-marker sets: markers stuck on body segments at an offset from a joint, as a capture system gives them.

A :class:`SkinMarker` is attached to the segment that ends at a canonical joint (its ``segment``) with an
``offset`` (metres) in that segment's local frame (:func:`segment_frames`):

* origin: the joint;
* ``y``: along the bone from the joint's parent to the joint (Hips: from Hips to Spine), i.e. distal;
* ``x``: the body's left (``UpperLeg_L − UpperLeg_R`` for the hips and legs, ``UpperArm_L − UpperArm_R``
  for the spine, head and arms), made orthogonal to ``y``;
* ``z = x × y``: forward for a segment that points up (hips, head), backward for one that points down
  (a hanging forearm or a shank).

Frames come from joint positions alone, so the same markers can be put on any skeleton the project converts
(the database's motions and a query's alike: k-NN compares like with like). Specification of the default set
and of the CSV format of a user's set: docs/reconstruct.md.
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stylemotion.reconstruct.markers import MarkerInputError
from stylemotion.skeleton import CANONICAL_JOINTS, CANONICAL_PARENTS, JOINT_INDEX

_EPS = 1e-9
_LOWER = {"Hips", "UpperLeg_L", "LowerLeg_L", "Foot_L", "Toes_L", "UpperLeg_R", "LowerLeg_R", "Foot_R", "Toes_R"}
#: Largest marker set :func:`read_marker_set` reads (rows).
MAX_MARKERS = 200


@dataclass(frozen=True)
class SkinMarker:
    """A marker ``name`` on the segment ending at joint ``segment``, ``offset`` ``(3,)`` metres in its frame."""

    name: str
    segment: str
    offset: tuple[float, float, float]


@dataclass(frozen=True)
class MarkerSet:
    """Named skin markers; :attr:`is_joint_centres` when every offset is zero and each marker is named after its
    joint (the markers are then the joint centres, as before skin markers existed)."""

    name: str
    markers: tuple[SkinMarker, ...]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(m.name for m in self.markers)

    @property
    def segments(self) -> tuple[str, ...]:
        return tuple(m.segment for m in self.markers)

    @property
    def offsets(self) -> np.ndarray:
        """``(markers, 3)`` metres."""
        return np.array([m.offset for m in self.markers], dtype=np.float64).reshape(-1, 3)

    @property
    def is_joint_centres(self) -> bool:
        return all(m.name == m.segment and not any(m.offset) for m in self.markers)

    def describe(self) -> list[dict]:
        """JSON-ready description (name, segment, offset in metres)."""
        return [{"name": m.name, "segment": m.segment, "offset_m": list(m.offset)} for m in self.markers]


def joint_marker_set(joints: Sequence[str]) -> MarkerSet:
    """Markers at the joint centres ``joints`` (zero offsets)."""
    return MarkerSet("joints", tuple(SkinMarker(j, j, (0.0, 0.0, 0.0)) for j in joints))


#: The default skin-marker set: a sparse layout like Table 2.3's six markers, each a few cm off its joint
#: (wrists' lateral side, lateral malleoli, top of the head, sacrum). Offsets in the segment frame (module
#: docstring): x = left, y = along the bone (distal), z = x × y.
SKIN_MARKERS = MarkerSet("skin", (
    SkinMarker("LWRI", "Hand_L", (0.03, 0.0, 0.0)),
    SkinMarker("RWRI", "Hand_R", (-0.03, 0.0, 0.0)),
    SkinMarker("LANK", "Foot_L", (0.04, 0.0, 0.0)),
    SkinMarker("RANK", "Foot_R", (-0.04, 0.0, 0.0)),
    SkinMarker("HEAD", "Head", (0.0, 0.08, 0.0)),
    SkinMarker("SACR", "Hips", (0.0, 0.0, -0.08)),
))
#: Names ``marker_set=`` takes besides a CSV file.
NAMED_MARKER_SETS = ("joints", "skin")


def _unit(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    norm = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(norm, _EPS), norm[..., 0]


def segment_frames(positions: np.ndarray, segments: Sequence[str]) -> np.ndarray:
    """The local frame of each segment (module docstring) in each frame.

    Args:
        positions: ``(frames, 21, 3)`` canonical joint positions, metres, Y up.  segments: canonical joints.

    Returns:
        ``(frames, len(segments), 3, 3)`` rotations; columns x, y, z in world coordinates.
    """
    p = np.asarray(positions, dtype=np.float64)
    out = np.empty(p.shape[:1] + (len(segments), 3, 3))
    left_lower = p[:, JOINT_INDEX["UpperLeg_L"]] - p[:, JOINT_INDEX["UpperLeg_R"]]
    left_upper = p[:, JOINT_INDEX["UpperArm_L"]] - p[:, JOINT_INDEX["UpperArm_R"]]
    for s, name in enumerate(segments):
        j = JOINT_INDEX[name]
        parent = CANONICAL_PARENTS[j]
        bone = p[:, JOINT_INDEX["Spine"]] - p[:, j] if parent < 0 else p[:, j] - p[:, parent]
        y, length = _unit(bone)
        y[length < _EPS] = (0.0, 1.0, 0.0)  # a zero-length bone (a clavicle on the chest): upright
        left = left_lower if name in _LOWER else left_upper
        x = left - np.sum(left * y, axis=-1, keepdims=True) * y
        x, size = _unit(x)
        flat = size < 1e-6  # the bone points left or right: take the world's forward for z instead
        if flat.any():
            z_ref = np.broadcast_to(np.array([0.0, 0.0, 1.0]), y[flat].shape)
            x[flat] = _unit(np.cross(y[flat], z_ref))[0]
        z = np.cross(x, y)
        out[:, s] = np.stack([x, y, z], axis=-1)
    return out


def virtual_markers(positions: np.ndarray, marker_set: MarkerSet) -> np.ndarray:
    """The markers of ``marker_set`` on a motion ``(frames, 21, 3)`` metres → ``(frames, markers, 3)`` metres."""
    p = np.asarray(positions, dtype=np.float64)
    joints = p[:, [JOINT_INDEX[s] for s in marker_set.segments]]
    if marker_set.is_joint_centres:
        return joints
    frames = segment_frames(p, marker_set.segments)
    return joints + np.einsum("fmij,mj->fmi", frames, marker_set.offsets)


def _check(markers: Sequence[SkinMarker], source: str) -> tuple[SkinMarker, ...]:
    if not markers:
        raise MarkerInputError(f"{source}: the marker set is empty")
    names = [m.name for m in markers]
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise MarkerInputError(f"{source}: marker(s) {repeated} named more than once")
    segments = [m.segment for m in markers]
    for m in markers:
        if m.segment not in JOINT_INDEX:
            raise MarkerInputError(f"{source}: marker {m.name}: segment {m.segment!r} is not a joint of the canonical "
                                   f"skeleton; valid: {list(CANONICAL_JOINTS)}")
    twice = sorted({s for s in segments if segments.count(s) > 1})
    if twice:
        raise MarkerInputError(f"{source}: segment(s) {twice} carry more than one marker (one marker per segment: "
                               f"the markers' body frame is built from their segments)")
    return tuple(markers)


def read_marker_set(path: str | Path) -> MarkerSet:
    """A marker set from a CSV ``name,segment,x,y,z`` (header line, metres in the segment frame, one marker per
    row and segment); :class:`MarkerInputError` naming the file, line and value otherwise."""
    path = Path(path)
    if not path.is_file():
        raise MarkerInputError(f"marker_set={path}: no such file (or one of {list(NAMED_MARKER_SETS)})")
    if path.stat().st_size > 100_000:
        raise MarkerInputError(f"{path}: {path.stat().st_size} bytes is too large for a marker set")
    try:
        rows = list(csv.reader(path.read_text(encoding="utf-8").splitlines()))
    except (OSError, UnicodeDecodeError) as exc:
        raise MarkerInputError(f"{path}: cannot read this marker set ({exc})") from None
    if not rows or [c.strip() for c in rows[0]] != ["name", "segment", "x", "y", "z"]:
        raise MarkerInputError(f"{path}: line 1 must be the header name,segment,x,y,z")
    if len(rows) - 1 > MAX_MARKERS:
        raise MarkerInputError(f"{path}: {len(rows) - 1} markers, more than {MAX_MARKERS}")
    markers = []
    for line, row in enumerate(rows[1:], start=2):
        if len(row) != 5:
            raise MarkerInputError(f"{path}: line {line} has {len(row)} cells, not 5 (name,segment,x,y,z)")
        offset = []
        for axis, cell in zip("xyz", row[2:]):
            try:
                value = float(cell)
            except ValueError:
                raise MarkerInputError(f"{path}: line {line}, column {axis}: {cell.strip()!r} is not a number") \
                    from None
            if not np.isfinite(value) or abs(value) > 1.0:
                raise MarkerInputError(f"{path}: line {line}, column {axis}: {value} m is not an offset within 1 m")
            offset.append(value)
        markers.append(SkinMarker(row[0].strip(), row[1].strip(), tuple(offset)))
    return MarkerSet(path.stem, _check(markers, str(path)))


def marker_set_named(value: str | None, joints: Sequence[str] | None = None) -> MarkerSet:
    """``marker_set=``: ``joints`` (joint centres ``joints``, default the six of Table 2.3), ``skin``
    (:data:`SKIN_MARKERS`) or a CSV file (:func:`read_marker_set`)."""
    from stylemotion.reconstruct.markers import DEFAULT_MARKERS, check_marker_names

    if value in (None, "", "joints"):
        return joint_marker_set(check_marker_names(DEFAULT_MARKERS if joints is None else joints))
    if value == "skin":
        return SKIN_MARKERS
    return read_marker_set(value)
