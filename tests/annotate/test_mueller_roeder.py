"""Müller & Röder's features on constructed poses whose answers are known (body facing +Z, its left +X, Y up)."""

import numpy as np
import pytest

from stylemotion.annotate.features import FeatureInputError
from stylemotion.annotate.mueller_roeder import (
    FEATURE_NAMES,
    NUM_FEATURES,
    hysteresis,
    mueller_roeder_features,
    plane_distance,
)
from stylemotion.skeleton import JOINT_INDEX as J

FPS = 30.0
HL = 0.28          # the constructed humerus: |UpperArm − LowerArm|

STANDING = {
    "Hips": (0, 1.0, 0), "Spine": (0, 1.15, 0), "Chest": (0, 1.3, 0), "Neck": (0, 1.5, 0), "Head": (0, 1.65, 0),
    "Shoulder_L": (0.08, 1.45, 0), "UpperArm_L": (0.18, 1.45, 0), "LowerArm_L": (0.18, 1.17, 0),
    "Hand_L": (0.18, 0.92, 0), "UpperLeg_L": (0.1, 0.95, 0), "LowerLeg_L": (0.1, 0.5, 0),
    "Foot_L": (0.1, 0.08, 0), "Toes_L": (0.1, 0.0, 0.12),
}
STANDING.update({k.replace("_L", "_R"): (-x, y, z) for k, (x, y, z) in list(STANDING.items()) if k.endswith("_L")})


def still(frames: int = 60) -> np.ndarray:
    """``(frames, 21, 3)`` of the standing pose."""
    pose = np.zeros((21, 3))
    for name, xyz in STANDING.items():
        pose[J[name]] = xyz
    return np.repeat(pose[None], frames, axis=0)


def column(motion: np.ndarray, name: str) -> np.ndarray:
    return mueller_roeder_features(motion, FPS)[:, FEATURE_NAMES.index(name)]


MIDDLE = slice(15, 45)       # away from the ends, where the velocity windows are cut


def test_names_shape_and_standing_pose():
    f = mueller_roeder_features(still(), FPS)
    assert f.shape == (60, NUM_FEATURES) == (60, 40) and f.dtype == bool and len(set(FEATURE_NAMES)) == 40
    on = {n for n, v in zip(FEATURE_NAMES, f.any(0)) if v}
    # standing still, arms hanging, feet together: no relation holds (hands 0.92 m above the toes: not lowered)
    assert on == set(), on


def test_hysteresis_switches_on_at_the_strict_and_off_at_the_loose_threshold():
    x = np.array([0.0, 1.5, 2.5, 1.5, 1.5, 0.5, 1.5, 2.5, 0.0])   # loose 1, strict 2
    assert hysteresis(x > 1, x > 2).tolist() == [False, False, True, True, True, False, False, True, False]
    # between the thresholds from the start: off until decided
    assert hysteresis(np.array([True, True]), np.array([False, False])).tolist() == [False, False]


def test_hand_in_front_of_and_behind_the_body_plane():
    m = still(3)
    neck, rhip, lhip = m[:, J["Neck"]], m[:, J["UpperLeg_R"]], m[:, J["UpperLeg_L"]]
    front, back = m[:, J["Hand_R"]] + [0, 0, 0.3], m[:, J["Hand_R"]] - [0, 0, 0.2]
    assert np.allclose(plane_distance(neck, rhip, lhip, front), 0.3)     # the torso plane's normal points ahead
    assert np.allclose(plane_distance(neck, rhip, lhip, back), -0.2)


@pytest.mark.parametrize("speed_hl, on", [(2.2, True), (1.0, False)])
def test_right_hand_moving_forward(speed_hl, on):
    m = still()
    m[:, J["Hand_R"], 2] += speed_hl * HL * np.arange(60) / FPS
    assert column(m, "rhand_moving_forward")[MIDDLE].all() == on
    assert not column(m, "lhand_moving_forward").any()
    m[:, J["Hand_R"], 2] *= -1                                             # moving back: never forward
    assert not column(m, "rhand_moving_forward").any()


def test_right_hand_above_neck():
    m = still()
    m[30:, J["Hand_R"]] = (-0.18, 1.9, 0.0)                                # raised above the head
    f = column(m, "rhand_above_neck")
    assert not f[:30].any() and f[30:].all() and not column(m, "lhand_above_neck").any()


def test_knee_bent_and_straight():
    m = still()
    m[:, J["Foot_R"]] = (-0.1, 0.5, -0.42)                                 # shin horizontal behind: 90° knee
    m[:, J["Toes_R"]] = (-0.1, 0.45, -0.5)
    assert column(m, "rknee_bent").all() and not column(m, "lknee_bent").any()


def test_foot_fast_and_still():
    m = still()
    for j in ("Foot_R", "Toes_R"):
        m[:, J[j], 2] += 3.0 * HL * np.arange(60) / FPS                   # 3 hl/s, above the strict 2.5
    assert column(m, "rfoot_fast")[MIDDLE].all() and not column(m, "lfoot_fast").any()


def test_foot_speed_between_the_thresholds_keeps_the_state():
    def foot_at(speeds_hl: np.ndarray) -> np.ndarray:
        m = still(len(speeds_hl))
        for j in ("Foot_R", "Toes_R"):
            m[:, J[j], 2] += np.cumsum(speeds_hl) * HL / FPS
        return column(m, "rfoot_fast")

    rising = foot_at(np.r_[np.zeros(20), np.full(40, 2.25)])              # still, then between 2 and 2.5 hl/s
    assert not rising[25:55].any()
    falling = foot_at(np.r_[np.full(20, 3.0), np.full(40, 2.25)])         # fast, then between the thresholds
    assert falling[5:55].all()


def test_foot_behind_the_other_leg():
    m = still()
    m[:30, J["Foot_R"], 2] -= 0.5 * HL                                     # behind the left leg's plane
    m[30:, J["Foot_R"], 2] += 0.5 * HL                                     # in front of it
    f = column(m, "rfoot_behind_lleg")
    assert f[:30].all() and not f[30:].any()
    # the relation is between the legs: with the right foot ahead, the left ankle is behind the right leg's plane
    g = column(m, "lfoot_behind_rleg")
    assert g[30:].all() and not g[:30].any()


def test_hands_far_apart_in_a_t_pose():
    m = still()
    for side, sign in (("L", 1), ("R", -1)):
        m[:, J[f"LowerArm_{side}"]] = (sign * 0.46, 1.45, 0)
        m[:, J[f"Hand_{side}"]] = (sign * 0.71, 1.45, 0)
    f = mueller_roeder_features(m, FPS)
    on = {n for n, v in zip(FEATURE_NAMES, f.all(0)) if v}
    assert {"hands_far_apart", "rhumerus_abducted", "lhumerus_abducted"} <= on
    assert not column(still(), "hands_far_apart").any()


def test_scale_and_facing_invariance():
    rng = np.random.default_rng(0)
    m = still() + np.cumsum(rng.normal(0, 0.004, (60, 21, 3)), axis=0)
    m[:, :, 2] += 1.2 * np.arange(60)[:, None] / FPS                       # walking forward
    f = mueller_roeder_features(m, FPS)
    assert np.array_equal(mueller_roeder_features(m * 1.5, FPS), f)
    turned = m[..., [2, 1, 0]] * [1, 1, -1]                                # the whole motion turned 90° about Y
    assert np.array_equal(mueller_roeder_features(turned, FPS), f)


def test_bad_input_is_named():
    with pytest.raises(FeatureInputError, match="21, 3"):
        mueller_roeder_features(np.zeros((5, 20, 3)), FPS)
    with pytest.raises(FeatureInputError, match="fps"):
        mueller_roeder_features(still(), 0.0)
