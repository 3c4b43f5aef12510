"""From autoencoder features to motions: decode, restore each clip's duration, integrate the root.

One path for every consumer (sampling in notebooks, validation MPJPE, evaluation, GIFs)::

    features (n, C, T') ──AE decode──▶ time-normalized frames (n, L, 66)
        ──restore_duration (per sample)──▶ frames at ``fps`` (n_i frames each)
        ──frames_to_positions──▶ positions (n_i, 21, 3), metres, from the origin facing +Z

It is vectorized: the AE decodes in large chunks, and samples whose restored lengths are equal are
resampled and integrated together (a primitive's durations span a few dozen frame counts).

Samples of different durations are returned in padded tensors: entries past ``num_frames[i]``
repeat sample ``i``'s last valid frame (the pose is held; a GIF shows the figure standing at its
end), so ``positions[i, :num_frames[i]]`` (or :meth:`MotionSamples.motion`) is the motion itself.
Statistics over frames must use :attr:`MotionSamples.mask`.

The models' ``sample(n, seed=...)`` (:class:`~stylemotion.models.vae.PrimitiveVAE`,
:class:`~stylemotion.models.cvae.StyleCVAE`) end here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from stylemotion.primitives.segmentation import restore_duration
from stylemotion.representation import FRAME_DIM, frames_to_positions
from stylemotion.skeleton import NUM_JOINTS

#: Samples decoded by the autoencoder at once (bounds peak memory: ~60 MB per 1,000 at 256 × 9).
DEFAULT_CHUNK = 4096


@dataclass
class MotionSamples:
    """A batch of motions of one primitive.

    Attributes:
        positions: ``(n, frames, 21, 3)`` float32 global joint positions, metres, Y up, at ``fps``;
            every sample starts with its root above the origin facing +Z. Padded (see module doc).
        frames: ``(n, frames, 66)`` float32 frames at ``fps`` (velocities per second), padded likewise.
        num_frames: ``(n,)`` int64 valid frames of each sample (``round(duration_s · fps) + 1``).
        duration_s: ``(n,)`` float32 durations, seconds.
        features: ``(n, channels, steps)`` float32 autoencoder features the motions were decoded from.
        normalized_frames: ``(n, timeline, 66)`` float32 time-normalized frames (the AE's output).
        fps: frame rate of ``positions`` and ``frames``.
        latent: ``(n, latent_dim)`` latent codes, or None (e.g. reconstructions of data).
    """

    positions: torch.Tensor
    frames: torch.Tensor
    num_frames: torch.Tensor
    duration_s: torch.Tensor
    features: torch.Tensor
    normalized_frames: torch.Tensor
    fps: float
    latent: torch.Tensor | None = None

    def __len__(self) -> int:
        return int(self.positions.shape[0])

    @property
    def mask(self) -> torch.Tensor:
        """``(n, frames)`` bool: True on each sample's valid frames."""
        steps = torch.arange(self.positions.shape[1], device=self.num_frames.device)
        return steps[None, :] < self.num_frames[:, None]

    def motion(self, index: int) -> torch.Tensor:
        """``(num_frames[index], 21, 3)`` positions of one sample, without padding."""
        return self.positions[index, : int(self.num_frames[index])]

    def subset(self, index: torch.Tensor | slice | list[int]) -> MotionSamples:
        """The samples at ``index`` (padding is kept at the full batch's length)."""
        return MotionSamples(self.positions[index], self.frames[index], self.num_frames[index],
                             self.duration_s[index], self.features[index], self.normalized_frames[index],
                             self.fps, None if self.latent is None else self.latent[index])


@torch.no_grad()
def decode_features(autoencoder, features: torch.Tensor, duration_s: torch.Tensor, timeline_frames: int,
                    fps: float, chunk_size: int = DEFAULT_CHUNK) -> MotionSamples:
    """Decode raw autoencoder features to motions with their durations applied.

    Args:
        autoencoder: a :class:`~stylemotion.models.autoencoder.MotionAutoencoder` (its ``decode``).
        features: ``(n, channels, steps)`` raw (un-normalized) features.
        duration_s: ``(n,)`` durations, seconds (> 0).
        timeline_frames: the primitive's canonical length, frames (what the features were encoded from).
        fps: output frame rate.
        chunk_size: samples per autoencoder call.

    Returns:
        :class:`MotionSamples` (``latent`` None), on the CPU.
    """
    if features.dim() != 3:
        raise ValueError(f"features must be (n, channels, steps), got {tuple(features.shape)}")
    n = features.shape[0]
    normalized = torch.cat([autoencoder.decode(features[i:i + chunk_size], timeline_frames).float().cpu()
                            for i in range(0, n, chunk_size)]) if n else torch.zeros(0, timeline_frames, FRAME_DIM)
    return motions_from_normalized(normalized, duration_s, fps, features.detach().float().cpu())


def motions_from_normalized(normalized: torch.Tensor, duration_s: torch.Tensor, fps: float,
                            features: torch.Tensor | None = None) -> MotionSamples:
    """Time-normalized frames ``(n, timeline, 66)`` played back at their durations ``(n,)`` (seconds, > 0) and
    ``fps``: frames and global positions (``features``: what they were decoded from, else empty ``(n, 0, 0)``)."""
    n = normalized.shape[0]
    duration_s = torch.as_tensor(duration_s, dtype=torch.float32).reshape(-1).cpu()
    if duration_s.shape[0] != n:
        raise ValueError(f"need one duration per sample: {n} samples, {duration_s.shape[0]} durations")
    if n and not bool((duration_s > 0).all()):
        raise ValueError("durations must be positive")
    # restore_duration's length rule, computed in double precision like Python floats
    lengths = torch.clamp(torch.round(duration_s.double() * fps).long() + 1, min=2)
    width = int(lengths.max()) if n else 2
    frames = torch.empty(n, width, normalized.shape[-1])
    positions = torch.empty(n, width, NUM_JOINTS, 3)
    num_frames = torch.empty(n, dtype=torch.int64)
    normalized_np = normalized.numpy()
    for length in torch.unique(lengths).tolist():
        idx = torch.nonzero(lengths == length).squeeze(1)
        group = torch.from_numpy(restore_duration(normalized_np[idx.numpy()], float(duration_s[idx[0]]), fps))
        got = group.shape[-2]
        pos = frames_to_positions(group, fps)
        frames[idx, :got], positions[idx, :got] = group, pos
        if got < width:
            frames[idx, got:] = group[:, -1:]
            positions[idx, got:] = pos[:, -1:]
        num_frames[idx] = got
    return MotionSamples(positions, frames, num_frames, duration_s,
                         torch.zeros(n, 0, 0) if features is None else features, normalized, float(fps))


def masked_mpjpe(pred: torch.Tensor, true: torch.Tensor, num_frames: torch.Tensor) -> torch.Tensor:
    """Mean per-joint position error over the valid frames of padded motions, metres.

    Args:
        pred, true: ``(n, frames_a, joints, 3)`` and ``(n, frames_b, joints, 3)`` positions, metres.
        num_frames: ``(n,)`` valid frames of each motion (≤ both padded lengths).

    Returns:
        Scalar: the mean over samples' valid frames and joints of the Euclidean distance.
    """
    width = int(num_frames.max())
    if width > pred.shape[1] or width > true.shape[1]:
        raise ValueError(f"num_frames up to {width} but motions hold {pred.shape[1]} and {true.shape[1]} frames")
    dist = torch.linalg.vector_norm(pred[:, :width] - true[:, :width].to(pred), dim=-1).mean(-1)
    mask = (torch.arange(width, device=dist.device)[None, :] < num_frames.to(dist.device)[:, None]).to(dist)
    return (dist * mask).sum() / mask.sum()


def pad_motions(motions: list[np.ndarray]) -> tuple[torch.Tensor, torch.Tensor]:
    """Stack ``(frames_i, ...)`` arrays into ``(n, max frames, ...)`` holding each last frame, plus lengths."""
    if not motions:
        raise ValueError("no motion to pad")
    width = max(len(m) for m in motions)
    out = np.empty((len(motions), width) + motions[0].shape[1:], dtype=np.float32)
    for i, m in enumerate(motions):
        out[i, : len(m)] = m
        out[i, len(m):] = m[-1]
    return torch.from_numpy(out), torch.tensor([len(m) for m in motions], dtype=torch.int64)
