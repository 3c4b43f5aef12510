"""Foot skating: how much a foot slides while it is in ground contact, for real or generated motions.

One definition for every caller: the evaluation's foot-skating metric
(:mod:`stylemotion.evaluation.metrics`), synthesis's check of its own walks
(:mod:`stylemotion.synthesis.quality`) and new styles' reports. Motions are padded
``(n, frames, 21, 3)`` positions in metres with ``num_frames`` valid frames each, as in
:class:`stylemotion.models.sampling.MotionSamples`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from stylemotion.primitives.contacts import foot_contacts, planted_point_speed
from stylemotion.skeleton import NUM_JOINTS

#: Planted-point speed (m/s) above which a foot in contact counts as skating.
SKATE_SPEED_MPS = 0.2


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


def padded_motions(positions: np.ndarray, num_frames: np.ndarray, min_frames: int) -> tuple[np.ndarray, np.ndarray]:
    """Padded motions ``(n, frames, 21, 3)`` as float64 and their valid frame counts ``(n,)`` as int64, checked: at
    least one motion, each with ``min_frames`` ≤ ``num_frames`` ≤ the padded length (ValueError otherwise)."""
    p = np.asarray(positions, dtype=np.float64)
    lengths = np.asarray(num_frames, dtype=np.int64).reshape(-1)
    if p.ndim != 4 or p.shape[2:] != (NUM_JOINTS, 3) or len(p) != len(lengths):
        raise ValueError(f"positions must be (n, frames, {NUM_JOINTS}, 3) with one num_frames each, got {p.shape} "
                         f"and {lengths.shape}")
    if len(p) == 0 or lengths.min() < min_frames or lengths.max() > p.shape[1]:
        raise ValueError(f"need ≥ 1 motion with {min_frames} ≤ num_frames ≤ {p.shape[1]}, got {lengths.tolist()[:8]}")
    return p, lengths


def foot_skating(positions: np.ndarray, num_frames: np.ndarray, fps: float, rest_heights: np.ndarray,
                 stance_foot: int | None = None, skate_speed: float = SKATE_SPEED_MPS) -> FootSkating:
    """Foot-skating ratio: the share of foot-frames in ground contact whose foot slides.

    Contacts come from THE contact detector, :func:`stylemotion.primitives.contacts.foot_contacts` (a foot is
    in contact while its heel or ball is low and slow, with hysteresis), judged against the resting
    heights of **real** data (``rest_heights``), so a floating foot is never in contact. A contact
    foot-frame *skates* when the foot's planted-point speed
    (:func:`stylemotion.primitives.contacts.planted_point_speed`: the slower of heel and ball, horizontal,
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
    p, lengths = padded_motions(positions, num_frames, 2)
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
