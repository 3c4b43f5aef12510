"""Stance travel: does the root move as far as the planted leg sweeps under it?

In a stance primitive (e.g. ``walk_leftStance``) one foot holds the ground. Over the middle half of the motion the
root then travels exactly as far as it moves *relative to that foot*: root travel ÷ leg travel is 1 and the foot
stays put. A model that widens the leg sweep without moving the root faster (or the reverse) makes the planted foot
slide, often too fast for the contact detector to call it planted at all, so the skating share
(:mod:`stylemotion.primitives.skating`) leaves the motion out; these figures show the mismatch itself.

The spreads over motions of the root's travel and of the leg's (the root relative to the stance foot: how far the
root would travel were the foot planted) tell variation in the steps from variation that only a sliding foot makes:
a model whose root speed varies while its legs do not has a wide root spread and a narrow leg spread.

Motions are padded ``(n, frames, 21, 3)`` positions in metres with ``num_frames`` valid frames each, as in
:class:`stylemotion.models.sampling.MotionSamples`.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from stylemotion.primitives.skating import padded_motions
from stylemotion.skeleton import FOOT_POINTS


@dataclass
class StanceTravel:
    """Stance travel of a set of motions (see :func:`stance_travel`); means over motions unless said.

    Attributes:
        root_travel_m: horizontal root travel over the middle half, metres.
        leg_travel_m: horizontal travel of the root relative to the planted foot over the middle half, metres (the
            smaller over heel and ball).
        travel_ratio: median over motions of root travel ÷ leg travel (1: the foot holds the ground).
        foot_drift_m: horizontal travel of the planted foot over the middle half, metres (the smaller over heel and
            ball).
        root_speed_mps: root travel over the whole motion ÷ its duration, m/s.
        duration_s: duration, seconds.
        motions: number of motions.
        root_travel_sd_m: standard deviation over motions of the root travel over the middle half, metres (None
            for one motion).
        leg_travel_sd_m: the same of the leg travel, metres (None for one motion).
        root_speed_sd_mps: the same of the root travel ÷ the middle half's duration, m/s (None for one motion).
        leg_speed_sd_mps: the same of the leg travel ÷ the middle half's duration, m/s (None for one motion).
    """

    root_travel_m: float
    leg_travel_m: float
    travel_ratio: float
    foot_drift_m: float
    root_speed_mps: float
    duration_s: float
    motions: int
    root_travel_sd_m: float | None = None
    leg_travel_sd_m: float | None = None
    root_speed_sd_mps: float | None = None
    leg_speed_sd_mps: float | None = None

    def as_dict(self) -> dict[str, float | int]:
        return asdict(self)


def stance_travel(positions: np.ndarray, num_frames: np.ndarray, fps: float, stance_foot: int) -> StanceTravel:
    """Root travel against leg travel over the middle half of each motion (module doc).

    The middle half of a motion of ``m`` valid frames is frames ``⌊m/4⌋`` to ``m − ⌊m/4⌋ − 1``.

    Args:
        positions: ``(n, frames, 21, 3)`` padded positions, metres, Y up.
        num_frames: ``(n,)`` valid frames of each motion (≥ 4).
        fps: frames per second.
        stance_foot: 0 (left) or 1 (right): the foot the primitive plants.

    Returns:
        :class:`StanceTravel`.
    """
    p, lengths = padded_motions(positions, num_frames, 4)
    if stance_foot not in (0, 1):
        raise ValueError(f"stance_foot must be 0 (left) or 1 (right), got {stance_foot!r}")
    rows = np.empty((len(p), 6))
    for i, (motion, m) in enumerate(zip(p, lengths)):
        ground = motion[:m][..., [0, 2]]  # (m, 21, 2) horizontal
        root, foot = ground[:, 0], ground[:, FOOT_POINTS[stance_foot]]  # (m, 2), (m, 2 points, 2)
        lo, hi = m // 4, m - m // 4 - 1
        relative = root[:, None] - foot  # (m, 2 points, 2)
        rows[i] = (np.linalg.norm(root[hi] - root[lo]), np.linalg.norm(relative[hi] - relative[lo], axis=-1).min(),
                   np.linalg.norm(foot[hi] - foot[lo], axis=-1).min(),
                   np.linalg.norm(root[m - 1] - root[0]) * fps / (m - 1), (m - 1) / fps, (hi - lo) / fps)
    ratio = rows[:, 0] / np.maximum(rows[:, 1], 1e-6)

    def sd(values: np.ndarray) -> float | None:
        return float(values.std(ddof=1)) if len(values) > 1 else None

    return StanceTravel(root_travel_m=float(rows[:, 0].mean()), leg_travel_m=float(rows[:, 1].mean()),
                        travel_ratio=float(np.median(ratio)), foot_drift_m=float(rows[:, 2].mean()),
                        root_speed_mps=float(rows[:, 3].mean()), duration_s=float(rows[:, 4].mean()),
                        motions=len(p), root_travel_sd_m=sd(rows[:, 0]), leg_travel_sd_m=sd(rows[:, 1]),
                        root_speed_sd_mps=sd(rows[:, 0] / rows[:, 5]), leg_speed_sd_mps=sd(rows[:, 1] / rows[:, 5]))
