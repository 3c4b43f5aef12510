"""Metrics the thesis lacks: Fréchet distance, diversity, foot skating, nearest-training-clip distance.

Each function states its definition; the report repeats it. Features are rows of a ``(n, d)``
array (e.g. the style classifier's feature space, :mod:`stylemotion.evaluation.classifier`); motions
are padded ``(n, frames, 21, 3)`` positions in metres with ``num_frames`` valid frames each, as in
:class:`stylemotion.sampling.MotionSamples`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy import linalg
from scipy.spatial.distance import pdist

from stylemotion.contacts import foot_contacts, planted_point_speed
from stylemotion.representation import FRAME_DIM, JOINT_DIMS
from stylemotion.skeleton import NUM_JOINTS

#: Planted-point speed (m/s) above which a foot in contact counts as skating.
SKATE_SPEED_MPS = 0.2


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


@dataclass
class FootSkating:
    """Foot-skating statistics of a set of motions (see :func:`foot_skating`).

    Attributes:
        ratio: skating foot-frames / contact foot-frames.
        contact_share: contact foot-frames / all valid foot-frames.
        no_plant_share: share of motions whose planted foot (``stance_foot``) is never in contact
            (NaN when no stance foot is given).
        planted_mid_mps: mean planted-point speed of the stance foot over the middle half of each
            motion, m/s (NaN when no stance foot is given).
        contact_frames: number of contact foot-frames behind ``ratio``.
        skating_frames: number of skating foot-frames.
        foot_frames: number of valid foot-frames (2 per valid frame).
        motions: number of motions.
    """

    ratio: float
    contact_share: float
    no_plant_share: float
    planted_mid_mps: float
    contact_frames: int
    skating_frames: int
    foot_frames: int
    motions: int

    def as_dict(self) -> dict[str, float | int]:
        return asdict(self)


def foot_skating(positions: np.ndarray, num_frames: np.ndarray, fps: float, rest_heights: np.ndarray,
                 stance_foot: int | None = None, skate_speed: float = SKATE_SPEED_MPS) -> FootSkating:
    """Foot-skating ratio: the share of foot-frames in ground contact whose foot slides.

    Contacts come from THE contact detector, :func:`stylemotion.contacts.foot_contacts` (a foot is
    in contact while its heel or ball is low and slow, with hysteresis), judged against the resting
    heights of **real** data (``rest_heights``), so a floating foot is never in contact. A contact
    foot-frame *skates* when the foot's planted-point speed
    (:func:`stylemotion.contacts.planted_point_speed`: the slower of heel and ball, horizontal,
    m/s) exceeds ``skate_speed``. Because the detector itself needs the foot to be slow, a foot
    that slides fast through a whole stance is not in contact at all: ``no_plant_share`` (stance
    foot never in contact) and ``planted_mid_mps`` (its speed over the middle half of the motion)
    catch that case; compare every number with the same statistic of real clips.

    Args:
        positions: ``(n, frames, 21, 3)`` padded positions, metres, Y up.
        num_frames: ``(n,)`` valid frames of each motion (≥ 2).
        fps: frames per second.
        rest_heights: ``(2, 2)`` resting heights of (foot, [heel, ball]) above y = 0, metres, from real data.
        stance_foot: 0 (left) or 1 (right) planted foot of the primitive, or None.
        skate_speed: m/s.

    Returns:
        :class:`FootSkating`.
    """
    p = np.asarray(positions, dtype=np.float64)
    lengths = np.asarray(num_frames, dtype=np.int64).reshape(-1)
    if p.ndim != 4 or p.shape[2:] != (NUM_JOINTS, 3) or len(p) != len(lengths):
        raise ValueError(f"positions must be (n, frames, {NUM_JOINTS}, 3) with one num_frames each, got {p.shape} "
                         f"and {lengths.shape}")
    if len(p) == 0 or lengths.min() < 2 or lengths.max() > p.shape[1]:
        raise ValueError(f"need ≥ 1 motion with 2 ≤ num_frames ≤ {p.shape[1]}, got {lengths.tolist()[:8]}")
    contact_frames = skating_frames = valid = no_plant = 0
    mids = []
    for length in np.unique(lengths):  # equal lengths are detected together
        group = p[lengths == length, :length]
        contact = foot_contacts(group, fps, rest_heights=rest_heights)  # (k, length, 2)
        speed = planted_point_speed(group, fps)
        contact_frames += int(contact.sum())
        skating_frames += int((contact & (speed > skate_speed)).sum())
        valid += contact.size
        if stance_foot is not None:
            no_plant += int((~contact[:, :, stance_foot].any(1)).sum())
            lo, hi = length // 4, max(length - length // 4, length // 4 + 1)
            mids.append(speed[:, lo:hi, stance_foot].mean(1))
    n = len(p)
    return FootSkating(
        ratio=skating_frames / contact_frames if contact_frames else float("nan"),
        contact_share=contact_frames / valid,
        no_plant_share=no_plant / n if stance_foot is not None else float("nan"),
        planted_mid_mps=float(np.concatenate(mids).mean()) if mids else float("nan"),
        contact_frames=contact_frames, skating_frames=skating_frames, foot_frames=valid, motions=n)


def pooled_skating(parts: list[FootSkating]) -> FootSkating:
    """Several :class:`FootSkating` results as one (ratios pooled over foot-frames and motions)."""
    if not parts:
        raise ValueError("nothing to pool")
    contact = sum(p.contact_frames for p in parts)
    skating = sum(p.skating_frames for p in parts)
    motions = sum(p.motions for p in parts)
    valid = sum(p.foot_frames for p in parts)

    def weighted(name: str) -> float:
        values = [(getattr(p, name), p.motions) for p in parts if np.isfinite(getattr(p, name))]
        return float(sum(v * w for v, w in values) / sum(w for _, w in values)) if values else float("nan")

    return FootSkating(ratio=skating / contact if contact else float("nan"),
                       contact_share=contact / valid if valid else 0.0, no_plant_share=weighted("no_plant_share"),
                       planted_mid_mps=weighted("planted_mid_mps"), contact_frames=contact, skating_frames=skating,
                       foot_frames=valid, motions=motions)
