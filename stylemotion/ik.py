"""Fit local joint rotations of a fixed-bone-length skeleton to global joint positions.

Generated motions are joint positions whose bone lengths vary a little from frame to frame.
:func:`fit_rotations` finds, for every frame, the local rotations of a skeleton with constant
bone lengths (its *offsets*) whose forward kinematics (:func:`stylemotion.skeleton.forward_kinematics`)
best reproduce the positions. It is analytic and vectorized over frames:

* a joint with several children (canonical: Hips, Chest) gets the rotation that best maps its
  children's rest directions onto their observed directions (Kabsch/Wahba by SVD, proper
  rotation enforced);
* a joint with one child gets the *swing*: the smallest rotation, in its parent's frame, that
  takes the rest direction of its bone onto the observed direction (no twist);
* a leaf joint (canonical: Head, Hand_*, Toes_*) gets the identity.

Every bone direction is matched exactly, so FK of the fit reproduces the positions exactly when
their bone lengths equal the offsets' lengths and the children of each multi-child joint keep
the offsets' configuration (true of any rigid skeleton); otherwise a joint moves only by the
length mismatch accumulated along its chain (plus, at Hips and Chest, by how much the observed
configuration of their children deviates from the rest one).

Default offsets (:func:`rest_offsets`) take each bone's length as its median over frames. The
rest directions form an upright T-pose facing +Z with +X the body's left (the convention of
:mod:`stylemotion.representation`), see :func:`rest_offsets`.

Units: positions and offsets in metres (any unit works, as long as it is the same for both).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from stylemotion.geometry import relative_rotation
from stylemotion.skeleton import CANONICAL_JOINTS, CANONICAL_PARENTS, checked_positions, forward_kinematics

#: Bones shorter than this (metres) have no direction to fit and are rejected.
MIN_BONE_LENGTH = 1e-6

#: Rest direction of each canonical bone whose parent joint has a single child, keyed by the
#: bone's child joint, in the body frame (+X left, +Y up, +Z forward): a T-pose with the arms
#: along X, legs pointing down and toes forward.
_TPOSE_DIRECTIONS: dict[str, tuple[float, float, float]] = {
    "Chest": (0.0, 1.0, 0.0),
    "Head": (0.0, 1.0, 0.0),
    "UpperArm_L": (1.0, 0.0, 0.0),
    "LowerArm_L": (1.0, 0.0, 0.0),
    "Hand_L": (1.0, 0.0, 0.0),
    "UpperArm_R": (-1.0, 0.0, 0.0),
    "LowerArm_R": (-1.0, 0.0, 0.0),
    "Hand_R": (-1.0, 0.0, 0.0),
    "LowerLeg_L": (0.0, -1.0, 0.0),
    "Foot_L": (0.0, -1.0, 0.0),
    "Toes_L": (0.0, 0.0, 1.0),
    "LowerLeg_R": (0.0, -1.0, 0.0),
    "Foot_R": (0.0, -1.0, 0.0),
    "Toes_R": (0.0, 0.0, 1.0),
}
#: Canonical multi-child joints: (joint, child that points up, left child, right child). Their
#: children keep the configuration found in the data, turned upright with these children.
_UPRIGHT_FRAMES: tuple[tuple[str, str, str, str], ...] = (
    ("Hips", "Spine", "UpperLeg_L", "UpperLeg_R"),
    ("Chest", "Neck", "Shoulder_L", "Shoulder_R"),
)


@dataclass
class SkeletonFit:
    """Local rotations of a fixed-bone-length skeleton fitted to joint positions.

    Attributes:
        offsets: ``(joints, 3)`` rest translation of each joint relative to its parent, metres;
            zeros for the root, whose translation is ``root_translation``.
        root_translation: ``(frames, 3)`` global root position, metres.
        local_rotations: ``(frames, joints, 3, 3)`` local rotation matrices (column vectors; a
            child's global rotation is ``R_parent_global @ R_local``), rest pose = identity.
        parents: ``(joints,)`` parent indices, -1 for the root.
    """

    offsets: np.ndarray
    root_translation: np.ndarray
    local_rotations: np.ndarray
    parents: tuple[int, ...]

    @property
    def root(self) -> int:
        return self.parents.index(-1)

    def translations(self) -> np.ndarray:
        """``(frames, joints, 3)`` local translations: offsets, the root's replaced per frame."""
        trans = np.repeat(self.offsets[None], self.root_translation.shape[0], axis=0)
        trans[:, self.root] = self.root_translation
        return trans

    def positions(self) -> np.ndarray:
        """``(frames, joints, 3)`` global positions of the fitted skeleton (metres), by FK."""
        return forward_kinematics(self.local_rotations, self.translations(), self.parents)


# ---------------------------------------------------------------------------------------------
# Validation


def _joint_name(joint: int, parents: tuple[int, ...]) -> str:
    return repr(CANONICAL_JOINTS[joint]) if parents == CANONICAL_PARENTS else f"joint {joint}"


def _check_parents(parents: np.ndarray | tuple[int, ...] | list[int]) -> tuple[int, ...]:
    parents = tuple(int(p) for p in parents)
    roots = [j for j, p in enumerate(parents) if p < 0]
    if len(roots) != 1:
        raise ValueError(f"parents must describe a tree with exactly one root (-1), found {len(roots)} roots")
    bad = [j for j, p in enumerate(parents) if p >= j]
    if bad:
        raise ValueError(f"parents must list parents before children; joint {bad[0]} has parent {parents[bad[0]]}")
    return parents


def _positions_with_bones(positions: np.ndarray, parents: tuple[int, ...]) -> np.ndarray:
    """:func:`~stylemotion.skeleton.checked_positions`, and every bone longer than :data:`MIN_BONE_LENGTH`."""
    positions = checked_positions(positions, parents)
    _check_bone_lengths(_bone_vectors_and_lengths(positions, parents)[1], parents, "positions")
    return positions


def _check_bone_lengths(lengths: np.ndarray, parents: tuple[int, ...], what: str) -> None:
    """Reject bones shorter than :data:`MIN_BONE_LENGTH`; ``lengths`` is ``(frames, joints)``."""
    short = lengths < MIN_BONE_LENGTH
    short[:, [j for j, p in enumerate(parents) if p < 0]] = False
    if short.any():
        frame, joint = np.argwhere(short)[0]
        frames = int(short[:, joint].sum())
        raise ValueError(
            f"{what}: bone {_joint_name(parents[joint], parents)}→{_joint_name(int(joint), parents)} has zero "
            f"length (< {MIN_BONE_LENGTH} m) in {frames} frame(s), first at frame {frame}; a zero-length bone "
            "has no direction to fit"
        )


def _check_offsets(offsets: np.ndarray, parents: tuple[int, ...]) -> np.ndarray:
    offsets = np.asarray(offsets, dtype=np.float64)
    if offsets.shape != (len(parents), 3):
        raise ValueError(f"offsets must have shape ({len(parents)}, 3), got {offsets.shape}")
    if not np.all(np.isfinite(offsets)):
        raise ValueError("offsets contain NaN or infinite values")
    _check_bone_lengths(np.linalg.norm(offsets, axis=-1)[None], parents, "offsets")
    offsets = offsets.copy()
    offsets[parents.index(-1)] = 0.0
    return offsets


# ---------------------------------------------------------------------------------------------
# Geometry helpers (batched)


def _bone_vectors_and_lengths(positions: np.ndarray, parents: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Bone vectors ``(..., joints, 3)`` (child minus parent; 0 for the root) and their lengths."""
    parent_idx = [max(p, 0) for p in parents]
    vectors = positions - positions[..., parent_idx, :]
    return vectors, np.linalg.norm(vectors, axis=-1)


def _normalize(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _children(parents: tuple[int, ...]) -> list[list[int]]:
    return [[c for c, p in enumerate(parents) if p == j] for j in range(len(parents))]


def kabsch(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Rotations ``R`` minimizing ``sum_i |R @ source_i - target_i|²`` (proper: det = +1).

    Args:
        source: ``(..., points, 3)`` vectors.
        target: ``(..., points, 3)`` vectors (broadcast against ``source``).

    Returns:
        ``(..., 3, 3)`` rotation matrices.
    """
    cov = np.einsum("...ki,...kj->...ij", target, source)
    u, _, vt = np.linalg.svd(cov)
    det = np.linalg.det(u @ vt)
    fix = np.ones(det.shape + (3,))
    fix[..., 2] = np.where(det < 0, -1.0, 1.0)
    return (u * fix[..., None, :]) @ vt


def swing_rotation(rest: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The smallest rotations taking unit ``rest`` directions onto unit ``target`` directions.

    The axis is ``rest × target`` (no twist about the bone). Opposite directions get a half turn
    about an axis perpendicular to ``rest``.

    Args:
        rest: ``(..., 3)`` unit vectors.
        target: ``(..., 3)`` unit vectors (broadcast against ``rest``).

    Returns:
        ``(..., 3, 3)`` rotation matrices.
    """
    rest, target = np.broadcast_arrays(rest, target)
    axis = np.cross(rest, target)
    sin = np.linalg.norm(axis, axis=-1)
    cos = np.sum(rest * target, axis=-1)
    angle = np.arctan2(sin, cos)
    tiny = sin < 1e-12
    rotvec = axis * np.where(tiny, 1.0, angle / np.where(tiny, 1.0, sin))[..., None]
    opposite = tiny & (cos < 0)
    if opposite.any():
        r = rest[opposite]
        helper = np.eye(3)[np.argmin(np.abs(r), axis=-1)]
        rotvec[opposite] = _normalize(np.cross(r, helper)) * np.pi
    return Rotation.from_rotvec(rotvec.reshape(-1, 3)).as_matrix().reshape(rotvec.shape[:-1] + (3, 3))


# ---------------------------------------------------------------------------------------------
# Rest pose


def _mean_configuration(vectors: np.ndarray, iterations: int = 3) -> np.ndarray:
    """Mean shape of a set of unit vectors that moves rigidly (generalized Procrustes).

    Args:
        vectors: ``(frames, points, 3)`` unit vectors.

    Returns:
        ``(points, 3)`` unit vectors, oriented roughly like ``vectors[0]``. For a rigid set it
        is ``vectors[0]`` up to float error.
    """
    mean = vectors[0]
    for _ in range(iterations):
        align = kabsch(vectors, mean)
        mean = _normalize(np.einsum("fij,fkj->ki", align, vectors) / vectors.shape[0])
    return mean


def _upright(up: np.ndarray, left: np.ndarray) -> np.ndarray:
    """``(3, 3)`` rotation taking ``up`` to +Y and the part of ``left`` across it to +X."""
    y = _normalize(up)
    x = _normalize(left - np.dot(left, y) * y)
    return np.stack([x, y, np.cross(x, y)])


def rest_offsets(positions: np.ndarray, parents: tuple[int, ...] = CANONICAL_PARENTS) -> np.ndarray:
    """A rest skeleton for ``positions``: median bone lengths, directions of a rest pose.

    Lengths: each bone's median length over frames. Directions:

    * the children of a joint with several children keep the configuration they have in the
      data (their mean shape over frames, so that a rigid skeleton is fitted exactly);
    * canonical skeleton: an upright T-pose facing +Z, +X the body's left. Hips and Chest are
      turned so that Spine / Neck point up (+Y) and the left-right children lie along X; the
      other bones point up (Chest, Head), sideways (clavicles and arms, along ±X), down (legs)
      or forward (toes);
    * any other skeleton: the first frame's pose (the multi-child configurations as above,
      aligned to the first frame).

    Single-child bones may point anywhere without changing what the fit reproduces; their rest
    directions only set what "zero rotation" means in an exported file.

    Args:
        positions: ``(frames, joints, 3)`` global positions, metres.
        parents: ``(joints,)`` parent indices, parents first, -1 for the root.

    Returns:
        ``(joints, 3)`` offsets in metres, zeros for the root.
    """
    parents = _check_parents(parents)
    positions = _positions_with_bones(positions, parents)
    vectors, lengths = _bone_vectors_and_lengths(positions, parents)
    directions = _normalize(np.where(lengths[..., None] > 0, vectors, 1.0))[0]
    for kids in _children(parents):
        if len(kids) >= 2:
            shape = _mean_configuration(_normalize(vectors[:, kids]))
            directions[kids] = shape @ kabsch(shape, directions[kids]).T
    if parents == CANONICAL_PARENTS:
        directions = _canonical_rest_directions(directions)
    offsets = directions * np.median(lengths, axis=0)[:, None]
    offsets[parents.index(-1)] = 0.0
    return offsets


def _canonical_rest_directions(directions: np.ndarray) -> np.ndarray:
    """Canonical T-pose directions ``(21, 3)`` from data directions (multi-child shapes kept)."""
    out = directions.copy()
    index = {name: j for j, name in enumerate(CANONICAL_JOINTS)}
    for joint, up, left, right in _UPRIGHT_FRAMES:
        kids = [c for c, p in enumerate(CANONICAL_PARENTS) if p == index[joint]]
        turn = _upright(directions[index[up]], directions[index[left]] - directions[index[right]])
        out[kids] = directions[kids] @ turn.T
    for name, direction in _TPOSE_DIRECTIONS.items():
        out[index[name]] = direction
    return out


# ---------------------------------------------------------------------------------------------
# Fitting


def fit_rotations(
    positions: np.ndarray,
    parents: tuple[int, ...] = CANONICAL_PARENTS,
    offsets: np.ndarray | None = None,
) -> SkeletonFit:
    """Local rotations of a skeleton with constant bones that reproduce ``positions``.

    Args:
        positions: ``(frames, joints, 3)`` global joint positions, metres (float32 or float64).
        parents: ``(joints,)`` parent indices, parents first, -1 for the root.
        offsets: ``(joints, 3)`` rest translations in metres, or None for :func:`rest_offsets`.
            The root's offset is ignored (the root follows ``positions``).

    Returns:
        A :class:`SkeletonFit` (float64) whose ``positions()`` reproduce ``positions`` up to the
        bone-length mismatch.

    Raises:
        ValueError: wrong shape, NaN/inf values, a zero-length bone (naming frame and joint), or
            bad ``parents``/``offsets``.
    """
    parents = _check_parents(parents)
    positions = _positions_with_bones(positions, parents)
    offsets = rest_offsets(positions, parents) if offsets is None else _check_offsets(offsets, parents)
    vectors, lengths = _bone_vectors_and_lengths(positions, parents)
    root = parents.index(-1)
    lengths[:, root] = 1.0
    targets = vectors / lengths[..., None]
    rest = _normalize(np.where(np.arange(len(parents))[:, None] == root, 1.0, offsets))

    num_frames = positions.shape[0]
    identity = np.broadcast_to(np.eye(3), (num_frames, 3, 3))
    global_rot = np.empty((num_frames, len(parents), 3, 3))
    local_rot = np.empty_like(global_rot)
    for joint, kids in enumerate(_children(parents)):
        parent_rot = identity if parents[joint] < 0 else global_rot[:, parents[joint]]
        if len(kids) >= 2:
            local_rot[:, joint] = relative_rotation(parent_rot, kabsch(rest[kids], targets[:, kids]))
        elif len(kids) == 1:
            target_local = np.einsum("fji,fj->fi", parent_rot, targets[:, kids[0]])
            local_rot[:, joint] = swing_rotation(rest[kids[0]], target_local)
        else:
            local_rot[:, joint] = identity
        global_rot[:, joint] = parent_rot @ local_rot[:, joint]
    return SkeletonFit(offsets, positions[:, root].copy(), local_rot, parents)
