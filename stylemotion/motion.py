"""The Motion container: a skeleton plus per-frame local rotations and translations.

Rotations are stored as unit quaternions in **scalar-last (x, y, z, w)** order, the order of
``scipy.spatial.transform.Rotation``; they are converted to matrices only for FK.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from stylemotion.skeleton import Skeleton, forward_kinematics


@dataclass
class Motion:
    """A motion in the units and axes of its source.

    Attributes:
        skeleton: the joint hierarchy.
        rotations: ``(frames, joints, 4)`` local rotations, quaternions (x, y, z, w).
        translations: ``(frames, joints, 3)`` local translations (OFFSETs, replaced by position
            channels where a joint has them), file units.
        fps: frames per second.
        source: where it came from (file path or ``zip::member``), for messages.
    """

    skeleton: Skeleton
    rotations: np.ndarray
    translations: np.ndarray
    fps: float
    source: str = "<memory>"

    @property
    def num_frames(self) -> int:
        return self.rotations.shape[0]

    @property
    def duration(self) -> float:
        """Seconds from the first to the last frame."""
        return (self.num_frames - 1) / self.fps

    def rotation_matrices(self) -> np.ndarray:
        """``(frames, joints, 3, 3)`` local rotation matrices."""
        flat = self.rotations.reshape(-1, 4)
        return Rotation.from_quat(flat).as_matrix().reshape(self.rotations.shape[:-1] + (3, 3))

    def global_positions(self) -> np.ndarray:
        """``(frames, joints, 3)`` global joint positions in file units (numpy FK)."""
        return forward_kinematics(self.rotation_matrices(), self.translations, self.skeleton.parents)

    def resampled_length(self, fps: float) -> int:
        """Frames that :meth:`resample` to ``fps`` gives (computed without resampling)."""
        if abs(fps - self.fps) < 1e-9 * fps or self.num_frames < 2:
            return self.num_frames
        return int(np.floor(self.duration * fps + 1e-6)) + 1

    def resample(self, fps: float) -> Motion:
        """Resample to ``fps``: slerp for rotations, linear interpolation for translations.

        The new timeline starts at the first frame and covers the original duration; the last
        new frame is at or before the original last frame.
        """
        if fps <= 0:
            raise ValueError(f"{self.source}: target fps must be positive, got {fps}")
        if abs(fps - self.fps) < 1e-9 * fps or self.num_frames < 2:
            # Same rate, or a single pose (nothing to interpolate): only the stated fps changes.
            return replace(self, fps=float(fps))
        times = np.arange(self.num_frames) / self.fps
        n_new = self.resampled_length(fps)
        new_times = np.minimum(np.arange(n_new) / fps, times[-1])
        rotations = np.empty((n_new,) + self.rotations.shape[1:])
        for j in range(self.skeleton.num_joints):
            slerp = Slerp(times, Rotation.from_quat(self.rotations[:, j]))
            rotations[:, j] = slerp(new_times).as_quat()
        # Linear interpolation of translations, vectorized over joints and axes.
        idx = np.clip(np.searchsorted(times, new_times, side="right") - 1, 0, self.num_frames - 2)
        w = ((new_times - times[idx]) * self.fps)[:, None, None]
        translations = (1 - w) * self.translations[idx] + w * self.translations[idx + 1]
        return replace(self, rotations=rotations, translations=translations, fps=float(fps))
