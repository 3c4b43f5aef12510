"""Canonical positions ⇄ 66-dim frames (thesis §5.2).

A frame holds, in this order:

* ``[0:63]``  the 21 canonical joints' xyz (joint-major: joint ``j`` at ``3j:3j+3``), in metres,
  relative to the root's ground projection (the Hips' x and z; y stays height above the ground)
  and rotated about the vertical so that the body faces +Z (+X is the body's left);
* ``[63:65]`` the root's ground velocity (x, z) in the body's frame, metres per second;
* ``[65]``    the yaw rate about +Y, radians per second (positive turns +Z towards +X).

Velocities are forward differences: frame ``t`` holds the motion from ``t`` to ``t+1`` expressed in
frame ``t``'s facing; the last frame repeats the previous one. The inverse integrates the root from
a start placement, so positions → frames → positions is exact up to float error once the first
frame's placement and heading are given.

Yaw ``θ`` rotates about +Y: ``x' = x cosθ + z sinθ``, ``z' = −x sinθ + z cosθ``, so the facing
direction of yaw ``θ`` is ``(sin θ, 0, cos θ)``.

One implementation each: :func:`positions_to_frames` (numpy, data preparation) and
:func:`frames_to_positions` (torch, differentiable; numpy in, numpy out), whose root integration
:func:`integrate_root` is also what synthesis uses to place steps. The rotations about the vertical
and the angle wrapping are those of :mod:`stylemotion.geometry`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from stylemotion.geometry import direction_yaw, rotate_yaw, rotate_yaw_torch, rotate_yaw_xz_torch, wrap_angle
from stylemotion.skeleton import JOINT_INDEX, NUM_JOINTS

if TYPE_CHECKING:  # torch is imported by the functions that use it, so that the numpy paths (search,
    import torch  # reconstruct, annotate, datasets) start without it (docs/architecture.md)

#: Identifier of the 66-dim frame layout below; a model trained on one representation refuses data or
#: checkpoints of another. Bump when the layout changes.
REPRESENTATION = "stylemotion.frames66/v1"
#: Values of the root-local joint positions in a frame (63: 21 joints × xyz).
POSITION_DIM = 3 * NUM_JOINTS
#: Values per frame (66): joint positions, root ground velocity (2), yaw rate (1).
FRAME_DIM = POSITION_DIM + 3
#: Where the parts of a frame lie in its values.
JOINT_DIMS = slice(0, POSITION_DIM)
VELOCITY_DIMS = slice(POSITION_DIM, POSITION_DIM + 2)
YAW_RATE_DIM = POSITION_DIM + 2
ROOT_JOINT = JOINT_INDEX["Hips"]


def facing_yaw(positions: np.ndarray, fps: float, smooth_seconds: float = 0.15) -> np.ndarray:
    """Facing angle per frame from hips and shoulders, smoothed in time.

    Args:
        positions: ``(..., frames, 21, 3)`` canonical positions, metres, Y up.
        fps: frames per second (sets the smoothing width).
        smooth_seconds: standard deviation of the Gaussian smoothing of the facing vector,
            seconds; 0 disables smoothing.

    Returns:
        ``(..., frames)`` yaw in radians; the body faces ``(sin yaw, 0, cos yaw)``.
    """
    across = (positions[..., JOINT_INDEX["UpperLeg_L"], :] - positions[..., JOINT_INDEX["UpperLeg_R"], :]) + (
        positions[..., JOINT_INDEX["UpperArm_L"], :] - positions[..., JOINT_INDEX["UpperArm_R"], :]
    )
    # forward = across × up = (-a_z, 0, a_x)
    forward = np.stack([-across[..., 2], across[..., 0]], axis=-1)
    sigma = smooth_seconds * fps
    if sigma > 0 and forward.shape[-2] > 1:
        from scipy.ndimage import gaussian_filter1d  # here: scipy.ndimage costs ~0.5 s of start-up

        forward = gaussian_filter1d(forward, sigma, axis=-2, mode="nearest")
    return direction_yaw(forward)


def positions_to_frames(
    positions: np.ndarray, fps: float, smooth_seconds: float = 0.15
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """66-dim frames of a take.

    Args:
        positions: ``(frames, 21, 3)`` canonical global positions, metres, Y up; frames ≥ 2.
        fps: frames per second of ``positions``.
        smooth_seconds: facing smoothing (see :func:`facing_yaw`).

    Returns:
        ``frames`` ``(frames, 66)`` float32, and the first frame's root placement ``(2,)`` (x, z)
        and heading (yaw, radians) — what :func:`frames_to_positions` needs to put the take back
        where it was.
    """
    positions = np.asarray(positions, dtype=np.float64)
    if positions.ndim != 3 or positions.shape[1:] != (NUM_JOINTS, 3):
        raise ValueError(f"positions must be (frames, {NUM_JOINTS}, 3), got {positions.shape}")
    n = positions.shape[0]
    if n < 2:
        raise ValueError(f"a take needs at least 2 frames for velocities, got {n}")
    yaw = facing_yaw(positions, fps, smooth_seconds)
    root = positions[:, ROOT_JOINT, :].copy()
    root[:, 1] = 0.0
    local = rotate_yaw(positions - root[:, None, :], -yaw[:, None])
    step = rotate_yaw(root[1:] - root[:-1], -yaw[:-1]) * fps
    velocity = np.concatenate([step[:, [0, 2]], step[-1:, [0, 2]]], axis=0)
    turn = wrap_angle(np.diff(yaw)) * fps
    yaw_rate = np.concatenate([turn, turn[-1:]])
    frames = np.concatenate([local.reshape(n, POSITION_DIM), velocity, yaw_rate[:, None]], axis=1)
    return frames.astype(np.float32), root[0, [0, 2]].copy(), float(yaw[0])


def integrate_root(
    frames: torch.Tensor,
    fps: float | torch.Tensor,
    start_xz: np.ndarray | torch.Tensor | None = None,
    start_yaw: float | np.ndarray | torch.Tensor = 0.0,
) -> tuple[torch.Tensor, torch.Tensor]:
    """The root's ground track and heading from 66-dim frames (torch, differentiable).

    Args:
        frames: ``(..., frames, 66)`` torch tensor.
        fps: frames per second: a number, or a tensor broadcastable to ``(..., 1)`` (one rate per
            motion, e.g. a time-normalized clip's playback rate ``(length − 1) / duration``, so the
            result is differentiable in the duration too).
        start_xz: ``(..., 2)`` root ground position of the first frame, metres (default origin).
        start_yaw: ``(...)`` heading of the first frame, radians (default 0: facing +Z).

    Returns:
        ``root_xz`` ``(..., frames, 2)`` metres and ``yaw`` ``(..., frames)`` radians (not wrapped).
    """
    import torch
    f = frames
    dtype, lead = f.dtype, f.shape[:-2]
    yaw0 = torch.as_tensor(start_yaw, dtype=dtype, device=f.device).expand(lead)
    xz0 = (torch.zeros(lead + (2,), dtype=dtype, device=f.device) if start_xz is None
           else torch.as_tensor(start_xz, dtype=dtype, device=f.device).expand(lead + (2,)))
    turn = f[..., :-1, YAW_RATE_DIM] / fps
    yaw = torch.cat([yaw0.unsqueeze(-1), yaw0.unsqueeze(-1) + torch.cumsum(turn, dim=-1)], dim=-1)
    vx, vz = f[..., :-1, VELOCITY_DIMS.start] / fps, f[..., :-1, VELOCITY_DIMS.start + 1] / fps
    step = rotate_yaw_xz_torch(torch.stack([vx, vz], dim=-1), yaw[..., :-1])  # world step = R_y(yaw) (vx, 0, vz)
    root_xz = torch.cat([xz0.unsqueeze(-2), xz0.unsqueeze(-2) + torch.cumsum(step, dim=-2)], dim=-2)
    return root_xz, yaw


def frames_to_positions(
    frames: np.ndarray | torch.Tensor,
    fps: float | torch.Tensor,
    start_xz: np.ndarray | torch.Tensor | None = None,
    start_yaw: float | np.ndarray | torch.Tensor = 0.0,
) -> np.ndarray | torch.Tensor:
    """Global positions from 66-dim frames by integrating the root (differentiable in torch).

    Args:
        frames: ``(..., frames, 66)``; numpy in gives numpy out, torch in gives torch out.
        fps: frames per second of ``frames`` (a number, or per motion, see :func:`integrate_root`).
        start_xz: ``(..., 2)`` root ground position of the first frame, metres (default origin).
        start_yaw: ``(...)`` heading of the first frame, radians (default 0: facing +Z).

    Returns:
        ``(..., frames, 21, 3)`` global positions, metres, Y up.
    """
    import torch
    as_numpy = isinstance(frames, np.ndarray)
    f = torch.as_tensor(frames) if as_numpy else frames
    if f.shape[-1] != FRAME_DIM:
        raise ValueError(f"frames must end in {FRAME_DIM} values, got shape {tuple(f.shape)}")
    dtype = f.dtype if f.is_floating_point() else torch.float32
    if as_numpy:
        dtype = torch.float64  # integrate in double precision for numpy callers
    f = f.to(dtype)
    root_xz, yaw = integrate_root(f, fps, start_xz, start_yaw)
    local = rotate_yaw_torch(f[..., JOINT_DIMS].reshape(f.shape[:-1] + (NUM_JOINTS, 3)), yaw.unsqueeze(-1))
    x = local[..., 0] + root_xz[..., :1]
    z = local[..., 2] + root_xz[..., 1:]
    positions = torch.stack([x, local[..., 1], z], dim=-1)
    return positions.numpy() if as_numpy else positions
