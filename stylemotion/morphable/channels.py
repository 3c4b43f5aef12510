"""The channels a clip is represented by before the spline fit (Du §3.3.3), and back to joints.

Two representations of a primitive clip (``(T, 21, 3)`` positions from the origin facing +Z, or its
``(T, 66)`` frames):

* ``quaternion`` (the thesis'): root translation (3, metres) and each joint's local rotation as a unit
  quaternion in scipy's **xyzw** order (21 × 4), fitted to a skeleton with fixed bones (the primitive's
  median bone lengths, :func:`stylemotion.ik.rest_offsets`) by :func:`stylemotion.ik.fit_rotations`;
  back to positions by :func:`stylemotion.skeleton.forward_kinematics`. 87 channels, 22 functions.
* ``frames``: the 66-dim frames themselves (:mod:`stylemotion.representation`); back to positions by
  :func:`~stylemotion.representation.frames_to_positions`. 66 channels, 23 functions (21 joints, the
  root's ground velocity, its yaw rate).

A *function* is a group of channels sharing one weight in normalized FPCA / SFPCA (§3.3.4).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from stylemotion.ik import fit_rotations, rest_offsets
from stylemotion.representation import FRAME_DIM, frames_to_positions
from stylemotion.skeleton import CANONICAL_JOINTS, CANONICAL_PARENTS, NUM_JOINTS, forward_kinematics

REPRESENTATIONS = ("quaternion", "frames")
#: Frames decoded to positions at once (bounds the rotation matrices held in memory).
DECODE_CHUNK = 200_000


def _continuous(quats: np.ndarray) -> np.ndarray:
    """``(T, J, 4)`` quaternions with signs flipped so consecutive frames lie in one hemisphere, and
    the first frame with w ≥ 0 (q and −q are the same rotation; splines need one of them)."""
    q = quats.copy()
    q[0] *= np.where(q[0, :, 3:4] < 0, -1.0, 1.0)
    for t in range(1, q.shape[0]):
        q[t] *= np.where((q[t] * q[t - 1]).sum(-1, keepdims=True) < 0, -1.0, 1.0)
    return q


@dataclass
class Channels:
    """One representation of clips as channels.

    Attributes:
        kind: ``quaternion`` or ``frames``.
        offsets: ``(21, 3)`` bone offsets, metres, of the quaternion skeleton (None for ``frames``).
    """

    kind: str
    offsets: np.ndarray | None = None

    def __post_init__(self) -> None:
        if self.kind not in REPRESENTATIONS:
            raise ValueError(f"unknown representation {self.kind!r}; one of {list(REPRESENTATIONS)}")
        if self.kind == "quaternion" and self.offsets is None:
            raise ValueError("the quaternion representation needs bone offsets (Channels.for_positions)")

    @classmethod
    def for_positions(cls, kind: str, positions: list[np.ndarray]) -> Channels:
        """The representation fitted to clips' ``(T_i, 21, 3)`` positions (median bone lengths)."""
        offsets = rest_offsets(np.concatenate(positions)) if kind == "quaternion" else None
        return cls(kind, offsets)

    @property
    def size(self) -> int:
        return 3 + 4 * NUM_JOINTS if self.kind == "quaternion" else FRAME_DIM

    @property
    def functions(self) -> list[tuple[str, slice]]:
        """``(name, channel slice)`` of each function."""
        if self.kind == "quaternion":
            return [("root_translation", slice(0, 3))] + [
                (name, slice(3 + 4 * j, 7 + 4 * j)) for j, name in enumerate(CANONICAL_JOINTS)]
        return [(name, slice(3 * j, 3 * j + 3)) for j, name in enumerate(CANONICAL_JOINTS)] + [
            ("root_velocity", slice(3 * NUM_JOINTS, 3 * NUM_JOINTS + 2)),
            ("yaw_rate", slice(3 * NUM_JOINTS + 2, FRAME_DIM))]

    def encode(self, positions: np.ndarray, frames: np.ndarray) -> np.ndarray:
        """``(T, size)`` channels of one clip from its ``(T, 21, 3)`` positions and ``(T, 66)`` frames."""
        if self.kind == "frames":
            return np.asarray(frames, dtype=np.float64)
        fit = fit_rotations(positions, CANONICAL_PARENTS, self.offsets)
        quats = Rotation.from_matrix(fit.local_rotations.reshape(-1, 3, 3)).as_quat()
        quats = _continuous(quats.reshape(-1, NUM_JOINTS, 4))
        return np.concatenate([fit.root_translation, quats.reshape(len(quats), -1)], axis=1)

    def positions(self, channels: np.ndarray, fps: float | np.ndarray = 30.0,
                  rotations: bool = False) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
        """Joint positions ``(..., T, 21, 3)`` metres of channels ``(..., T, size)``.

        ``fps``: frame rate of the channels (``frames`` integrates root velocities with it; a number or
        ``(...,)`` per clip). ``rotations``: also return ``(..., T, 21, 3, 3)`` global joint rotations
        (``quaternion`` only).
        """
        channels = np.asarray(channels, dtype=np.float64)
        if self.kind == "frames":
            if rotations:
                raise ValueError("joint orientations need the quaternion representation; this model uses frames")
            fps_arr = np.asarray(fps, dtype=np.float64)
            rate = fps_arr[..., None] if fps_arr.ndim else float(fps_arr)
            return frames_to_positions(channels, rate if np.ndim(rate) == 0 else _torch(rate))
        lead, frames = channels.shape[:-1], int(np.prod(channels.shape[:-1]))
        flat = channels.reshape(frames, -1)
        pos = np.empty((frames, NUM_JOINTS, 3))
        rot = np.empty((frames, NUM_JOINTS, 3, 3)) if rotations else None
        step = max(1, DECODE_CHUNK // NUM_JOINTS)
        trans = np.broadcast_to(self.offsets, (NUM_JOINTS, 3)).copy()
        for i in range(0, frames, step):
            part = flat[i:i + step]
            quats = part[:, 3:].reshape(-1, 4)
            norm = np.linalg.norm(quats, axis=-1, keepdims=True)
            quats = np.where(norm > 1e-9, quats / np.maximum(norm, 1e-12), [0.0, 0.0, 0.0, 1.0])
            local = Rotation.from_quat(quats).as_matrix().reshape(len(part), NUM_JOINTS, 3, 3)
            t = np.repeat(trans[None], len(part), axis=0)
            t[:, CANONICAL_PARENTS.index(-1)] = part[:, :3]
            out = forward_kinematics(local, t, CANONICAL_PARENTS, return_rotations=rotations)
            if rotations:
                pos[i:i + step], rot[i:i + step] = out
            else:
                pos[i:i + step] = out
        pos = pos.reshape(lead + (NUM_JOINTS, 3))
        return (pos, rot.reshape(lead + (NUM_JOINTS, 3, 3))) if rotations else pos


def _torch(rate: np.ndarray):
    import torch

    return torch.as_tensor(rate)
