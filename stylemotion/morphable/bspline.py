"""Functional representation of motion clips (Du §3.3.3): cubic B-splines with equally spaced knots.

A clip's channels sampled on ``T`` frames become ``K`` coefficients per channel of a clamped cubic
B-spline on the normalized time ``u ∈ [0, 1]`` (``K − 4`` equally spaced interior knots). Fitting is
scipy's least-squares spline (:func:`scipy.interpolate.make_lsq_spline`), one solve for all clips and
channels together; evaluation at any number of frames is :class:`scipy.interpolate.BSpline`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import BSpline, make_lsq_spline

DEGREE = 3


@dataclass(frozen=True)
class SplineBasis:
    """A clamped cubic B-spline basis with ``num_coefficients`` functions on ``[0, 1]``.

    Attributes:
        num_coefficients: ``K`` ≥ 4, coefficients per channel.
    """

    num_coefficients: int

    def __post_init__(self) -> None:
        if int(self.num_coefficients) < DEGREE + 1:
            raise ValueError(f"a cubic B-spline needs at least {DEGREE + 1} coefficients, got {self.num_coefficients}")

    @property
    def knots(self) -> np.ndarray:
        """``(K + 4,)`` knot vector: 0 and 1 repeated four times around equally spaced interior knots."""
        interior = np.linspace(0.0, 1.0, self.num_coefficients - DEGREE + 1)[1:-1]
        return np.concatenate([np.zeros(DEGREE + 1), interior, np.ones(DEGREE + 1)])

    def fit(self, values: np.ndarray) -> np.ndarray:
        """Least-squares coefficients of samples on equally spaced times.

        Args:
            values: ``(..., T, C)`` channels on ``T`` equally spaced frames spanning ``[0, 1]``;
                ``T ≥ K``.

        Returns:
            ``(..., C, K)`` float64 coefficients.
        """
        values = np.asarray(values, dtype=np.float64)
        if values.ndim < 2:
            raise ValueError(f"values must be (..., frames, channels), got shape {values.shape}")
        frames = values.shape[-2]
        if frames < self.num_coefficients:
            raise ValueError(f"{frames} frames cannot determine {self.num_coefficients} spline coefficients; "
                             "use fewer coefficients (K ≤ the shortest clip's frames)")
        lead, channels = values.shape[:-2], values.shape[-1]
        y = np.moveaxis(values.reshape(-1, frames, channels), 1, 0).reshape(frames, -1)
        spline = make_lsq_spline(np.linspace(0.0, 1.0, frames), y, self.knots, k=DEGREE)
        coeffs = spline.c.reshape(self.num_coefficients, -1, channels)  # (K, batch, C)
        return np.moveaxis(coeffs, 0, -1).reshape(lead + (channels, self.num_coefficients))

    def matrix(self, times: np.ndarray) -> np.ndarray:
        """``(len(times), K)`` basis function values at normalized ``times`` in ``[0, 1]`` (read-only; short
        time grids, such as a timeline or a few keyframes evaluated again and again, are cached)."""
        u = np.clip(np.asarray(times, dtype=np.float64), 0.0, 1.0)
        if u.ndim == 1 and len(u) <= CACHED_TIMES:
            return _design_matrix(self.knots.tobytes(), u.tobytes())
        return BSpline.design_matrix(u, self.knots, DEGREE).toarray()

    def evaluate(self, coefficients: np.ndarray, frames: int | np.ndarray) -> np.ndarray:
        """Channels at ``frames`` equally spaced times (an int) or at given normalized times.

        Args:
            coefficients: ``(..., C, K)``.
            frames: a number of frames ≥ 2 spanning ``[0, 1]``, or ``(T,)`` normalized times.

        Returns:
            ``(..., T, C)`` float64.
        """
        times = np.linspace(0.0, 1.0, int(frames)) if np.ndim(frames) == 0 else np.asarray(frames)
        return np.einsum("tk,...ck->...tc", self.matrix(times), np.asarray(coefficients, dtype=np.float64))


#: Longest time grid whose design matrix is cached.
CACHED_TIMES = 256


@functools.lru_cache(maxsize=128)
def _design_matrix(knots: bytes, times: bytes) -> np.ndarray:
    out = BSpline.design_matrix(np.frombuffer(times), np.frombuffer(knots), DEGREE).toarray()
    out.flags.writeable = False
    return out
