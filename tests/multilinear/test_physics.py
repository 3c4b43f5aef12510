import numpy as np
import pytest

from stylemotion.datasets import load_dataset
from stylemotion.geometry import rotate_yaw
from stylemotion.multilinear.physics import SEGMENTS, balanced, body_com, physics_features
from stylemotion.skeleton import JOINT_INDEX


@pytest.fixture(scope="module")
def walk():
    takes = load_dataset("synthetic").takes
    return next(t.positions for t in takes if t.content == "walk").astype(np.float64)


def test_masses_sum_to_one_and_a_rigid_shift_moves_the_com():
    assert sum(s[2] for s in SEGMENTS.values()) == pytest.approx(1.0)
    p = np.random.default_rng(0).normal(size=(4, 21, 3))
    assert np.allclose(body_com(p + [1.0, 2.0, 3.0]), body_com(p) + [1.0, 2.0, 3.0])


def test_features_ignore_where_the_body_is_and_which_way_it_faces(walk):
    moved = rotate_yaw(walk, 0.7) + np.array([3.0, 0.0, -2.0])
    assert np.allclose(physics_features(moved, 30.0), physics_features(walk, 30.0), atol=1e-9)


def test_a_body_gliding_at_constant_velocity_has_no_com_acceleration(walk):
    still = np.repeat(walk[:1], 20, axis=0) + np.arange(20)[:, None, None] * np.array([0.05, 0.0, 0.0])
    assert np.abs(physics_features(still, 30.0)[:, :3]).max() < 1e-9


def test_a_foot_turning_about_the_ankle_has_the_angular_momentum_m_r2_omega(walk):
    frames, omega = 30, 2.0                                         # rad/s about the vertical
    p = np.repeat(walk[:1], frames, axis=0)
    ankle, toe = JOINT_INDEX["Foot_L"], JOINT_INDEX["Toes_L"]
    offset = np.array([0.0, 0.0, 0.15])                            # a horizontal foot, 15 cm
    angle = omega * np.arange(frames) / 30.0
    p[:, toe] = p[:, ankle] + rotate_yaw(np.repeat(offset[None], frames, axis=0), angle)
    f = physics_features(p, 30.0, ("foot_l",))
    _, _, mass, at = SEGMENTS["foot_l"]
    want = mass * (at * 0.15) ** 2 * omega
    assert np.allclose(f[2:-2, 4], want, rtol=1e-2)                # the y component; ends: one-sided differences
    assert np.abs(f[2:-2, [3, 5]]).max() < 1e-9
    assert np.allclose(np.sqrt(np.mean(np.sum(balanced(f).reshape(frames, -1, 3) ** 2, axis=2), axis=0))[1], 1.0)
