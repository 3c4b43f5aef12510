"""Relational features (Müller & Röder; Krüger §3.2.1): boolean relations between body points, per frame.

Each feature is a yes/no answer to a question about the pose or its speed ("is the right hand above the
neck?", "is the left knee bent?", "is the body turning fast to the left?"). Lengths are measured in body
units of the take itself, so the same thresholds hold on any skeleton mapped to the canonical 21 joints:

* ``h``: humerus length, the median of ``|UpperArm − LowerArm|`` over frames and both sides (metres);
* ``w``: shoulder width, the median of ``|UpperArm_L − UpperArm_R|`` (metres).

Speeds are in ``h`` per second, angles in degrees, the yaw rate in rad/s. Sideways and forward mean the
body's own facing (:func:`stylemotion.representation.facing_yaw`). Every feature and its threshold is listed
in docs/annotate.md; :data:`FEATURE_NAMES` gives their order.
"""

from __future__ import annotations

import numpy as np

from stylemotion.geometry import facing_direction, left_direction, wrap_angle
from stylemotion.io.errors import UserInputError
from stylemotion.representation import facing_yaw
from stylemotion.skeleton import JOINT_INDEX, checked_positions

J = JOINT_INDEX


class FeatureInputError(UserInputError, ValueError):
    """Positions that relational features cannot be computed on (wrong shape, non-finite, degenerate body)."""


def _pairs(name: str) -> list[str]:
    return [name.format(s=s) for s in ("l", "r")]


#: Names of the relational features in column order (42: 20 left/right pairs and 2 single ones).
FEATURE_NAMES: tuple[str, ...] = tuple(
    _pairs("{s}hand_in_front") + _pairs("{s}hand_behind") + _pairs("{s}hand_above_neck")
    + _pairs("{s}hand_above_head") + _pairs("{s}hand_sideways") + _pairs("{s}hand_low")
    + _pairs("{s}elbow_bent") + _pairs("{s}arm_stretched") + _pairs("{s}hand_fast")
    + _pairs("{s}hand_moving_up") + _pairs("{s}hand_moving_down") + _pairs("{s}hand_moving_sideways")
    + _pairs("{s}foot_in_front") + _pairs("{s}foot_raised") + _pairs("{s}foot_fast")
    + _pairs("{s}knee_bent") + _pairs("{s}foot_sideways") + _pairs("{s}hand_near_head")
    + ["hands_apart", "hands_close", "root_fast", "root_very_fast"]
    + ["root_turning_left", "root_turning_right"]
)
NUM_FEATURES = len(FEATURE_NAMES)
#: Yaw rate (rad/s) above which the root turns, and the smoothing of the facing (s) it is measured on: the
#: walking sway of the facing is ±0.5 rad/s, a Bandai walk-turn's median rate 0.1–0.46 rad/s.
TURN_RATE, TURN_SMOOTH_S = 0.12, 0.5


def body_units(positions: np.ndarray) -> tuple[float, float]:
    """``(h, w)``: humerus length and shoulder width in metres, medians over the frames of ``(frames, 21, 3)``."""
    p = np.asarray(positions, dtype=np.float64)
    upper = np.linalg.norm(p[:, [J["UpperArm_L"], J["UpperArm_R"]]] - p[:, [J["LowerArm_L"], J["LowerArm_R"]]],
                           axis=-1)
    shoulders = np.linalg.norm(p[:, J["UpperArm_L"]] - p[:, J["UpperArm_R"]], axis=-1)
    return float(np.median(upper)), float(np.median(shoulders))


def joint_angle(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Angle at ``b`` between ``a − b`` and ``c − b`` in degrees, ``(frames,)``."""
    u, v = a - b, c - b
    cos = (u * v).sum(-1) / np.maximum(np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1), 1e-9)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def time_rate(x: np.ndarray, fps: float) -> np.ndarray:
    """Central-difference time derivative along axis 0 (per second); one frame gives zeros."""
    if x.shape[0] < 2:
        return np.zeros_like(x)
    return np.gradient(x, axis=0) * fps


def checked_motion(positions: np.ndarray, fps: float) -> tuple[np.ndarray, float, float]:
    """``(positions as float64, h, w)`` of a motion every feature set can be computed on.

    Raises:
        FeatureInputError: a wrong shape, non-finite positions, ``fps`` ≤ 0 or a zero-size body.
    """
    try:
        p = checked_positions(positions)
    except ValueError as exc:
        raise FeatureInputError(str(exc)) from None
    if not fps > 0:
        raise FeatureInputError(f"fps={fps} must be positive")
    h, w = body_units(p)
    if not (h > 1e-4 and w > 1e-4):
        raise FeatureInputError(f"degenerate body: humerus {h:.3g} m, shoulder width {w:.3g} m")
    return p, h, w


def relational_features(positions: np.ndarray, fps: float) -> np.ndarray:
    """Boolean relational features of a motion.

    Args:
        positions: ``(frames, 21, 3)`` canonical positions, metres, Y up.
        fps: frames per second.

    Returns:
        ``(frames, NUM_FEATURES)`` bool, columns in :data:`FEATURE_NAMES` order.

    Raises:
        FeatureInputError: a wrong shape, non-finite positions or a zero-size body (naming the value).
    """
    p, h, w = checked_motion(positions, fps)
    yaw = facing_yaw(p, fps)
    fwd, left = facing_direction(yaw), left_direction(yaw)          # (frames, 2) as (x, z)

    def ground(v: np.ndarray, axis: np.ndarray) -> np.ndarray:      # component of (frames, 3) along axis
        return v[:, 0] * axis[:, 0] + v[:, 2] * axis[:, 1]

    chest, neck, head, hips = (p[:, J[n]] for n in ("Chest", "Neck", "Head", "Hips"))
    cols: dict[str, np.ndarray] = {}
    hand_vel = {}
    for s, side in (("l", "L"), ("r", "R")):
        other = "R" if side == "L" else "L"
        hand, elbow, shoulder = p[:, J[f"Hand_{side}"]], p[:, J[f"LowerArm_{side}"]], p[:, J[f"UpperArm_{side}"]]
        foot, knee, hip = p[:, J[f"Foot_{side}"]], p[:, J[f"LowerLeg_{side}"]], p[:, J[f"UpperLeg_{side}"]]
        ofoot = p[:, J[f"Foot_{other}"]]
        ahead = ground(hand - chest, fwd)
        outward = ground(hand - shoulder, left) * (1.0 if side == "L" else -1.0)
        v = time_rate(hand - hips, fps)                                   # hand velocity relative to the root
        hand_vel[s] = v
        cols[f"{s}hand_in_front"] = ahead > 0.5 * h
        cols[f"{s}hand_behind"] = ahead < -0.3 * h
        cols[f"{s}hand_above_neck"] = hand[:, 1] > neck[:, 1] + 0.2 * h
        cols[f"{s}hand_above_head"] = hand[:, 1] > head[:, 1] + 0.2 * h
        cols[f"{s}hand_sideways"] = outward > 0.8 * h
        cols[f"{s}hand_low"] = hand[:, 1] < hips[:, 1]
        cols[f"{s}elbow_bent"] = joint_angle(shoulder, elbow, hand) < 110.0
        cols[f"{s}arm_stretched"] = joint_angle(shoulder, elbow, hand) > 160.0
        cols[f"{s}hand_fast"] = np.linalg.norm(v, axis=-1) > 2.0 * h
        cols[f"{s}hand_moving_up"] = v[:, 1] > 1.5 * h
        cols[f"{s}hand_moving_down"] = v[:, 1] < -1.5 * h
        cols[f"{s}hand_moving_sideways"] = np.abs(ground(v, left)) > 1.5 * h
        cols[f"{s}foot_in_front"] = ground(foot - ofoot, fwd) > 0.5 * h
        cols[f"{s}foot_raised"] = foot[:, 1] - ofoot[:, 1] > 0.2 * h
        cols[f"{s}foot_fast"] = np.linalg.norm(time_rate(foot, fps), axis=-1) > 3.0 * h
        cols[f"{s}knee_bent"] = joint_angle(hip, knee, foot) < 150.0
        cols[f"{s}foot_sideways"] = np.abs(ground(foot - hips, left)) > 0.9 * w
        cols[f"{s}hand_near_head"] = np.linalg.norm(hand - head, axis=-1) < 0.8 * h
    hands = np.linalg.norm(p[:, J["Hand_L"]] - p[:, J["Hand_R"]], axis=-1)
    cols["hands_apart"] = hands > 2.0 * w
    cols["hands_close"] = hands < 0.6 * h
    root_speed = np.linalg.norm(time_rate(hips[:, [0, 2]], fps), axis=-1)
    cols["root_fast"] = root_speed > 2.5 * h
    cols["root_very_fast"] = root_speed > 7.0 * h
    yaw_rate = unwrapped_rate(facing_yaw(p, fps, smooth_seconds=TURN_SMOOTH_S), fps)
    cols["root_turning_left"] = yaw_rate > TURN_RATE
    cols["root_turning_right"] = yaw_rate < -TURN_RATE
    return np.stack([cols[name] for name in FEATURE_NAMES], axis=1)


def unwrapped_rate(yaw: np.ndarray, fps: float) -> np.ndarray:
    """Yaw rate in rad/s (positive: turning towards the body's left), robust to the ±π wrap."""
    return time_rate(np.unwrap(wrap_angle(yaw)), fps)

