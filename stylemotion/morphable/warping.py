"""Time warping to a canonical timeline (Du §4.4.1).

Every clip of a primitive is aligned by dynamic time warping (dtaidistance's multivariate DTW) to the
reference clip, the one whose length is the primitive's median length (``L`` frames). The warping
function ``w(i)``, ``i = 0 … L−1``, gives the clip's own frame (fractional, at the data's fps) shown at
canonical frame ``i``; it starts at 0, ends at the clip's last frame ``n − 1`` and never decreases. The
clip's channels resampled at ``w`` are its time-aligned version; ``w`` itself is kept (as a spline with
the spatial basis, :mod:`.model`) so that samples vary in timing and duration too.
"""

from __future__ import annotations

import numpy as np
from dtaidistance import dtw_ndim

#: Smallest step of a warping function, frames (keeps it strictly increasing, hence invertible).
MIN_STEP = 1e-3


def monotone(warp: np.ndarray, last: float | np.ndarray | None = None) -> np.ndarray:
    """``(..., L)`` warping functions made non-decreasing (running maximum) with steps ≥ :data:`MIN_STEP`,
    starting at 0; ``last``: also end there (frames), by scaling."""
    w = np.maximum.accumulate(np.asarray(warp, dtype=np.float64), axis=-1)
    w = w - w[..., :1]
    w = w + MIN_STEP * np.arange(w.shape[-1])
    if last is not None:
        w = w * (np.asarray(last, dtype=np.float64)[..., None] / np.maximum(w[..., -1:], MIN_STEP))
    return w


def dtw_warp(reference: np.ndarray, clip: np.ndarray) -> np.ndarray:
    """``(L,)`` warping function aligning ``clip`` ``(n, d)`` to ``reference`` ``(L, d)`` (features such as
    root-local joint positions): each reference frame gets the mean clip frame the DTW path matches to it."""
    reference, clip = np.ascontiguousarray(reference, dtype=np.double), np.ascontiguousarray(clip, dtype=np.double)
    path = np.asarray(dtw_ndim.warping_path(reference, clip, use_c=True))  # the C path: ~50× faster, same path
    sums = np.bincount(path[:, 0], weights=path[:, 1], minlength=len(reference))
    counts = np.bincount(path[:, 0], minlength=len(reference))
    return monotone(sums / np.maximum(counts, 1), last=len(clip) - 1)


def resample(values: np.ndarray, at: np.ndarray) -> np.ndarray:
    """``(n, C)`` frames linearly interpolated at fractional frame indices ``at`` ``(m,)`` → ``(m, C)``."""
    values = np.asarray(values, dtype=np.float64)
    src = np.arange(len(values), dtype=np.float64)
    return np.stack([np.interp(at, src, values[:, c]) for c in range(values.shape[1])], axis=1)


def canonical_times(warp: np.ndarray, num_frames: int) -> np.ndarray:
    """Normalized canonical times ``(num_frames,)`` in ``[0, 1]`` of a clip's own frames ``0 … num_frames−1``
    under a monotone warping function ``warp`` ``(L,)`` (its inverse, scaled so the clip ends at ``w(L−1)``)."""
    canonical = np.linspace(0.0, 1.0, len(warp))
    own = np.linspace(0.0, float(warp[-1]), num_frames)
    return np.interp(own, warp, canonical)
