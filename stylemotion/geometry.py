"""Small geometric transforms, one implementation each, as numpy and torch twins.

Data preparation, synthesis, the synthetic data set, export and the figures all call these; nothing
else rotates about the vertical, wraps an angle, solves a two-bone chain or turns global rotations
into local ones.

Conventions (those of :mod:`stylemotion.representation`): Y is up and the ground is the ``(x, z)``
plane; angles are radians; rotation matrices act on column vectors. Yaw ``θ`` rotates about +Y::

    x' = x cos θ + z sin θ,    y' = y,    z' = −x sin θ + z cos θ

so heading ``θ`` faces ``(sin θ, 0, cos θ)``, the body's left is ``(cos θ, 0, −sin θ)`` and a
positive yaw turns +Z towards +X (a left turn).

**Twins.** Every numpy function ``f`` has a torch twin ``f_torch`` beside it, with the same
arguments, the same operation order and the same result up to rounding (``tests/test_geometry.py``
checks each pair); the torch ones are differentiable and keep the tensors' dtype and device.
Two names rather than one function that dispatches on its argument's type, as
:func:`stylemotion.skeleton.forward_kinematics` / ``forward_kinematics_torch`` already do: a call
site's precision stays visible and fixed (numpy callers compute in their arrays' dtype, float64 for
the data; torch callers in the tensor's), which is what keeps the data and the thesis' tables
bit-identical whichever twin another caller uses.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # torch is imported by the functions that use it, so that the numpy paths (search,
    import torch  # reconstruct, annotate, datasets) start without it (docs/architecture.md)

#: Lengths below this (metres, or unit vectors' norms) count as zero where a division needs a guard.
EPSILON = 1e-9

#: How :func:`two_bone_ik` places the middle joint (see there).
IK_LAWS = ("distances", "cosines")


# ---------------------------------------------------------------------------------------------
# Angles and ground directions


def wrap_angle(angle: np.ndarray) -> np.ndarray:
    """Angles ``(...)`` wrapped to ``[-π, π)``, radians (``π`` itself becomes ``-π``; an angle within
    rounding below ``-π`` comes out as ``+π``)."""
    return (angle + np.pi) % (2 * np.pi) - np.pi


def wrap_angle_torch(angle: torch.Tensor) -> torch.Tensor:
    """Torch twin of :func:`wrap_angle`."""
    import torch
    return torch.remainder(angle + math.pi, 2 * math.pi) - math.pi


def direction_yaw(direction: np.ndarray) -> np.ndarray:
    """Yaw ``(...)`` faced by ground directions ``(..., 2)`` ``(x, z)`` (any length > 0), radians in ``[-π, π]``."""
    return np.arctan2(direction[..., 0], direction[..., 1])


def direction_yaw_torch(direction: torch.Tensor) -> torch.Tensor:
    """Torch twin of :func:`direction_yaw`."""
    import torch
    return torch.atan2(direction[..., 0], direction[..., 1])


def facing_direction(yaw: np.ndarray) -> np.ndarray:
    """Unit ground direction ``(..., 2)`` ``(x, z)`` faced at ``yaw`` ``(...)``: ``(sin θ, cos θ)``."""
    return np.stack([np.sin(yaw), np.cos(yaw)], axis=-1)


def facing_direction_torch(yaw: torch.Tensor) -> torch.Tensor:
    """Torch twin of :func:`facing_direction`."""
    import torch
    return torch.stack([torch.sin(yaw), torch.cos(yaw)], dim=-1)


def left_direction(yaw: np.ndarray) -> np.ndarray:
    """Unit ground direction ``(..., 2)`` ``(x, z)`` of the body's left at ``yaw`` ``(...)``: ``(cos θ, −sin θ)``."""
    return np.stack([np.cos(yaw), -np.sin(yaw)], axis=-1)


def left_direction_torch(yaw: torch.Tensor) -> torch.Tensor:
    """Torch twin of :func:`left_direction`."""
    import torch
    return torch.stack([torch.cos(yaw), -torch.sin(yaw)], dim=-1)


# ---------------------------------------------------------------------------------------------
# Rotation about the vertical


def _cos_sin(yaw: torch.Tensor | float, like: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """``cos`` and ``sin`` of a tensor yaw as it is; a number becomes a tensor of ``like``'s dtype and device."""
    import torch
    if not isinstance(yaw, torch.Tensor):
        yaw = torch.tensor(float(yaw), dtype=like.dtype, device=like.device)
    return torch.cos(yaw), torch.sin(yaw)


def rotate_yaw(vectors: np.ndarray, yaw: np.ndarray | float) -> np.ndarray:
    """Vectors ``(..., 3)`` rotated about +Y by ``yaw`` (broadcast against ``vectors[..., 0]``), radians."""
    c, s = np.cos(yaw), np.sin(yaw)
    x, y, z = vectors[..., 0], vectors[..., 1], vectors[..., 2]
    rotated_x = c * x + s * z
    return np.stack([rotated_x, np.broadcast_to(y, rotated_x.shape), -s * x + c * z], axis=-1)


def rotate_yaw_torch(vectors: torch.Tensor, yaw: torch.Tensor | float) -> torch.Tensor:
    """Torch twin of :func:`rotate_yaw`."""
    import torch
    c, s = _cos_sin(yaw, vectors)
    x, y, z = vectors[..., 0], vectors[..., 1], vectors[..., 2]
    rotated_x = c * x + s * z
    return torch.stack([rotated_x, torch.broadcast_to(y, rotated_x.shape), -s * x + c * z], dim=-1)


def rotate_yaw_xz(ground: np.ndarray, yaw: np.ndarray | float) -> np.ndarray:
    """Ground vectors ``(..., 2)`` ``(x, z)`` rotated about +Y by ``yaw`` (broadcast against ``ground[..., 0]``)."""
    c, s = np.cos(yaw), np.sin(yaw)
    x, z = ground[..., 0], ground[..., 1]
    return np.stack([c * x + s * z, -s * x + c * z], axis=-1)


def rotate_yaw_xz_torch(ground: torch.Tensor, yaw: torch.Tensor | float) -> torch.Tensor:
    """Torch twin of :func:`rotate_yaw_xz`."""
    import torch
    c, s = _cos_sin(yaw, ground)
    x, z = ground[..., 0], ground[..., 1]
    return torch.stack([c * x + s * z, -s * x + c * z], dim=-1)


# ---------------------------------------------------------------------------------------------
# Rotation matrices about the axes


def _axis_matrix_np(angle: np.ndarray, layout: str) -> np.ndarray:
    c, s, o, i = np.cos(angle), np.sin(angle), np.zeros_like(angle), np.ones_like(angle)
    entries = {"x": (i, o, o, o, c, -s, o, s, c), "y": (c, o, s, o, i, o, -s, o, c), "z": (c, -s, o, s, c, o, o, o, i)}
    return np.stack(entries[layout], axis=-1).reshape(np.shape(angle) + (3, 3))


def _axis_matrix_torch(angle: torch.Tensor, layout: str) -> torch.Tensor:
    import torch
    c, s, o, i = torch.cos(angle), torch.sin(angle), torch.zeros_like(angle), torch.ones_like(angle)
    entries = {"x": (i, o, o, o, c, -s, o, s, c), "y": (c, o, s, o, i, o, -s, o, c), "z": (c, -s, o, s, c, o, o, o, i)}
    return torch.stack(entries[layout], dim=-1).reshape(angle.shape + (3, 3))


def rotation_x(angle: np.ndarray) -> np.ndarray:
    """Rotations ``(..., 3, 3)`` about +X by ``angle`` ``(...)`` (positive tips +Y towards +Z: leaning forward)."""
    return _axis_matrix_np(angle, "x")


def rotation_x_torch(angle: torch.Tensor) -> torch.Tensor:
    """Torch twin of :func:`rotation_x`."""
    return _axis_matrix_torch(angle, "x")


def rotation_y(angle: np.ndarray) -> np.ndarray:
    """Yaw rotations ``(..., 3, 3)`` about +Y by ``angle`` ``(...)`` (positive turns +Z towards +X: a left
    turn); ``rotation_y(θ) @ v`` is :func:`rotate_yaw` of ``v``."""
    return _axis_matrix_np(angle, "y")


def rotation_y_torch(angle: torch.Tensor) -> torch.Tensor:
    """Torch twin of :func:`rotation_y`."""
    return _axis_matrix_torch(angle, "y")


def rotation_z(angle: np.ndarray) -> np.ndarray:
    """Rotations ``(..., 3, 3)`` about +Z by ``angle`` ``(...)`` (positive raises +X: the body's left side)."""
    return _axis_matrix_np(angle, "z")


def rotation_z_torch(angle: torch.Tensor) -> torch.Tensor:
    """Torch twin of :func:`rotation_z`."""
    return _axis_matrix_torch(angle, "z")


# ---------------------------------------------------------------------------------------------
# Local rotations from global ones


def relative_rotation(parent: np.ndarray, child: np.ndarray) -> np.ndarray:
    """``parentᵀ @ child`` ``(..., 3, 3)``: a child's global rotation expressed in its parent's frame."""
    return np.swapaxes(parent, -1, -2) @ child


def relative_rotation_torch(parent: torch.Tensor, child: torch.Tensor) -> torch.Tensor:
    """Torch twin of :func:`relative_rotation`."""
    return parent.transpose(-1, -2) @ child


def _parent_index(parents: Sequence[int] | np.ndarray) -> tuple[list[int], list[int]]:
    """Each joint's parent (the root's own index for the root) and the roots."""
    parents = [int(p) for p in parents]
    return [p if p >= 0 else j for j, p in enumerate(parents)], [j for j, p in enumerate(parents) if p < 0]


def local_rotations(global_rotations: np.ndarray, parents: Sequence[int] | np.ndarray) -> np.ndarray:
    """Local rotations from global ones (forward kinematics composes them back: ``R = R_parent @ R_local``).

    Args:
        global_rotations: ``(..., joints, 3, 3)`` global rotation matrices.
        parents: ``(joints,)`` parent indices, -1 for a root.

    Returns:
        ``(..., joints, 3, 3)``: ``R_parentᵀ @ R`` for every joint, the global rotation for a root.
    """
    index, roots = _parent_index(parents)
    local = relative_rotation(global_rotations[..., index, :, :], global_rotations)
    local[..., roots, :, :] = global_rotations[..., roots, :, :]
    return local


def local_rotations_torch(global_rotations: torch.Tensor, parents: Sequence[int] | np.ndarray) -> torch.Tensor:
    """Torch twin of :func:`local_rotations`."""
    import torch
    index, roots = _parent_index(parents)
    local = relative_rotation_torch(global_rotations[..., index, :, :], global_rotations)
    is_root = torch.zeros(len(index), 1, 1, dtype=torch.bool, device=global_rotations.device)
    is_root[roots] = True
    return torch.where(is_root, global_rotations, local)


# ---------------------------------------------------------------------------------------------
# Two-bone inverse kinematics


def two_bone_ik(
    root: np.ndarray, target: np.ndarray, pole: np.ndarray, upper: np.ndarray | float, lower: np.ndarray | float,
    law: str = "distances", margin: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Middle joint of a two-bone chain (hip → knee → ankle) whose end reaches for ``target``.

    The chain keeps its bone lengths; the middle joint lies in the plane of the root→target line
    and ``pole``, on the pole's side of that line.

    Args:
        root: ``(..., 3)`` the chain's fixed root (hip), metres.
        target: ``(..., 3)`` where its end (ankle) should be, metres.
        pole: ``(..., 3)`` a direction the middle joint bends towards (its part across the
            root→target line counts).
        upper, lower: bone lengths root→middle and middle→end, metres: numbers, or arrays
            ``(..., 1)``.
        law: two roundings of the same geometry. ``"distances"``: the middle joint lies
            ``(u² − l² + d²) / 2d`` along the root→target line (``d`` its length) and
            ``√(u² − along²)`` across it. ``"cosines"``: the angle at the root from the law of
            cosines (clipped to ``[-1, 1]``), middle ``= root + u (cos α · axis + sin α · bend)``.
            Both are kept so that the two callers — the synthetic data set (``distances``) and the
            foot clean-up of synthesized walks (``cosines``) — compute, bit for bit, what they
            computed before they shared this function.
        margin: if given, the root–end distance is clamped to ``[|u − l| + margin, u + l − margin]``
            metres (a target out of reach is pulled towards the root); None: no clamping (the
            caller guarantees reach, as the synthetic generator does).

    Returns:
        ``(middle, end)`` ``(..., 3)`` each: the middle joint and the reached end (``target``
        itself without ``margin``).
    """
    if law not in IK_LAWS:
        raise ValueError(f"law must be one of {IK_LAWS}, got {law!r}")
    to_target = target - root
    dist = np.linalg.norm(to_target, axis=-1, keepdims=True)
    axis = to_target / np.maximum(dist, EPSILON)
    reach = dist if margin is None else np.clip(dist, np.abs(upper - lower) + margin, upper + lower - margin)
    bend = pole - np.sum(pole * axis, axis=-1, keepdims=True) * axis
    bend = bend / np.maximum(np.linalg.norm(bend, axis=-1, keepdims=True), EPSILON)
    if law == "distances":
        along = (upper**2 - lower**2 + reach**2) / (2 * reach)
        across = np.sqrt(np.maximum(upper**2 - along**2, 0.0))
        middle = root + along * axis + across * bend
    else:
        cos = np.clip((upper**2 + reach**2 - lower**2) / (2 * upper * reach), -1.0, 1.0)
        middle = root + upper * (cos * axis + np.sqrt(1.0 - cos**2) * bend)
    end = target if margin is None else root + axis * reach
    return middle, end


def two_bone_ik_torch(
    root: torch.Tensor, target: torch.Tensor, pole: torch.Tensor, upper: torch.Tensor | float,
    lower: torch.Tensor | float, law: str = "distances", margin: float | None = None,
) -> tuple[torch.Tensor, torch.Tensor]:
    """Torch twin of :func:`two_bone_ik` (its gradient is infinite where the chain is straight)."""
    import torch
    if law not in IK_LAWS:
        raise ValueError(f"law must be one of {IK_LAWS}, got {law!r}")
    to_target = target - root
    dist = torch.linalg.norm(to_target, dim=-1, keepdim=True)
    axis = to_target / torch.clamp(dist, min=EPSILON)
    if margin is None:
        reach = dist
    else:
        low = torch.as_tensor(abs(upper - lower) + margin, dtype=dist.dtype, device=dist.device)
        high = torch.as_tensor(upper + lower - margin, dtype=dist.dtype, device=dist.device)
        reach = torch.minimum(torch.maximum(dist, low), high)
    bend = pole - torch.sum(pole * axis, dim=-1, keepdim=True) * axis
    bend = bend / torch.clamp(torch.linalg.norm(bend, dim=-1, keepdim=True), min=EPSILON)
    if law == "distances":
        along = (upper**2 - lower**2 + reach**2) / (2 * reach)
        across = torch.sqrt(torch.clamp(upper**2 - along**2, min=0.0))
        middle = root + along * axis + across * bend
    else:
        cos = torch.clamp((upper**2 + reach**2 - lower**2) / (2 * upper * reach), -1.0, 1.0)
        middle = root + upper * (cos * axis + torch.sqrt(1.0 - cos**2) * bend)
    end = target if margin is None else root + axis * reach
    return middle, end
