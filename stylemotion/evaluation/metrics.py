"""Metrics the thesis lacks: Fréchet distance, diversity, foot skating, nearest-training-clip distance.

Foot skating is measured below the evaluation, in :mod:`stylemotion.primitives.skating` (synthesis checks its own
walks with it too); its names are kept here with the other metrics.

Each function states its definition; the report repeats it. Features are rows of a ``(n, d)``
array (e.g. the style classifier's feature space, :mod:`stylemotion.evaluation.classifier`); motions
are padded ``(n, frames, 21, 3)`` positions in metres with ``num_frames`` valid frames each, as in
:class:`stylemotion.models.sampling.MotionSamples`.
"""

from __future__ import annotations

import numpy as np
from scipy import linalg
from scipy.spatial.distance import pdist

from stylemotion.primitives.skating import SKATE_SPEED_MPS, FootSkating, foot_skating, pooled_skating
from stylemotion.representation import FRAME_DIM, JOINT_DIMS

__all__ = ["SKATE_SPEED_MPS", "FootSkating", "diversity", "foot_skating", "frechet_distance", "nearest_distances",
           "pooled_skating", "pose_sequences"]

def frechet_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Fréchet distance between Gaussians fitted to two feature sets.

    ``FD = ‖μ_a − μ_b‖² + tr(Σ_a + Σ_b − 2 (Σ_a Σ_b)^½)`` with the sample means and (unbiased)
    covariances of the rows — the FID formula, in whatever feature space the rows live in. In squared
    feature units; 0 for identical distributions; it grows with a shift of the mean and with a
    difference in spread, and is biased upwards for small sets (compare values computed with the same
    set sizes).

    Args:
        a: ``(n, d)`` features, n ≥ 2.
        b: ``(m, d)`` features, m ≥ 2.

    Returns:
        The distance (≥ 0, up to float error).
    """
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    if a.ndim != 2 or b.ndim != 2 or a.shape[1] != b.shape[1]:
        raise ValueError(f"features must be (n, d) and (m, d), got {a.shape} and {b.shape}")
    if len(a) < 2 or len(b) < 2:
        raise ValueError(f"the Fréchet distance needs at least 2 rows per set, got {len(a)} and {len(b)}")
    mu_a, mu_b = a.mean(0), b.mean(0)
    cov_a, cov_b = np.atleast_2d(np.cov(a, rowvar=False)), np.atleast_2d(np.cov(b, rowvar=False))
    root = linalg.sqrtm(cov_a @ cov_b)
    if not np.isfinite(root).all():  # singular product: regularize as the FID reference code does
        eps = 1e-6 * np.eye(cov_a.shape[0])
        root = linalg.sqrtm((cov_a + eps) @ (cov_b + eps))
    root = np.real(root)
    value = float(np.sum((mu_a - mu_b) ** 2) + np.trace(cov_a) + np.trace(cov_b) - 2.0 * np.trace(root))
    return max(value, 0.0)


def diversity(features: np.ndarray, max_items: int = 2000) -> float:
    """Mean Euclidean distance between all pairs of rows (in feature units).

    Over the first ``max_items`` rows (rows are random samples, so a prefix is a random subset);
    a set of identical motions scores 0.

    Args:
        features: ``(n, d)``, n ≥ 2.
        max_items: rows used at most (bounds the ``n²/2`` pairs).
    """
    x = np.asarray(features, dtype=np.float64)[:max_items]
    if x.ndim != 2 or len(x) < 2:
        raise ValueError(f"diversity needs (n ≥ 2, d) features, got {x.shape}")
    return float(pdist(x).mean())


def pose_sequences(normalized_frames: np.ndarray) -> np.ndarray:
    """Root-local joint positions of time-normalized clips, flattened.

    Args:
        normalized_frames: ``(n, length, 66)`` frames on one canonical timeline.

    Returns:
        ``(n, length · 63)`` float64: joints relative to the root's ground projection, facing +Z,
        metres (frame values ``[0:63]``; the root path is left out).
    """
    f = np.asarray(normalized_frames, dtype=np.float64)
    if f.ndim != 3 or f.shape[-1] != FRAME_DIM:
        raise ValueError(f"normalized frames must be (n, length, {FRAME_DIM}), got {f.shape}")
    return f[..., JOINT_DIMS].reshape(len(f), -1)


def nearest_distances(query: np.ndarray, reference: np.ndarray, chunk: int = 1024) -> np.ndarray:
    """Root-mean-square joint distance (metres) from each query clip to its nearest reference clip.

    For pose sequences of :func:`pose_sequences` (``length · 21`` joints each),
    ``d(a, b) = sqrt(mean over frames and joints of ‖a_tj − b_tj‖²) = ‖a − b‖ / sqrt(length · 21)``,
    minimized over the reference clips.

    Args:
        query: ``(n, length · 63)``.
        reference: ``(m, length · 63)``, m ≥ 1.
        chunk: query rows per distance block.

    Returns:
        ``(n,)`` metres.
    """
    q, r = np.asarray(query, dtype=np.float64), np.asarray(reference, dtype=np.float64)
    if q.ndim != 2 or r.ndim != 2 or q.shape[1] != r.shape[1] or q.shape[1] % 3:
        raise ValueError(f"need (n, k·3) query and (m, k·3) reference, got {q.shape} and {r.shape}")
    if len(r) == 0:
        raise ValueError("no reference clip to measure nearest distances to")
    points = q.shape[1] // 3
    r_sq = (r ** 2).sum(1)
    out = np.empty(len(q))
    for i in range(0, len(q), chunk):
        block = q[i:i + chunk]
        sq = (block ** 2).sum(1)[:, None] + r_sq[None, :] - 2.0 * block @ r.T
        out[i:i + chunk] = np.sqrt(np.maximum(sq.min(1), 0.0) / points)
    return out
