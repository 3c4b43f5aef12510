"""Put a motion on other bone lengths: every bone keeps its direction, takes the target length.

Thesis §5.2 retargets all data to one skeleton, so that neither a model nor a classifier can tell
recordings apart by body proportions. This module is that transform on canonical positions:

* ``positions``: ``(frames, 21, 3)`` global canonical joint positions, metres, Y up
  (:data:`stylemotion.skeleton.CANONICAL_JOINTS` order);
* bone lengths: ``(20,)`` metres, one per non-root joint (the bone from its parent to it), in
  :data:`BONE_NAMES` order (the canonical order without Hips).

The tree walk is the one FK (:func:`stylemotion.skeleton.forward_kinematics`) with identity
rotations and each bone's new global vector as its translation. The root (Hips) trajectory is
scaled by the ratio of target to source leg length (:func:`leg_length`), so stride relative to leg
length, and with it the feet planted on the ground, stays plausible; the ground (the lowest height
of any foot point over the take) stays at its level.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from stylemotion.ik import MIN_BONE_LENGTH
from stylemotion.skeleton import (
    CANONICAL_JOINTS,
    CANONICAL_PARENTS,
    FOOT_POINTS,
    JOINT_INDEX,
    bone_lengths,
    checked_positions,
    forward_kinematics,
)

#: Canonical index of the child joint of each bone, i.e. every joint but the root (20).
BONE_JOINTS: tuple[int, ...] = tuple(j for j, p in enumerate(CANONICAL_PARENTS) if p >= 0)
#: Each bone named by its child joint (``"LowerLeg_L"`` is the thigh, from the hip joint ``UpperLeg_L``).
BONE_NAMES: tuple[str, ...] = tuple(CANONICAL_JOINTS[j] for j in BONE_JOINTS)
#: Number of bones of the canonical skeleton (20).
NUM_BONES = len(BONE_JOINTS)
#: Bone indices (into :data:`BONE_NAMES`) of the thigh and the shin of each leg: the hip-to-ankle
#: chain of :func:`stylemotion.primitives.contacts.leg_length`.
_LEG_BONES = {side: (BONE_NAMES.index(f"LowerLeg_{side}"), BONE_NAMES.index(f"Foot_{side}")) for side in "LR"}
_ROOT = JOINT_INDEX["Hips"]


def median_bone_lengths(positions: np.ndarray) -> np.ndarray:
    """Each bone's median length over frames.

    Args:
        positions: ``(..., frames, 21, 3)`` canonical positions, metres.

    Returns:
        ``(..., 20)`` float64 bone lengths in :data:`BONE_NAMES` order, metres.
    """
    positions = np.asarray(positions, dtype=np.float64)
    return np.median(bone_lengths(positions)[..., list(BONE_JOINTS)], axis=-2)


def target_bone_lengths(takes: Iterable[np.ndarray]) -> np.ndarray:
    """One skeleton for several takes: per bone, the median over takes of each take's median length.

    Args:
        takes: each ``(frames, 21, 3)`` canonical positions, metres.

    Returns:
        ``(20,)`` float64 bone lengths, metres.

    Raises:
        ValueError: no takes.
    """
    per_take = [median_bone_lengths(p) for p in takes]
    if not per_take:
        raise ValueError("target_bone_lengths needs at least one take")
    return np.median(np.stack(per_take), axis=0)


def leg_length(lengths: np.ndarray) -> np.ndarray:
    """Hip-to-ankle length (thigh + shin, mean of both legs) of a skeleton given by its bones.

    The same chain as :func:`stylemotion.primitives.contacts.leg_length`, from bone lengths instead of positions.

    Args:
        lengths: ``(..., 20)`` bone lengths, metres.

    Returns:
        ``(...)`` leg length, metres.
    """
    lengths = np.asarray(lengths, dtype=np.float64)
    return sum(lengths[..., thigh] + lengths[..., shin] for thigh, shin in _LEG_BONES.values()) / 2.0


def retarget_positions(positions: np.ndarray, target_lengths: np.ndarray) -> np.ndarray:
    """``positions`` on a skeleton with bone lengths ``target_lengths``.

    Every bone keeps its direction in every frame and gets its target length; the joints are
    placed from the root outwards. The root's horizontal path (relative to its first frame) and its
    height are scaled by ``leg_length(target) / leg_length(source)`` (source: the take's median
    bone lengths); then the whole take is shifted vertically so that its ground, the lowest height
    of any foot point (``Foot_*``, ``Toes_*``) over all frames, is where it was.

    Args:
        positions: ``(frames, 21, 3)`` canonical positions, metres, Y up.
        target_lengths: ``(20,)`` bone lengths in :data:`BONE_NAMES` order, metres.

    Returns:
        ``(frames, 21, 3)`` positions, metres, in the dtype of ``positions`` (float64 for integers).

    Raises:
        ValueError: bad shapes or values (naming the argument), a source bone of zero length
            (< :data:`stylemotion.ik.MIN_BONE_LENGTH`) whose target is not zero and whose path to its
            child joint has zero length too (naming the bone and frame; a zero-length bone otherwise
            takes the direction from its parent to its child joint), or a zero leg length.
    """
    result = retarget_takes(positions, np.array([0, len(np.asarray(positions))]), target_lengths)
    dtype = np.asarray(positions).dtype
    return result.astype(dtype if np.issubdtype(dtype, np.floating) else np.float64)


def retarget_takes(positions: np.ndarray, take_start: np.ndarray, target_lengths: np.ndarray,
                   directions: np.ndarray | None = None) -> np.ndarray:
    """:func:`retarget_positions` of several takes at once (each take's root path and ground as there).

    Args:
        positions: ``(frames, 21, 3)`` the takes one after another, metres.  take_start: ``(takes + 1,)`` offsets
            (take ``i`` is ``positions[take_start[i]:take_start[i + 1]]``).  target_lengths: ``(20,)`` metres.
        directions: ``(frames, 20, 3)`` unit bone vectors to use instead of the source's (None: the source's).

    Returns:
        ``(frames, 21, 3)`` float64 positions, metres.
    """
    source = checked_positions(positions).astype(np.float64)
    target = _check_lengths(target_lengths)
    own, lengths = _bone_directions(source, target)
    directions = own if directions is None else np.asarray(directions, np.float64)
    starts = np.asarray(take_start, dtype=np.int64)
    if starts.ndim != 1 or len(starts) < 2 or starts[0] != 0 or starts[-1] != len(source) or \
            np.any(np.diff(starts) < 1):
        raise ValueError(f"take_start must rise from 0 to the {len(source)} frames, got {starts[:5]}…")
    take = np.repeat(np.arange(len(starts) - 1), np.diff(starts))
    legs = np.array([leg_length(np.median(lengths[a:b], axis=0)) for a, b in zip(starts[:-1], starts[1:])])
    if np.any(legs < MIN_BONE_LENGTH):
        raise ValueError(f"positions: the leg (thigh + shin) has zero length ({legs.min():.3g} m) in take "
                         f"{int(np.argmin(legs))}; cannot scale the root's path")
    ratio = (float(leg_length(target)) / legs)[take][:, None]
    root = source[:, _ROOT]
    start = root[starts[:-1]][take] * np.array([1.0, 0.0, 1.0])  # each take's first ground point stays put
    result = _place(directions, target, start + ratio * (root - start))
    feet = list(FOOT_POINTS.ravel())
    shift = np.minimum.reduceat(source[:, feet, 1].min(axis=1), starts[:-1]) \
        - np.minimum.reduceat(result[:, feet, 1].min(axis=1), starts[:-1])
    result[..., 1] += shift[take][:, None]
    return result


def place_bones(positions: np.ndarray, target_lengths: np.ndarray) -> np.ndarray:
    """``positions`` with every bone set to its length in ``target_lengths``, each frame's root kept where it is
    (unlike :func:`retarget_positions`, no scaling of the root's path and no ground shift): the bone lengths of the
    result are constant over time.

    Args:
        positions: ``(frames, 21, 3)`` canonical positions, metres.  target_lengths: ``(20,)`` metres.

    Returns:
        ``(frames, 21, 3)`` float64 positions, metres.

    Raises:
        ValueError: as :func:`retarget_positions` (a zero-length source bone without a direction).
    """
    source = checked_positions(positions).astype(np.float64)
    target = _check_lengths(target_lengths)
    directions, _ = _bone_directions(source, target)
    return _place(directions, target, source[:, _ROOT])


def _bone_directions(source: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit bone vectors ``(frames, 20, 3)`` (zero for a bone without a direction whose target is zero) and the
    source's bone lengths ``(frames, 20)``; ValueError for a bone without a direction whose target is not zero."""
    children, parents = list(BONE_JOINTS), [CANONICAL_PARENTS[j] for j in BONE_JOINTS]
    vectors = source[:, children] - source[:, parents]  # (frames, 20, 3)
    lengths = bone_lengths(source)[:, children]  # (frames, 20)
    short = lengths < MIN_BONE_LENGTH
    vectors, lengths, short = _through_short_bones(source, vectors, lengths, short)
    lost = short & (target >= MIN_BONE_LENGTH)
    if lost.any():
        frame, bone = (int(i) for i in np.argwhere(lost)[0])
        raise ValueError(f"positions: bone {BONE_NAMES[bone]!r} has zero length (< {MIN_BONE_LENGTH} m) in "
                         f"{int(lost[:, bone].sum())} frame(s), first at frame {frame}, so it has no direction "
                         f"to give the target length {target[bone]:.4g} m")
    return np.where(short[..., None], 0.0, vectors / np.where(short, 1.0, lengths)[..., None]), lengths


def _place(directions: np.ndarray, target: np.ndarray, root: np.ndarray) -> np.ndarray:
    """Joints from unit bone vectors ``(frames, 20, 3)``, bone lengths ``(20,)`` and root positions ``(frames, 3)``
    (the one FK, identity rotations)."""
    translations = np.zeros(directions.shape[:1] + (len(CANONICAL_JOINTS), 3))
    translations[:, _ROOT] = root
    translations[:, list(BONE_JOINTS)] = directions * target[:, None]
    return forward_kinematics(np.broadcast_to(np.eye(3), (len(CANONICAL_JOINTS), 3, 3)), translations,
                              CANONICAL_PARENTS)


def _through_short_bones(source: np.ndarray, vectors: np.ndarray, lengths: np.ndarray, short: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Directions for bones of zero length in the source (e.g. a clavicle that a skeleton places on the
    neck): the direction from the bone's parent joint to its first child joint, where that is not zero
    too. Returns the bone vectors, lengths and the still-short mask."""
    if not short.any():
        return vectors, lengths, short
    vectors, lengths = vectors.copy(), lengths.copy()
    for bone, joint in enumerate(BONE_JOINTS):
        if not short[:, bone].any():
            continue
        child = next((k for k, parent in enumerate(CANONICAL_PARENTS) if parent == joint), None)
        if child is None:
            continue
        through = source[:, child] - source[:, CANONICAL_PARENTS[joint]]
        span = np.linalg.norm(through, axis=-1)
        usable = short[:, bone] & (span >= MIN_BONE_LENGTH)
        vectors[usable, bone], lengths[usable, bone] = through[usable], span[usable]
    return vectors, lengths, lengths < MIN_BONE_LENGTH


def _check_lengths(target_lengths: np.ndarray) -> np.ndarray:
    """``target_lengths`` as float64 ``(20,)``, finite and ≥ 0; ValueError naming what is wrong."""
    lengths = np.asarray(target_lengths)
    if lengths.shape != (NUM_BONES,) or not np.issubdtype(lengths.dtype, np.number):
        raise ValueError(f"target_lengths must be {NUM_BONES} numbers (metres, bones {list(BONE_NAMES)}), got "
                         f"shape {lengths.shape} dtype {lengths.dtype}")
    lengths = lengths.astype(np.float64)
    bad = ~np.isfinite(lengths) | (lengths < 0)
    if bad.any():
        bone = int(np.argmax(bad))
        raise ValueError(f"target_lengths must be finite and ≥ 0 metres; bone {BONE_NAMES[bone]!r} has "
                         f"{float(lengths[bone])!r}")
    return lengths
