"""Foot-skating clean-up of synthesized positions: hold planted feet still, re-solve the knees.

Contacts come from the one detector, :func:`stylemotion.primitives.contacts.foot_contacts`. During each
contact interval of a foot, the horizontal drift of its *planted point* — per frame the slower of
heel (``Foot_*``) and ball (``Toes_*``), as in :func:`stylemotion.primitives.contacts.planted_point_speed` — is
accumulated and subtracted from the whole foot (heel and ball move together, so the foot keeps its
shape and its roll from heel to ball). When the foot lifts off, the accumulated correction is
released over ``release_frames`` frames of the swing (smoothstep), so the foot rejoins its own
swing without a jump.

The corrected ankle is then reached by the analytic two-bone solve of the leg
(:func:`stylemotion.geometry.two_bone_ik`): hip fixed, thigh and shin lengths of that frame kept,
the knee in the plane spanned by the hip→ankle line and the original knee (the original knee
direction is the pole). An ankle out of reach is pulled towards the hip until the leg is straight.
"""

from __future__ import annotations

import numpy as np

from stylemotion.geometry import two_bone_ik
from stylemotion.primitives.contacts import contact_intervals, foot_contacts, horizontal_speed
from stylemotion.skeleton import FOOT_POINTS, JOINT_INDEX, checked_positions

#: Closest a solved leg comes to fully straight or fully folded: the hip–ankle distance stays this
#: far inside ``[|thigh − shin|, thigh + shin]``, metres.
REACH_MARGIN_M = 1e-6

#: ``(hip, knee, ankle, toes)`` joint indices of the left and the right leg.
LEGS = ((JOINT_INDEX["UpperLeg_L"], JOINT_INDEX["LowerLeg_L"], JOINT_INDEX["Foot_L"], JOINT_INDEX["Toes_L"]),
        (JOINT_INDEX["UpperLeg_R"], JOINT_INDEX["LowerLeg_R"], JOINT_INDEX["Foot_R"], JOINT_INDEX["Toes_R"]))


def planted_drift(positions: np.ndarray, fps: float, contact: np.ndarray, foot: int,
                  release_frames: int) -> np.ndarray:
    """``(frames, 2)`` horizontal (x, z) correction of one foot that cancels its planted point's drift.

    Args:
        positions: ``(frames, 21, 3)`` metres.
        fps: frames per second.
        contact: ``(frames,)`` bool contact of this foot.
        foot: 0 (left) or 1 (right).
        release_frames: frames after lift-off over which the correction returns to zero.
    """
    points = positions[:, FOOT_POINTS[foot]][..., [0, 2]]  # (frames, 2 points, 2)
    step = np.diff(points, axis=0)  # (frames - 1, points, 2): motion from t to t + 1
    speed = horizontal_speed(positions[:, FOOT_POINTS[foot]], fps)[:-1]  # (frames - 1, points)
    planted = np.take_along_axis(step, speed.argmin(-1)[:, None, None], axis=1)[:, 0]  # (frames - 1, 2)
    correction = np.zeros((len(positions), 2))
    for start, stop in contact_intervals(contact):
        drift = np.cumsum(planted[start:stop - 1], axis=0)
        correction[start + 1:stop] = -drift
        held = correction[stop - 1].copy()
        after = min(release_frames, len(positions) - stop)
        if after > 0:
            t = np.arange(1, after + 1) / (release_frames + 1)
            correction[stop:stop + after] += (1.0 - t * t * (3.0 - 2.0 * t))[:, None] * held
    return correction


def solve_knee(hip: np.ndarray, knee: np.ndarray, ankle: np.ndarray, target: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """Two-bone leg solve keeping thigh and shin lengths (all ``(frames, 3)`` metres).

    Returns:
        The new knee and the reached ankle (``target``, or pulled towards the hip if out of reach).
    """
    thigh = np.linalg.norm(knee - hip, axis=-1, keepdims=True)
    shin = np.linalg.norm(ankle - knee, axis=-1, keepdims=True)
    return two_bone_ik(hip, target, knee - hip, thigh, shin, law="cosines", margin=REACH_MARGIN_M)


def clean_foot_skating(positions: np.ndarray, fps: float, release_frames: int = 4,
                       rest_heights: np.ndarray | None = None) -> np.ndarray:
    """Positions with planted feet held still and the legs re-solved (see the module doc).

    Args:
        positions: ``(frames, 21, 3)`` metres, Y up.
        fps: frames per second.
        release_frames: frames over which a foot's correction is released after lift-off.
        rest_heights: resting heights for the contact detector (default: estimated from the motion).

    Returns:
        ``(frames, 21, 3)`` float64 corrected positions (only knees, ankles and toes move).
    """
    p = checked_positions(positions, min_frames=2)
    contact = foot_contacts(p, fps, rest_heights=rest_heights)
    for foot, (hip, knee, ankle, toes) in enumerate(LEGS):
        shift = planted_drift(p, fps, contact[:, foot], foot, release_frames)
        moved = ~np.all(shift == 0, axis=-1)
        if not moved.any():
            continue
        target = p[moved, ankle].copy()
        target[:, [0, 2]] += shift[moved]
        new_knee, reached = solve_knee(p[moved, hip], p[moved, knee], p[moved, ankle], target)
        p[moved, toes] += reached - p[moved, ankle]
        p[moved, knee], p[moved, ankle] = new_knee, reached
    return p
