"""Spread of repeated walks' steps and of real clips, against closed-form cases."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.representation import JOINT_DIMS
from stylemotion.synthesis.variation import clip_variation, pose_spread, step_frames


def _clip(rng, frames: int = 20) -> np.ndarray:
    return rng.normal(size=(frames, 66))


def test_identical_steps_have_no_spread():
    clip = _clip(np.random.default_rng(0))
    assert pose_spread([clip, clip.copy(), clip.copy()], 12) == pytest.approx(0.0, abs=1e-6)  # float32 resampling


def test_two_steps_apart_by_a_constant_offset_spread_by_half_of_it():
    clip = _clip(np.random.default_rng(1))
    moved = clip.copy()
    offset = np.array([0.03, -0.04, 0.0])  # 5 cm on every joint
    moved[:, JOINT_DIMS] += np.tile(offset, 21)  # 21 joints
    assert pose_spread([clip, moved], 10) == pytest.approx(0.025)


def test_clip_variation_reads_lengths_and_durations():
    rng = np.random.default_rng(2)
    frames = [_clip(rng, 31), _clip(rng, 21)]  # 1.0 s and 0.667 s at 30 fps
    positions = [np.zeros((31, 21, 3)), np.zeros((21, 21, 3))]
    positions[0][-1, 0] = [0.0, 0.9, 0.6]  # 0.6 m step
    positions[1][-1, 0] = [0.8, 0.9, 0.0]  # 0.8 m step
    v = clip_variation(frames, positions, 30.0, 15)
    assert v["step_length_sd_m"] == pytest.approx(0.1) and v["duration_sd_s"] == pytest.approx(1 / 6)
    assert v["clips"] == 2


def test_steps_share_their_junction_frame():
    frames = np.arange(10, dtype=float)[:, None].repeat(66, 1)
    parts = step_frames(frames, [0, 4, 7])
    assert [p[:, 0].tolist() for p in parts] == [[0, 1, 2, 3, 4], [4, 5, 6, 7], [7, 8, 9]]


def test_a_single_step_has_no_spread():
    with pytest.raises(ValueError, match="at least two"):
        pose_spread([np.zeros((5, 66))], 5)
