"""Per-channel z-score normalization as an ``nn.Module`` whose statistics are persistent buffers, so
they travel in a model's checkpoint (the statistics themselves are computed by the data side:
:func:`stylemotion.datamodules.normalization.channel_stats`)."""

from __future__ import annotations

import numpy as np
import torch
from torch import nn


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
