"""Stance travel (:mod:`stylemotion.primitives.stance`): a planted foot gives root travel = leg travel and no drift;
a foot sliding backwards under a slower root shows as a ratio below 1 and as drift; padding is ignored."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.primitives.stance import stance_travel
from stylemotion.skeleton import FOOT_POINTS, NUM_JOINTS

FPS = 30.0


def walker(frames: int, root_speed: float, foot_speed: float, stance: int = 0) -> np.ndarray:
    """``(frames, 21, 3)``: the root walks along +Z at ``root_speed`` m/s; the stance foot's heel and ball move along
    +Z at ``foot_speed`` m/s (0: planted); every other joint rides with the root."""
    t = np.arange(frames) / FPS
    p = np.zeros((frames, NUM_JOINTS, 3))
    p[:, :, 2] = root_speed * t[:, None]
    p[:, :, 1] = 0.9
    for joint in FOOT_POINTS[stance]:
        p[:, joint, 1] = 0.05
        p[:, joint, 2] = 0.3 + foot_speed * t
    return p


def test_a_planted_foot_travels_the_root_as_far_as_the_leg_sweeps() -> None:
    s = stance_travel(walker(17, 1.2, 0.0)[None], np.array([17]), FPS, 0)
    # the middle half of 17 frames: frames 4 .. 12, 8 frame steps of 0.04 m
    assert s.root_travel_m == pytest.approx(0.32) and s.leg_travel_m == pytest.approx(0.32)
    assert s.travel_ratio == pytest.approx(1.0) and s.foot_drift_m == pytest.approx(0.0, abs=1e-12)
    assert s.root_speed_mps == pytest.approx(1.2) and s.duration_s == pytest.approx(16 / FPS) and s.motions == 1


def test_a_foot_sliding_backwards_under_a_slower_root_shows_as_ratio_and_drift() -> None:
    s = stance_travel(walker(17, 0.9, -0.9)[None], np.array([17]), FPS, 0)
    # the root moves 0.24 m, the foot 0.24 m backwards: the leg sweeps 0.48 m
    assert s.root_travel_m == pytest.approx(0.24) and s.leg_travel_m == pytest.approx(0.48)
    assert s.travel_ratio == pytest.approx(0.5) and s.foot_drift_m == pytest.approx(0.24)
    # the same slide of the right foot, judged as a right-stance motion
    right = stance_travel(walker(17, 0.9, -0.9, stance=1)[None], np.array([17]), FPS, 1)
    assert right.travel_ratio == pytest.approx(0.5) and right.foot_drift_m == pytest.approx(0.24)


def test_padding_past_num_frames_is_ignored_and_bad_input_is_refused() -> None:
    padded = np.concatenate([walker(17, 1.2, 0.0), np.repeat(walker(17, 1.2, 0.0)[-1:], 10, 0) + 5.0])
    both = np.stack([padded, padded])
    s = stance_travel(both, np.array([17, 17]), FPS, 0)
    assert s.travel_ratio == pytest.approx(1.0) and s.motions == 2 and s.foot_drift_m == pytest.approx(0, abs=1e-12)
    with pytest.raises(ValueError, match="num_frames"):
        stance_travel(both, np.array([3, 17]), FPS, 0)
    with pytest.raises(ValueError, match="stance_foot"):
        stance_travel(both, np.array([17, 17]), FPS, 2)


def test_a_root_speed_spread_the_legs_do_not_make_shows_in_the_root_spread_only() -> None:
    # two motions, the same leg sweep (1.2 m/s relative to the stance foot): one planted, one whose foot slides
    # backwards at 0.3 m/s under a root at 0.9 m/s
    both = np.stack([walker(17, 1.2, 0.0), walker(17, 0.9, -0.3)])
    s = stance_travel(both, np.array([17, 17]), FPS, 0)
    assert s.root_travel_sd_m == pytest.approx(np.std([0.32, 0.24], ddof=1))
    assert s.leg_travel_sd_m == pytest.approx(0.0, abs=1e-12)
    assert s.root_speed_sd_mps == pytest.approx(np.std([1.2, 0.9], ddof=1))  # over the middle half's 8 / 30 s
    assert s.leg_speed_sd_mps == pytest.approx(0.0, abs=1e-12)
    one = stance_travel(both[:1], np.array([17]), FPS, 0)
    assert one.root_travel_sd_m is None and one.leg_speed_sd_mps is None
