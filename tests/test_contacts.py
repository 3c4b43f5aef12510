"""Foot contacts: ground truth of the synthetic generator, invariances, bad input."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.synthetic import CONTENTS, STYLES, generate_take
from stylemotion.primitives.contacts import (
    ContactSettings,
    _fill_low_gaps,
    contact_intervals,
    foot_contacts,
    foot_signals,
    leg_length,
    planted_point_speed,
)


def _interval_errors(truth: np.ndarray, detected: np.ndarray) -> list[tuple[int, int]]:
    """(onset error, offset error) in frames of every interior true contact interval, matched
    one-to-one with the detected intervals overlapping it; AssertionError on a missing or split one."""
    n = truth.shape[0]
    errors = []
    for foot in (0, 1):
        found = contact_intervals(detected[:, foot])
        for a, b in contact_intervals(truth[:, foot]):
            if a == 0 or b == n:
                continue  # cut by the take's start or end: its true extent is unknown
            overlapping = [(c, d) for c, d in found if c < b and d > a]
            assert len(overlapping) == 1, f"foot {foot} contact [{a}, {b}) detected as {overlapping}"
            c, d = overlapping[0]
            errors.append((c - a, d - b))
    return errors


@pytest.mark.parametrize("content", CONTENTS)
def test_synthetic_contacts_within_two_frames_at_30fps(content: str) -> None:
    errors = []
    for style in STYLES:
        for index in range(2):
            take = generate_take(content, style, index, seed=3, fps=30.0, duration_s=4.0)
            detected = foot_contacts(take.positions, take.fps)
            errors += _interval_errors(take.contacts, detected)
    errors = np.array(errors)
    assert len(errors) > 40
    assert np.abs(errors).max() <= 2, f"worst onset/offset error {np.abs(errors).max(0)} frames"
    assert np.abs(errors).mean() < 1.0


def test_contacts_do_not_depend_on_frame_rate() -> None:
    """At 60 fps the errors stay within the same time (±2 frames at 30 fps = ±1/15 s)."""
    worst = 0.0
    for content in ("walk", "run"):
        for style in ("elderly", "youthful", "exhausted"):
            take = generate_take(content, style, 0, seed=4, fps=60.0, duration_s=3.0)
            errors = _interval_errors(take.contacts, foot_contacts(take.positions, take.fps))
            worst = max(worst, np.abs(errors).max() / 60.0)
    assert worst <= 2 / 30 + 1e-9


def test_runs_have_flight_and_walks_double_support() -> None:
    run = generate_take("run", "normal", 0, seed=0, duration_s=4.0)
    walk = generate_take("walk", "normal", 0, seed=0, duration_s=4.0)
    run_c = foot_contacts(run.positions, run.fps)
    walk_c = foot_contacts(walk.positions, walk.fps)
    assert (~run_c.any(1)).sum() >= 0.5 * (~run.contacts.any(1)).sum() > 0  # flights found
    assert not (~walk_c.any(1)).any()  # a walk is never airborne
    assert (walk_c.all(1)).sum() > 0  # double support found


def test_thresholds_scale_with_body_size_and_ground_level() -> None:
    take = generate_take("walk", "elderly", 1, seed=0, duration_s=4.0)
    base = foot_contacts(take.positions, take.fps)
    child = take.positions * 0.55  # a small body: heights and speeds shrink together
    assert leg_length(child) == pytest.approx(0.55 * leg_length(take.positions))
    np.testing.assert_array_equal(foot_contacts(child, take.fps), base)
    raised = take.positions + np.array([0.0, 0.4, 0.0], np.float32)  # floor at y = 0.4 m
    np.testing.assert_array_equal(foot_contacts(raised, take.fps), base)


def test_batched_input_matches_single_sequences() -> None:
    a = generate_take("walk", "normal", 0, seed=0, duration_s=2.0)
    b = generate_take("run", "active", 0, seed=0, duration_s=2.0)
    batch = foot_contacts(np.stack([a.positions, b.positions]), 30.0)
    assert batch.shape == (2, 60, 2) and batch.dtype == bool
    np.testing.assert_array_equal(batch[0], foot_contacts(a.positions, 30.0))
    np.testing.assert_array_equal(batch[1], foot_contacts(b.positions, 30.0))


def test_standing_still_and_gliding() -> None:
    pose = generate_take("walk", "normal", 0, seed=0, duration_s=1.0).positions[0]
    standing = np.repeat(pose[None], 30, axis=0)
    assert foot_contacts(standing, 30.0).all()
    glide = standing + (np.arange(30)[:, None, None] * np.array([0.0, 0.0, 0.1])).astype(np.float32)  # 3 m/s
    assert not foot_contacts(glide, 30.0).any()


def test_fixed_rest_heights_judge_a_floating_body() -> None:
    """Given the resting heights of real data, a body floating 20 cm up is never in contact."""
    take = generate_take("walk", "normal", 0, seed=0, duration_s=2.0)
    rest = foot_signals(take.positions, take.fps).rest_heights
    floating = take.positions + np.array([0.0, 0.2, 0.0], np.float32)
    assert foot_contacts(floating, take.fps).any()  # own resting heights: the floor moved up
    assert not foot_contacts(floating, take.fps, rest_heights=rest).any()


def test_planted_point_speed_is_zero_on_planted_feet() -> None:
    take = generate_take("walk", "masculine", 0, seed=0, duration_s=3.0)
    speed = planted_point_speed(take.positions, take.fps)
    assert speed.shape == (90, 2)
    inner = take.contacts.copy()
    inner[1:-1] &= take.contacts[:-2] & take.contacts[2:]  # away from strike and lift-off
    assert speed[inner].max() < 1e-3
    assert speed[~take.contacts].mean() > 1.0


def test_short_pivot_gaps_are_filled_only_when_the_foot_stays_low() -> None:
    contact = np.array([1, 1, 1, 0, 0, 1, 1, 0, 0, 0, 0, 0, 1], bool)
    low = np.array([1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 1, 1], bool)
    filled = _fill_low_gaps(contact, low, max_gap=3)
    np.testing.assert_array_equal(filled, [1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 1])
    assert not _fill_low_gaps(np.array([0, 0, 1, 1], bool), np.ones(4, bool), 3)[:2].any()  # edge gap kept


def test_bad_input() -> None:
    take = generate_take("walk", "normal", 0, seed=0, duration_s=1.0)
    with pytest.raises(ValueError, match=r"\(\.\.\., frames, 21, 3\)"):
        foot_contacts(take.positions[:, :20], 30.0)
    with pytest.raises(ValueError, match="at least 2 frames"):
        foot_contacts(take.positions[:1], 30.0)
    with pytest.raises(ValueError, match="0 < on <= off"):
        ContactSettings(speed_on=0.8, speed_off=0.5)


def test_contact_intervals() -> None:
    assert contact_intervals(np.array([0, 1, 1, 0, 1], bool)) == [(1, 3), (4, 5)]
    assert contact_intervals(np.zeros(3, bool)) == []
