"""Müller & Röder's relational features (SCA 2006, Table 1; Krüger §3.2.1's ``f = 40``), per frame.

The 39 boolean features of Müller & Röder's motion templates — planes, angles and velocities between body
points, with two thresholds each (hysteresis, :func:`hysteresis`) — plus Krüger's 40th, "the angular velocity of
the root orientation is high". Thresholds are in the body units of the take (medians over its frames):

* ``hl``: humerus length ``|UpperArm − LowerArm|`` (:func:`~.features.body_units`);
* ``sw``: shoulder width ``|UpperArm_L − UpperArm_R|``; ``hw``: hip width ``|UpperLeg_L − UpperLeg_R|``;
* ``cl``: chest length ``|Chest − Neck|``; ``bl``: body length, the sum of shin, thigh and the spine chain
  ``Hips–Spine–Chest–Neck–Head`` (their skeleton's head top is our ``Head``).

Each feature is on where its quantity passes the *strict* threshold, off where it falls back past the
*loose* one, and keeps its previous value in between (their "robust" features). Velocities are central
differences averaged over a window (100 ms, 250 ms for the hand's forward and upward motion, as theirs).
The canonical skeleton stands in for theirs: wrist and fingers are ``Hand``, ankle ``Foot``, toes ``Toes``,
the root ``Hips``. Every feature, its quantity and its two thresholds: docs/annotate.md.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import uniform_filter1d

from stylemotion.annotate.features import (
    TURN_RATE,
    TURN_SMOOTH_S,
    body_units,
    checked_motion,
    joint_angle,
    time_rate,
    unwrapped_rate,
)
from stylemotion.representation import facing_yaw
from stylemotion.skeleton import JOINT_INDEX

J = JOINT_INDEX


def _pair(name: str) -> list[str]:
    return [name.format(s="r"), name.format(s="l")]


#: Names in Müller & Röder's order (F1–F39: right before left), then Krüger's root angular velocity (F40).
FEATURE_NAMES: tuple[str, ...] = tuple(
    _pair("{s}hand_moving_forward") + _pair("{s}hand_above_neck") + _pair("{s}hand_moving_up")
    + _pair("{s}elbow_bent") + ["hands_far_apart", "hands_approaching"] + _pair("{s}hand_moving_away_from_root")
    + _pair("{s}hand_fast")
    + ["rfoot_behind_lleg", "lfoot_behind_rleg"] + _pair("{s}foot_raised") + ["feet_far_apart"]
    + _pair("{s}knee_bent") + ["feet_crossed", "feet_approaching", "feet_moving_apart"] + _pair("{s}foot_fast")
    + _pair("{s}humerus_abducted") + _pair("{s}femur_abducted") + ["root_behind_frontal_plane", "spine_horizontal"]
    + _pair("{s}hand_lowered") + ["shoulders_rotated_right", "shoulders_rotated_left", "body_y_extent_small",
                                  "body_xz_extent_large", "root_fast", "root_turning_fast"]
)
NUM_FEATURES = len(FEATURE_NAMES)


def hysteresis(loose: np.ndarray, strict: np.ndarray) -> np.ndarray:
    """Two-threshold switching along axis 0: on where ``strict`` holds, off where ``loose`` does not, and
    otherwise the previous frame's value (off before the first decision). ``(frames,)`` bool each."""
    loose, strict = np.asarray(loose, dtype=bool), np.asarray(strict, dtype=bool)
    decided = strict | ~loose
    index = np.where(decided, np.arange(decided.shape[0]), -1)
    last = np.maximum.accumulate(index) if index.size else index
    return np.where(last >= 0, strict[np.maximum(last, 0)], False)


def _above(x: np.ndarray, loose: float, strict: float) -> np.ndarray:
    """Hysteresis of ``x > threshold`` (``loose`` < ``strict``)."""
    return hysteresis(x > loose, x > strict)


def _below(x: np.ndarray, loose: float, strict: float) -> np.ndarray:
    """Hysteresis of ``x < threshold`` (``loose`` > ``strict``)."""
    return hysteresis(x < loose, x < strict)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-9)


def plane_distance(p1: np.ndarray, p2: np.ndarray, p3: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Signed distance ``(frames,)`` of ``q`` from the plane through ``p1, p2, p3`` (normal
    ``(p1 − p3) × (p2 − p3)``), all ``(frames, 3)``."""
    n = _unit(np.cross(p1 - p3, p2 - p3))
    return ((q - p3) * n).sum(-1)


def normal_plane_distance(a: np.ndarray, b: np.ndarray, c: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Signed distance ``(frames,)`` of ``q`` from the plane through ``c`` with normal ``b − a``."""
    return ((q - c) * _unit(b - a)).sum(-1)


def _smoothed_rate(x: np.ndarray, fps: float, window_ms: float) -> np.ndarray:
    """Time derivative (per second) along axis 0, averaged over ``window_ms`` (at least one frame)."""
    frames = max(int(round(window_ms * fps / 1000.0)), 1)
    rate = time_rate(x, fps)
    return uniform_filter1d(rate, frames, axis=0, mode="nearest") if frames > 1 else rate


def _speed(x: np.ndarray, fps: float, window_ms: float = 100.0) -> np.ndarray:
    return np.linalg.norm(_smoothed_rate(x, fps, window_ms), axis=-1)


def mueller_roeder_features(positions: np.ndarray, fps: float) -> np.ndarray:
    """Müller & Röder's boolean features (and Krüger's 40th) of a motion.

    Args:
        positions: ``(frames, 21, 3)`` canonical positions, metres, Y up.
        fps: frames per second.

    Returns:
        ``(frames, NUM_FEATURES)`` bool, columns in :data:`FEATURE_NAMES` order.

    Raises:
        FeatureInputError: a wrong shape, non-finite positions or a zero-size body (naming the value).
    """
    p, hl, sw = checked_motion(positions, fps)

    def joint(name: str) -> np.ndarray:
        return p[:, J[name]]

    def length(a: str, b: str) -> float:
        return float(np.median(np.linalg.norm(joint(a) - joint(b), axis=-1)))

    hw, cl = length("UpperLeg_L", "UpperLeg_R"), length("Chest", "Neck")
    bl = (length("UpperLeg_R", "LowerLeg_R") + length("LowerLeg_R", "Foot_R") + length("Hips", "Spine")
          + length("Spine", "Chest") + length("Chest", "Neck") + length("Neck", "Head"))
    root, chest, neck = joint("Hips"), joint("Chest"), joint("Neck")

    def rate(x: np.ndarray, window_ms: float) -> np.ndarray:
        return _smoothed_rate(x, fps, window_ms)

    y_min = p[:, :, 1].min(axis=1)
    cols: dict[str, np.ndarray] = {}
    for s, side, other in (("r", "R", "L"), ("l", "L", "R")):
        wrist, elbow, shoulder = joint(f"Hand_{side}"), joint(f"LowerArm_{side}"), joint(f"UpperArm_{side}")
        hip, knee, ankle, toes = (joint(f"{n}_{side}") for n in ("UpperLeg", "LowerLeg", "Foot", "Toes"))
        forward = plane_distance(neck, joint("UpperLeg_R"), joint("UpperLeg_L"), wrist)   # torso plane, normal ahead
        cols[f"{s}hand_moving_forward"] = _above(rate(forward, 250.0), 1.3 * hl, 1.8 * hl)
        cols[f"{s}hand_above_neck"] = _above(normal_plane_distance(chest, neck, neck, wrist), 0.0, 0.2 * cl)
        cols[f"{s}hand_moving_up"] = _above(rate(normal_plane_distance(chest, neck, neck, wrist), 250.0),
                                            1.3 * hl, 1.8 * hl)
        cols[f"{s}elbow_bent"] = _below(joint_angle(shoulder, elbow, wrist), 120.0, 110.0)
        away = np.linalg.norm(wrist - root, axis=-1)
        cols[f"{s}hand_moving_away_from_root"] = _above(rate(away, 100.0), 1.2 * hl, 1.4 * hl)
        cols[f"{s}hand_fast"] = _above(_speed(wrist, fps), 2.0 * hl, 2.5 * hl)
        # the other leg's plane through root, its hip and its ankle (normal pointing back): this ankle behind it
        ohip, oankle = joint(f"UpperLeg_{other}"), joint(f"Foot_{other}")
        behind = plane_distance(root, ohip, oankle, ankle) if side == "R" else plane_distance(root, oankle, ohip,
                                                                                             ankle)
        cols[f"{s}foot_behind_{'l' if side == 'R' else 'r'}leg"] = _above(behind, 0.0, 0.375 * hl)
        cols[f"{s}foot_raised"] = _above(toes[:, 1] - y_min, 1.0 * hl, 1.2 * hl)
        cols[f"{s}knee_bent"] = _below(joint_angle(hip, knee, ankle), 120.0, 110.0)
        cols[f"{s}foot_fast"] = _above(np.minimum(_speed(toes, fps), _speed(ankle, fps)), 2.0 * hl, 2.5 * hl)
        down = root - neck
        cols[f"{s}humerus_abducted"] = _below(_vector_angle(down, shoulder - elbow), 155.0, 150.0)
        cols[f"{s}femur_abducted"] = _above(_vector_angle(down, knee - hip), 45.0, 50.0)
        others = [j for j in range(p.shape[1]) if j != J[f"Hand_{side}"]]
        cols[f"{s}hand_lowered"] = _below(wrist[:, 1] - p[:, others, 1].min(axis=1), 1.4 * hl, 1.2 * hl)
    lwrist, rwrist = joint("Hand_L"), joint("Hand_R")
    lshoulder, rshoulder = joint("UpperArm_L"), joint("UpperArm_R")
    lhip, rhip, lankle, rankle = joint("UpperLeg_L"), joint("UpperLeg_R"), joint("Foot_L"), joint("Foot_R")
    cols["hands_far_apart"] = _above(normal_plane_distance(lshoulder, rshoulder, lwrist, rwrist), 2.0 * sw,
                                     2.5 * sw)
    closing = -rate(np.linalg.norm(rwrist - lwrist, axis=-1), 100.0)
    cols["hands_approaching"] = _above(closing, 1.2 * hl, 1.4 * hl)
    cols["feet_far_apart"] = _above(normal_plane_distance(lhip, rhip, lankle, rankle), 1.8 * hl, 2.1 * hl)
    spread = normal_plane_distance(lhip, rhip, lankle, rankle)           # right ankle's lead to the right
    cols["feet_crossed"] = _below(spread, 0.0, -0.125 * hw)
    spread_rate = rate(spread, 100.0)
    cols["feet_approaching"] = _above(-spread_rate, 1.3 * hl, 1.5 * hl)
    cols["feet_moving_apart"] = _above(spread_rate, 1.3 * hl, 1.5 * hl)
    cols["root_behind_frontal_plane"] = _below(plane_distance(lankle, neck, rankle, root), -0.35 * hl, -0.5 * hl)
    tilt = _vector_angle(neck - root, np.broadcast_to([0.0, 1.0, 0.0], root.shape))
    cols["spine_horizontal"] = hysteresis((tilt > 60.0) & (tilt < 120.0), (tilt > 70.0) & (tilt < 110.0))
    twist = plane_distance(rhip, lhip, neck, lshoulder) - plane_distance(rhip, lhip, neck, rshoulder)
    cols["shoulders_rotated_right"] = _above(twist, 0.35 * hl, 0.4 * hl)
    cols["shoulders_rotated_left"] = _above(-twist, 0.35 * hl, 0.4 * hl)
    cols["body_y_extent_small"] = _below(p[:, :, 1].max(axis=1) - y_min, 0.9 * bl, 0.8 * bl)
    cols["body_xz_extent_large"] = _above(_ground_diameter(p[:, [J[n] for n in (
        "Foot_L", "Foot_R", "Hand_L", "Hand_R", "Head", "Hips")]]), 3.0 * hl, 3.25 * hl)
    cols["root_fast"] = _above(_speed(root, fps), 2.0 * hl, 2.3 * hl)
    yaw_rate = unwrapped_rate(facing_yaw(p, fps, smooth_seconds=TURN_SMOOTH_S), fps)
    cols["root_turning_fast"] = np.abs(yaw_rate) > TURN_RATE
    return np.stack([cols[name] for name in FEATURE_NAMES], axis=1)


def _vector_angle(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Angle between ``u`` and ``v`` ``(frames, 3)`` in degrees."""
    cos = (_unit(u) * _unit(v)).sum(-1)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def _ground_diameter(points: np.ndarray) -> np.ndarray:
    """Largest ground-plane (x, z) distance ``(frames,)`` between any two of ``points`` ``(frames, k, 3)``."""
    g = points[:, :, [0, 2]]
    return np.linalg.norm(g[:, :, None] - g[:, None, :], axis=-1).max(axis=(1, 2))


__all__ = ["FEATURE_NAMES", "NUM_FEATURES", "body_units", "hysteresis", "mueller_roeder_features",
           "normal_plane_distance", "plane_distance"]
