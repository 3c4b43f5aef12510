"""Foot-skating clean-up: the planted point's drift is cancelled during contact and released smoothly after it;
the knee solve keeps the leg's bone lengths; on a skating walk the planted foot holds still again and only
knees, ankles and toes move."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.synthetic import generate_take
from stylemotion.primitives.contacts import contact_intervals, foot_contacts, planted_point_speed
from stylemotion.skeleton import JOINT_INDEX, NUM_JOINTS
from stylemotion.synthesis.cleanup import REACH_MARGIN_M, clean_foot_skating, planted_drift, solve_knee

FPS = 30.0
LEG_L = [JOINT_INDEX[j] for j in ("UpperLeg_L", "LowerLeg_L", "Foot_L", "Toes_L")]
LEG_R = [JOINT_INDEX[j] for j in ("UpperLeg_R", "LowerLeg_R", "Foot_R", "Toes_R")]


def test_the_drift_of_a_sliding_planted_foot_is_cancelled_then_released() -> None:
    frames, step = 30, 0.01
    positions = np.zeros((frames, NUM_JOINTS, 3))
    for joint in ("Foot_L", "Toes_L"):
        positions[:, JOINT_INDEX[joint], 0] = step * np.arange(frames)  # heel and ball slide 1 cm per frame in x
    contact = np.zeros(frames, dtype=bool)
    contact[5:15] = True
    correction = planted_drift(positions, FPS, contact, foot=0, release_frames=4)
    assert correction.shape == (frames, 2) and np.all(correction[:, 1] == 0)  # no z drift, no z correction
    assert np.all(correction[:6] == 0)  # nothing before the contact, nothing at its first frame
    held = positions[5:15, JOINT_INDEX["Foot_L"], 0] + correction[5:15, 0]
    np.testing.assert_allclose(held, positions[5, JOINT_INDEX["Foot_L"], 0], atol=1e-12)  # held still
    released = correction[14:20, 0]
    assert np.all(np.diff(released) > 0) and released[-1] == 0  # back to zero over 4 frames, monotonically
    t = np.arange(1, 5) / 5
    np.testing.assert_allclose(correction[15:19, 0], (1 - t * t * (3 - 2 * t)) * correction[14, 0])  # smoothstep
    assert np.all(correction[19:] == 0)


def test_the_slower_point_is_the_planted_one() -> None:
    frames = 12
    positions = np.zeros((frames, NUM_JOINTS, 3))
    positions[:, JOINT_INDEX["Foot_R"], 2] = 0.02 * np.arange(frames)  # the heel slides 2 cm per frame
    positions[:, JOINT_INDEX["Toes_R"], 2] = 0.005 * np.arange(frames)  # the ball 0.5 cm: it holds the ground
    contact = np.ones(frames, dtype=bool)
    correction = planted_drift(positions, FPS, contact, foot=1, release_frames=3)
    np.testing.assert_allclose(correction[:, 1], -0.005 * np.arange(frames), atol=1e-12)
    assert np.all(correction[:, 0] == 0)


def test_the_knee_solve_keeps_bone_lengths_and_reaches_what_it_can() -> None:
    hip = np.array([[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    knee = np.array([[0.0, 0.55, 0.05], [0.0, 0.55, 0.05]])
    ankle = np.array([[0.0, 0.1, 0.0], [0.0, 0.1, 0.0]])
    target = np.array([[0.05, 0.12, 0.1], [0.0, -1.0, 0.0]])  # reachable; far below the hip: out of reach
    new_knee, reached = solve_knee(hip, knee, ankle, target)
    thigh, shin = np.linalg.norm(knee - hip, axis=-1), np.linalg.norm(ankle - knee, axis=-1)
    np.testing.assert_allclose(np.linalg.norm(new_knee - hip, axis=-1), thigh, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(reached - new_knee, axis=-1), shin, atol=1e-9)
    np.testing.assert_allclose(reached[0], target[0], atol=1e-9)
    direction = (target[1] - hip[1]) / np.linalg.norm(target[1] - hip[1])
    np.testing.assert_allclose(reached[1], hip[1] + (thigh[1] + shin[1] - REACH_MARGIN_M) * direction, atol=1e-6)
    assert new_knee[0, 2] > 0  # the knee stays on the side of the original knee (the pole)


@pytest.fixture(scope="module")
def skating_walk() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A synthetic walk, the same walk with its left foot sliding 0.5 cm per frame (15 cm/s) in each contact,
    and the walk's contacts."""
    walk = generate_take("walk", "normal", 0, seed=0, fps=FPS, duration_s=4.0).positions.astype(np.float64)
    contact = foot_contacts(walk, FPS)
    drift = np.zeros(len(walk))
    for start, stop in contact_intervals(contact[:, 0]):
        drift[start:stop] = 0.005 * np.arange(stop - start)
        after = min(3, len(walk) - stop)
        drift[stop:stop + after] = drift[stop - 1] * np.array([0.75, 0.5, 0.25])[:after]
    skating = walk.copy()
    for joint in ("Foot_L", "Toes_L"):
        skating[:, JOINT_INDEX[joint], 0] += drift
    return walk, skating, contact


def test_a_skating_foot_is_held_still_again(skating_walk) -> None:
    walk, skating, contact = skating_walk
    cleaned = clean_foot_skating(skating.astype(np.float32), FPS)
    assert cleaned.dtype == np.float64 and cleaned.shape == walk.shape
    left = contact[:, 0]
    before, after = planted_point_speed(skating, FPS)[left, 0].mean(), planted_point_speed(cleaned, FPS)[left, 0].mean()
    clean_walk = planted_point_speed(walk, FPS)[left, 0].mean()
    assert before > 5 * clean_walk and after < 1.5 * clean_walk, (before, after, clean_walk)


def test_only_knees_ankles_and_toes_move_and_the_legs_keep_their_shape(skating_walk) -> None:
    _, skating, _ = skating_walk
    cleaned = clean_foot_skating(skating, FPS)
    moved = np.flatnonzero(np.abs(cleaned - skating).max(axis=(0, 2)) > 0)
    assert set(moved.tolist()) <= {LEG_L[1], LEG_L[2], LEG_L[3], LEG_R[1], LEG_R[2], LEG_R[3]}
    assert LEG_L[2] in moved
    for hip, knee, ankle, toes in (LEG_L, LEG_R):
        for a, b in ((hip, knee), (knee, ankle)):  # thigh and shin of every frame
            np.testing.assert_allclose(np.linalg.norm(cleaned[:, a] - cleaned[:, b], axis=-1),
                                       np.linalg.norm(skating[:, a] - skating[:, b], axis=-1), atol=1e-6)
        np.testing.assert_allclose(cleaned[:, toes] - cleaned[:, ankle], skating[:, toes] - skating[:, ankle],
                                   atol=1e-9)  # the foot moves rigidly with the ankle


def test_a_foot_that_never_touches_the_ground_is_left_alone() -> None:
    walk = generate_take("walk", "normal", 0, seed=0, fps=FPS, duration_s=2.0).positions.astype(np.float64)
    flying = walk.copy()
    flying[:, :, 1] += 1.0  # the whole body a metre up, but the detector's rest heights say the ground is at 0
    cleaned = clean_foot_skating(flying, FPS, rest_heights=np.zeros((2, 2)))
    np.testing.assert_array_equal(cleaned, flying)


@pytest.mark.parametrize("shape", [(1, NUM_JOINTS, 3), (10, NUM_JOINTS - 1, 3), (10, NUM_JOINTS), (10, NUM_JOINTS, 2)])
def test_positions_of_another_shape_are_refused(shape) -> None:
    with pytest.raises(ValueError, match=r"positions must have shape \(frames, 21, 3\) with at least 2 frame"):
        clean_foot_skating(np.zeros(shape), FPS)
