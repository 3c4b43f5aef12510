"""Per-channel z-score statistics of 66-dim frames (the module that applies them and carries them in
checkpoints as buffers is :class:`stylemotion.models.normalization.Normalizer`).

Statistics come from the training split only (:func:`channel_stats`); a channel whose standard
deviation is below ``std_floor`` (e.g. the Hips' x and z, which are 0 by construction in the
root-local representation) keeps a floor so that dividing by it never blows noise up.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

__all__ = ["DEFAULT_STD_FLOOR", "channel_stats"]

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
