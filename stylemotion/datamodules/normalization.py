"""Per-channel z-score normalization of 66-dim frames, stored as buffers so it travels in checkpoints.

Statistics come from the training split only (:func:`channel_stats`); a channel whose standard
deviation is below ``std_floor`` (e.g. the Hips' x and z, which are 0 by construction in the
root-local representation) keeps a floor so that dividing by it never blows noise up.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import torch
from torch import nn

#: Smallest standard deviation used for a channel (in the channel's own unit: m, m/s or rad/s).
DEFAULT_STD_FLOOR = 1e-3


def channel_stats(
    sequences: Iterable[np.ndarray], std_floor: float = DEFAULT_STD_FLOOR
) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation of every channel over all frames of ``sequences``.

    Args:
        sequences: arrays ``(frames, channels)``; accumulated in float64.
        std_floor: lower bound of the returned standard deviation.

    Returns:
        ``mean`` and ``std``, each ``(channels,)`` float32.
    """
    count, total, total_sq = 0, None, None
    for seq in sequences:
        seq = np.asarray(seq, dtype=np.float64)
        if seq.ndim != 2:
            raise ValueError(f"sequences must be (frames, channels), got {seq.shape}")
        if total is None:
            total, total_sq = np.zeros(seq.shape[1]), np.zeros(seq.shape[1])
        count += seq.shape[0]
        total += seq.sum(axis=0)
        total_sq += np.square(seq).sum(axis=0)
    if not count:
        raise ValueError("cannot compute normalization statistics from no frames")
    mean = total / count
    var = np.maximum(total_sq / count - np.square(mean), 0.0)
    std = np.maximum(np.sqrt(var), std_floor)
    return mean.astype(np.float32), std.astype(np.float32)


class Normalizer(nn.Module):
    """``(x - mean) / std`` over the last dimension, with ``mean``/``std`` as persistent buffers.

    A fresh normalizer is the identity (mean 0, std 1) and reports ``initialized == False`` until
    :meth:`set_stats` is called (or a checkpoint holding the statistics is loaded).
    """

    def __init__(self, channels: int):
        super().__init__()
        self.channels = channels
        self.register_buffer("mean", torch.zeros(channels))
        self.register_buffer("std", torch.ones(channels))
        self.register_buffer("_initialized", torch.zeros((), dtype=torch.bool))

    @property
    def initialized(self) -> bool:
        return bool(self._initialized)

    def set_stats(self, mean: np.ndarray | torch.Tensor, std: np.ndarray | torch.Tensor) -> None:
        """Install statistics ``(channels,)``; std must be positive and both finite."""
        mean_t = torch.as_tensor(np.asarray(mean), dtype=torch.float32).reshape(-1)
        std_t = torch.as_tensor(np.asarray(std), dtype=torch.float32).reshape(-1)
        if mean_t.numel() != self.channels or std_t.numel() != self.channels:
            raise ValueError(f"normalization statistics must have {self.channels} channels, got "
                             f"mean {tuple(mean_t.shape)} and std {tuple(std_t.shape)}")
        if not (torch.isfinite(mean_t).all() and torch.isfinite(std_t).all() and (std_t > 0).all()):
            raise ValueError("normalization statistics must be finite with std > 0")
        self.mean.copy_(mean_t)
        self.std.copy_(std_t)
        self._initialized.fill_(True)

    def normalize(self, x: torch.Tensor) -> torch.Tensor:
        """``(..., channels)`` raw values to z-scores."""
        return (x - self.mean) / self.std

    def denormalize(self, z: torch.Tensor) -> torch.Tensor:
        """``(..., channels)`` z-scores back to raw values."""
        return z * self.std + self.mean
