"""Keyframe bounds of a primitive's tree, for branch-and-bound constraint search (beyond Du §4.5.2).

Keyframe constraints (:mod:`.constraints`) sit mostly at the primitive's *keyframes*: its first and last
canonical frames, where it hands over to the previous and next primitive. For the tree's codes the joint
positions (m) and global rotation matrices at those two frames are computed once (one FK of two frames per
code: ~0.7 s for 10,000 codes) and boxed per node (:meth:`~.tree.SpaceTree.node_bounds`, stored as float32
rounded outwards, so the boxes stay conservative). A constraint's error over a node is then bounded below
without decoding any code:

* position: the distance from the target to the joint's box;
* pose: the mean over joints of those distances;
* orientation: the Frobenius distance ``δ`` from the target matrix to the box of the joint's 9 matrix
  entries; since ``‖R − T‖_F = 2√2 · sin(θ/2)``, the angle is at least ``2 · asin(δ / 2√2)`` (times the
  constraint's metres per radian).

The sum over constraints bounds eq. 4.2's objective, and :meth:`~.tree.SpaceTree.search_bounded` opens nodes
best first. The same keyframe values, orientations scaled to metres like the objective, are what a
``space="keyframes"`` tree clusters (:meth:`~.model.MorphableModel.build_tree`), so its nodes are compact
where the bounds look. Constraints at other frames fall back to the thesis' beam search (:func:`best_code`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from stylemotion.morphable.constraints import KeyframeConstraint, objective
from stylemotion.morphable.tree import SearchResult, SpaceTree

#: Normalized canonical times of the keyframes bounded per node.
KEYFRAME_TIMES = (0.0, 1.0)
#: Metres per radian of orientation used when clustering (the constraints' default).
ORIENTATION_SCALE_M = KeyframeConstraint.__dataclass_fields__["orientation_scale_m"].default
#: Evaluations the bounded search may spend by default (the issue's budget for Fig. 4.12).
MAX_EVALUATIONS = 120


def keyframe_frames(length: int) -> list[int]:
    """Canonical frame indices of :data:`KEYFRAME_TIMES` on an ``length``-frame timeline."""
    return [int(round(t * (length - 1))) for t in KEYFRAME_TIMES]


def keyframe_values(model, latent: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """Positions ``(n, 2, 21, 3)`` (m) and global rotations ``(n, 2, 21, 3, 3)`` of ``(n, d)`` codes at the
    keyframes (rotations None for a model of the 66-dim frames, which has no joint orientations)."""
    if model.channels.kind != "quaternion":
        return model.poses_at(latent, keyframe_frames(model.length)), None
    return model.poses_at(latent, keyframe_frames(model.length), rotations=True)


def clustering_features(model, latent: np.ndarray) -> np.ndarray:
    """``(n, 2 · 21 · 12)`` keyframe positions and rotation entries, the latter scaled so that their Euclidean
    distance approximates the objective's orientation error (``‖ΔR‖_F ≈ √2 θ`` for small angles)."""
    pos, rot = keyframe_values(model, latent)
    n = len(latent)
    if rot is None:
        return pos.reshape(n, -1)
    return np.concatenate([pos.reshape(n, -1), rot.reshape(n, -1) * (ORIENTATION_SCALE_M / np.sqrt(2.0))], axis=1)


def _outward(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    lo32, hi32 = lo.astype(np.float32), hi.astype(np.float32)
    lo32 = np.where(lo32 > lo, np.nextafter(lo32, np.float32(-np.inf)), lo32)
    hi32 = np.where(hi32 < hi, np.nextafter(hi32, np.float32(np.inf)), hi32)
    return lo32, hi32


@dataclass
class KeyframeBounds:
    """Per-node boxes: ``position_lo``/``position_hi`` ``(M, 2, 21, 3)`` metres and ``rotation_lo``/
    ``rotation_hi`` ``(M, 2, 21, 9)`` matrix entries (float32, rounded outwards; None for a frames model);
    ``frames``: the keyframes' canonical indices."""

    position_lo: np.ndarray
    position_hi: np.ndarray
    rotation_lo: np.ndarray | None
    rotation_hi: np.ndarray | None
    frames: list[int]

    @classmethod
    def of(cls, model, tree: SpaceTree) -> KeyframeBounds:
        pos, rot = keyframe_values(model, tree.latent)
        p_lo, p_hi = _outward(*tree.node_bounds(pos))
        r_lo, r_hi = (None, None) if rot is None else _outward(*tree.node_bounds(rot.reshape(*rot.shape[:3], 9)))
        return cls(p_lo, p_hi, r_lo, r_hi, keyframe_frames(model.length))

    @property
    def nbytes(self) -> int:
        arrays = (self.position_lo, self.position_hi, self.rotation_lo, self.rotation_hi)
        return sum(a.nbytes for a in arrays if a is not None)

    def lower_bound(self, constraints: Sequence[KeyframeConstraint], length: int):
        """``nodes → (bound, guess)`` for :meth:`~.tree.SpaceTree.search_bounded` (guess: the error at the
        boxes' centres), or None when a constraint is not at a keyframe (or is an orientation without rotation
        boxes)."""
        slots = []
        for c in constraints:
            frame = int(round(c.frame * (length - 1)))
            if frame not in self.frames or (c.kind == "orientation" and self.rotation_lo is None):
                return None
            slots.append(self.frames.index(frame))

        def box_distance(lo: np.ndarray, hi: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            gap = np.maximum(np.maximum(lo - target, target - hi), 0.0)
            return np.linalg.norm(gap, axis=-1), np.linalg.norm((lo + hi) / 2.0 - target, axis=-1)

        def bound(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            total, guess = np.zeros(len(nodes)), np.zeros(len(nodes))
            for c, k in zip(constraints, slots):
                if c.kind == "position":
                    b, g = box_distance(self.position_lo[nodes, k, c.joint_index],
                                        self.position_hi[nodes, k, c.joint_index], c.target)
                elif c.kind == "pose":
                    b, g = box_distance(self.position_lo[nodes, k], self.position_hi[nodes, k], c.target)
                    b, g = b.mean(-1), g.mean(-1)
                else:
                    d, dc = box_distance(self.rotation_lo[nodes, k, c.joint_index],
                                         self.rotation_hi[nodes, k, c.joint_index], c.target.reshape(9))
                    b, g = (2.0 * np.arcsin(np.minimum(x / (2.0 * np.sqrt(2.0)), 1.0)) * c.orientation_scale_m
                            for x in (d, dc))
                total += b
                guess += g
            return total, guess

        return bound


def best_code(model, constraints: Sequence[KeyframeConstraint], candidates: int = 4,
              max_evaluations: int = MAX_EVALUATIONS) -> SearchResult:
    """The tree's best code for ``constraints`` (eq. 4.2): branch and bound within ``max_evaluations`` when
    every constraint is at a keyframe, else the thesis' beam search with ``candidates`` nodes per level."""
    tree = model.ensure_tree()
    cost = objective(model, constraints)
    bound = model.keyframe_bounds().lower_bound(constraints, model.length)
    if bound is None:
        return tree.search(cost, candidates)
    return tree.search_bounded(cost, bound, max_evaluations)
