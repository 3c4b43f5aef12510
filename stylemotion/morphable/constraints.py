"""Spatial constraints on a primitive's motion at a keyframe (Du §4.5.1–4.5.2, eq. 4.2).

A constraint asks a joint to be at a position, to have an orientation, or the whole body to take a pose,
at a frame of the primitive's canonical timeline (``frame``: normalized time in ``[0, 1]``; 1 is the last
frame, the semantic keyframe where the next primitive starts). Positions are metres in the primitive's own
frame (the clip starts with its root above the origin facing +Z). The objective of a code is eq. 4.2,
the sum over constraints of their errors:

* position: the joint's distance to the target (m);
* orientation: the angle (rad) between the joint's global rotation and the target rotation, times
  ``orientation_scale_m`` (metres per radian, so that it adds to distances);
* pose: the mean distance (m) of the 21 joints to the target pose.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from stylemotion.skeleton import CANONICAL_JOINTS, NUM_JOINTS


@dataclass(frozen=True)
class KeyframeConstraint:
    """One constraint (see the module doc).

    Attributes:
        kind: ``position``, ``orientation`` or ``pose``.
        frame: normalized canonical time in ``[0, 1]`` (1 = the last keyframe).
        joint: canonical joint name (``position``/``orientation``).
        target: ``(3,)`` position (m), ``(3, 3)`` global rotation matrix, or ``(21, 3)`` pose (m).
        orientation_scale_m: metres per radian of orientation error.
    """

    kind: str
    target: np.ndarray
    joint: str | None = None
    frame: float = 1.0
    orientation_scale_m: float = 0.1

    def __post_init__(self) -> None:
        shapes = {"position": (3,), "orientation": (3, 3), "pose": (NUM_JOINTS, 3)}
        if self.kind not in shapes:
            raise ValueError(f"unknown constraint kind {self.kind!r}; one of {sorted(shapes)}")
        target = np.asarray(self.target, dtype=np.float64)
        if target.shape != shapes[self.kind]:
            raise ValueError(f"a {self.kind} constraint's target must have shape {shapes[self.kind]}, "
                             f"got {target.shape}")
        if not np.isfinite(target).all():
            raise ValueError(f"{self.kind} constraint target holds NaN or inf: {target.tolist()}")
        object.__setattr__(self, "target", target)
        if self.kind != "pose":
            if self.joint not in CANONICAL_JOINTS:
                raise ValueError(f"unknown joint {self.joint!r} in a {self.kind} constraint; joints: "
                                 f"{list(CANONICAL_JOINTS)}")
        if not 0.0 <= float(self.frame) <= 1.0:
            raise ValueError(f"constraint frame is normalized time in [0, 1], got {self.frame}")

    @property
    def joint_index(self) -> int:
        return CANONICAL_JOINTS.index(self.joint)


def constraint_errors(positions: np.ndarray, rotations: np.ndarray | None, constraints: Sequence[KeyframeConstraint],
                      length: int) -> np.ndarray:
    """``(m, constraints)`` errors (metres; orientations scaled) of motions on the canonical timeline.

    Args:
        positions: ``(m, L, 21, 3)`` canonical-timeline positions.
        rotations: ``(m, L, 21, 3, 3)`` global rotations (needed by orientation constraints).
        constraints: the constraints.
        length: ``L``.
    """
    out = np.empty((positions.shape[0], len(constraints)))
    for i, c in enumerate(constraints):
        frame = int(round(c.frame * (length - 1)))
        if c.kind == "position":
            out[:, i] = np.linalg.norm(positions[:, frame, c.joint_index] - c.target, axis=-1)
        elif c.kind == "pose":
            out[:, i] = np.linalg.norm(positions[:, frame] - c.target, axis=-1).mean(-1)
        else:
            if rotations is None:
                raise ValueError("orientation constraints need joint rotations")
            rel = np.einsum("mji,jk->mik", rotations[:, frame, c.joint_index], c.target)
            cos = np.clip((np.trace(rel, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
            out[:, i] = np.arccos(cos) * c.orientation_scale_m
    return out


def objective(model, constraints: Sequence[KeyframeConstraint]):
    """Eq. 4.2 for a :class:`~stylemotion.morphable.model.MorphableModel`: ``(m, d)`` codes → ``(m,)`` summed
    constraint errors."""
    if not constraints:
        raise ValueError("no constraint given")
    need_rot = any(c.kind == "orientation" for c in constraints)
    frames = sorted({int(round(c.frame * (model.length - 1))) for c in constraints})
    # evaluate only the constrained frames: re-express each constraint's frame as its index among them
    local = [KeyframeConstraint(c.kind, c.target, c.joint, frames.index(int(round(c.frame * (model.length - 1))))
                                / max(len(frames) - 1, 1), c.orientation_scale_m) for c in constraints]

    def cost(latent: np.ndarray) -> np.ndarray:
        out = model.poses_at(latent, frames, rotations=need_rot)
        pos, rot = out if need_rot else (out, None)
        return constraint_errors(pos, rot, local, len(frames)).sum(-1)

    return cost
