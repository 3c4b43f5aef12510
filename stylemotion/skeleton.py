"""Skeletons and forward kinematics (FK), in numpy and in torch.

Conventions used across stylemotion:

* A skeleton is a tree of joints listed parents-before-children; ``parents[j]`` is the index of
  joint ``j``'s parent and ``-1`` for the root.
* ``translations``: local translation of each joint relative to its parent, ``(..., joints, 3)``.
  For a BVH file this is the OFFSET, or the per-frame position channels where a joint has them.
* ``rotations``: local rotation matrices ``(..., joints, 3, 3)`` acting on column vectors, so a
  child's global rotation is ``R_parent_global @ R_local``.
* FK returns global joint positions ``(..., joints, 3)`` in the units of ``translations``.

There is exactly one numpy FK (:func:`forward_kinematics`) and one torch FK
(:func:`forward_kinematics_torch`, differentiable, batched); everything else calls them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # torch is imported by the functions that use it, so that the numpy paths (search,
    import torch  # reconstruct, annotate, datasets) start without it (docs/architecture.md)

#: The 21 canonical joints, named as the Bandai-Namco dataset names them (without joint_Root).
CANONICAL_JOINTS: tuple[str, ...] = (
    "Hips", "Spine", "Chest", "Neck", "Head",
    "Shoulder_L", "UpperArm_L", "LowerArm_L", "Hand_L",
    "Shoulder_R", "UpperArm_R", "LowerArm_R", "Hand_R",
    "UpperLeg_L", "LowerLeg_L", "Foot_L", "Toes_L",
    "UpperLeg_R", "LowerLeg_R", "Foot_R", "Toes_R",
)  # fmt: skip
#: Number of canonical joints (21).
NUM_JOINTS = len(CANONICAL_JOINTS)

_CANONICAL_PARENT_NAMES: dict[str, str | None] = {
    "Hips": None, "Spine": "Hips", "Chest": "Spine", "Neck": "Chest", "Head": "Neck",
    "Shoulder_L": "Chest", "UpperArm_L": "Shoulder_L", "LowerArm_L": "UpperArm_L",
    "Hand_L": "LowerArm_L",
    "Shoulder_R": "Chest", "UpperArm_R": "Shoulder_R", "LowerArm_R": "UpperArm_R",
    "Hand_R": "LowerArm_R",
    "UpperLeg_L": "Hips", "LowerLeg_L": "UpperLeg_L", "Foot_L": "LowerLeg_L", "Toes_L": "Foot_L",
    "UpperLeg_R": "Hips", "LowerLeg_R": "UpperLeg_R", "Foot_R": "LowerLeg_R", "Toes_R": "Foot_R",
}  # fmt: skip

#: Parent index of each canonical joint (-1 for Hips).
CANONICAL_PARENTS: tuple[int, ...] = tuple(
    -1 if _CANONICAL_PARENT_NAMES[n] is None else CANONICAL_JOINTS.index(_CANONICAL_PARENT_NAMES[n])
    for n in CANONICAL_JOINTS
)

#: Index of a canonical joint by name, e.g. ``JOINT_INDEX["Hips"] == 0``.
JOINT_INDEX: dict[str, int] = {name: i for i, name in enumerate(CANONICAL_JOINTS)}
#: ``(foot, point)`` joint indices: heel (ankle) and ball (toes) of the left and the right foot (the foot
#: points of contacts, bone retargeting and the viewer; the order of :data:`stylemotion.primitives.contacts.FEET`).
FOOT_POINTS: np.ndarray = np.array([[JOINT_INDEX["Foot_L"], JOINT_INDEX["Toes_L"]],
                                    [JOINT_INDEX["Foot_R"], JOINT_INDEX["Toes_R"]]])

#: Left/right joint index pairs of the canonical skeleton (for mirroring and symmetry checks).
CANONICAL_MIRROR = tuple(JOINT_INDEX[n.replace("_L", "_R")] if n.endswith("_L") else
                         JOINT_INDEX[n.replace("_R", "_L")] if n.endswith("_R") else JOINT_INDEX[n]
                         for n in CANONICAL_JOINTS)  # fmt: skip


@dataclass
class Skeleton:
    """A joint hierarchy.

    Attributes:
        names: joint names, parents before children.
        parents: ``(joints,)`` parent indices, -1 for the root.
        offsets: ``(joints, 3)`` rest translation of each joint relative to its parent (file units).
        channels: per joint, its BVH channel names in file order (e.g. ``["Zrotation", ...]``).
        end_sites: joint index → ``(3,)`` offset of that joint's End Site, if it has one.
    """

    names: list[str]
    parents: np.ndarray
    offsets: np.ndarray
    channels: list[list[str]] = field(default_factory=list)
    end_sites: dict[int, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.parents = np.asarray(self.parents, dtype=np.int64)
        self.offsets = np.asarray(self.offsets, dtype=np.float64)
        if not self.channels:
            self.channels = [[] for _ in self.names]
        n = len(self.names)
        if self.parents.shape != (n,) or self.offsets.shape != (n, 3) or len(self.channels) != n:
            raise ValueError(
                f"skeleton arrays disagree: {n} names, parents {self.parents.shape}, "
                f"offsets {self.offsets.shape}, {len(self.channels)} channel lists"
            )
        for j, p in enumerate(self.parents):
            if p >= j:
                raise ValueError(f"joint {self.names[j]!r} is listed before its parent (index {p})")

    @property
    def num_joints(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        """Index of joint ``name``; raises KeyError naming the missing joint."""
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"joint {name!r} not in skeleton (joints: {', '.join(self.names)})") from None

    def children(self, joint: int) -> list[int]:
        return [j for j, p in enumerate(self.parents) if p == joint]


def checked_positions(positions: np.ndarray, parents: tuple[int, ...] | None = None, min_frames: int = 1,
                      what: str = "positions") -> np.ndarray:
    """``positions`` as float64 ``(frames ≥ min_frames, joints, 3)`` (joints: ``len(parents)``, the canonical 21
    by default), finite numbers; the one check every module runs on a motion's joint positions.

    Raises:
        ValueError: naming ``what``, the wrong shape or dtype, or the first NaN/inf by frame and joint.
    """
    parents = CANONICAL_PARENTS if parents is None else tuple(parents)
    array = np.asarray(positions)
    num_joints = len(parents)
    if array.ndim != 3 or array.shape[1:] != (num_joints, 3) or array.shape[0] < min_frames:
        raise ValueError(f"{what} must have shape (frames, {num_joints}, 3) with at least {min_frames} frame(s), "
                         f"got {array.shape}")
    if not np.issubdtype(array.dtype, np.number):
        raise ValueError(f"{what} must be numbers, got dtype {array.dtype}")
    array = array.astype(np.float64)
    bad = ~np.isfinite(array)
    if bad.any():
        frame, joint, _ = (int(i) for i in np.argwhere(bad)[0])
        name = repr(CANONICAL_JOINTS[joint]) if parents == CANONICAL_PARENTS else f"joint {joint}"
        raise ValueError(f"{what} hold NaN or infinite values, first at frame {frame}, joint {name} "
                         f"({int(bad.sum())} in all)")
    return array


def forward_kinematics(
    rotations: np.ndarray, translations: np.ndarray, parents: np.ndarray | tuple[int, ...],
    return_rotations: bool = False,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """Global joint positions from local rotations and translations (numpy).

    Args:
        rotations: ``(..., joints, 3, 3)`` local rotation matrices.
        translations: ``(..., joints, 3)`` local translations (broadcast against ``rotations``).
        parents: ``(joints,)`` parent indices, parents before children, -1 for the root.
        return_rotations: also return the ``(..., joints, 3, 3)`` global rotations.

    Returns:
        ``(..., joints, 3)`` global positions, in the units of ``translations``.
    """
    rotations = np.asarray(rotations)
    translations = np.asarray(translations)
    lead = np.broadcast_shapes(rotations.shape[:-3], translations.shape[:-2])
    num_joints = rotations.shape[-3]
    dtype = np.result_type(rotations, translations)
    global_rot = np.empty(lead + (num_joints, 3, 3), dtype=dtype)
    global_pos = np.empty(lead + (num_joints, 3), dtype=dtype)
    for j, p in enumerate(parents):
        if p < 0:
            global_rot[..., j, :, :] = rotations[..., j, :, :]
            global_pos[..., j, :] = translations[..., j, :]
        else:
            global_rot[..., j, :, :] = global_rot[..., p, :, :] @ rotations[..., j, :, :]
            global_pos[..., j, :] = global_pos[..., p, :] + np.einsum(
                "...ab,...b->...a", global_rot[..., p, :, :], translations[..., j, :]
            )
    return (global_pos, global_rot) if return_rotations else global_pos


def forward_kinematics_torch(
    rotations: torch.Tensor, translations: torch.Tensor, parents: np.ndarray | tuple[int, ...],
) -> torch.Tensor:
    """Differentiable, batched FK (torch); same conventions as :func:`forward_kinematics`.

    Args:
        rotations: ``(..., joints, 3, 3)`` local rotation matrices.
        translations: ``(..., joints, 3)`` local translations.
        parents: ``(joints,)`` parent indices.

    Returns:
        ``(..., joints, 3)`` global positions.
    """
    import torch
    lead = torch.broadcast_shapes(rotations.shape[:-3], translations.shape[:-2])
    global_rot: list[torch.Tensor] = []
    global_pos: list[torch.Tensor] = []
    for j, p in enumerate(parents):
        r_local = rotations[..., j, :, :]
        t_local = translations[..., j, :]
        if p < 0:
            # Broadcast like the numpy FK: either input may carry the batch dimensions.
            global_rot.append(r_local.expand(lead + (3, 3)))
            global_pos.append(t_local.expand(lead + (3,)))
        else:
            global_rot.append(global_rot[p] @ r_local)
            global_pos.append(global_pos[p] + (global_rot[p] @ t_local.unsqueeze(-1)).squeeze(-1))
    return torch.stack(global_pos, dim=-2)


def bone_lengths(positions: np.ndarray, parents: tuple[int, ...] = CANONICAL_PARENTS) -> np.ndarray:
    """Length of each bone ``(..., joints)`` from positions ``(..., joints, 3)``; 0 for the root."""
    parent_idx = np.array([max(p, 0) for p in parents])
    lengths = np.linalg.norm(positions - positions[..., parent_idx, :], axis=-1)
    lengths[..., [j for j, p in enumerate(parents) if p < 0]] = 0.0
    return lengths
