"""Deterministic procedural stylized locomotion on the canonical 21-joint skeleton.

The embedded default dataset: a fresh clone can train and test on it with no download. It is a
ground truth for tests (exact foot contacts, known turning direction, styles that differ in known
ways), never evidence that a method works on real motion.

Everything is built at the position level so that the contacts are exact:

1. **Footsteps** are planned first: alternating left/right footfalls with per-step random step
   length, width, duration and heading. Turning takes follow a heading curve that turns by about
   ±90° over the take (``walk-turn-left`` turns left, i.e. positive yaw); straight takes drift a
   little.
2. **Feet**: a planted foot (ankle and toes) stays exactly fixed on the ground from its footfall to
   its lift-off; the swing foot follows a minimum-jerk path with a height bump (knee lift) and a
   toe-off/heel-strike pitch, drawn in towards the hip where the leg could not reach it. Walks
   overlap stances (double support, about 20% of the cycle); runs have flight phases.
3. **Pelvis**: a cubic spline through points above the planted feet (with lateral sway), at a
   height that is a smooth minimum of the style's carriage (with an inverted-pendulum bob when
   walking) and of what the planted legs reach, so no leg is ever over-stretched.
4. **Body**: pelvis, spine, head and arms are posed by rotating a rest skeleton (torso lean, head
   drop, pelvis twist and list, shoulder counter-rotation, arm swing opposite to the legs) through
   :func:`stylemotion.skeleton.forward_kinematics`; knees come from an analytic two-bone IK with a
   forward pole. Every bone keeps its length exactly.

Conventions: positions ``(frames, 21, 3)`` in metres, Y up, ground at ``y = 0``; yaw ``θ`` faces
``(sin θ, 0, cos θ)`` and the body's left is ``(cos θ, 0, −sin θ)`` (see
:mod:`stylemotion.representation`). Every take starts with the pelvis above the origin, facing +Z.
"""

from __future__ import annotations

import dataclasses
import hashlib
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.special import logsumexp

from stylemotion.config import ConfigError
from stylemotion.geometry import (
    facing_direction,
    left_direction,
    local_rotations,
    rotation_x,
    rotation_y,
    rotation_z,
    two_bone_ik,
)
from stylemotion.skeleton import CANONICAL_PARENTS, JOINT_INDEX, NUM_JOINTS, forward_kinematics

CONTENTS: tuple[str, ...] = ("walk", "walk-turn-left", "walk-turn-right", "run")

# Rest skeleton of a 1.75 m adult, metres, body frame (+X left, +Y up, +Z forward): offsets of
# joints from their parents (left side; the right side mirrors x) and bone lengths.
_ANKLE_HEIGHT = 0.08  # ankle above the ground with the foot flat
_TOE_HEIGHT = 0.02  # ball of the foot above the ground with the foot flat
_THIGH = 0.43
_SHIN = 0.42
_PELVIS_DROP = 0.06  # hip joints below the Hips joint
_FOOT = np.array([0.0, _TOE_HEIGHT - _ANKLE_HEIGHT, 0.14])  # ankle → toes, foot flat
_SPINE = np.array([0.0, 0.10, 0.0])
_CHEST = np.array([0.0, 0.18, 0.0])
_NECK = np.array([0.0, 0.20, 0.0])
_HEAD = np.array([0.0, 0.08, 0.02])
_CLAVICLE_BASE = np.array([0.035, 0.16, 0.0])  # chest → shoulder (clavicle start)
_UPPER_ARM = 0.29
_FOREARM = 0.26

_SOFTMIN_M = 0.01  # smoothing width of the pelvis height limit, metres
_REACH = 0.995  # fraction of thigh + shin the hip-ankle distance may reach
_FEET_CLEARANCE = 0.11  # least lateral ankle distance while the swing foot passes, metres
# Slack per unit of swing progress, as a fraction of the leg's length, with which a swinging leg's
# last footfall spot stops limiting the pelvis height after lift-off (fast) and its next spot starts
# limiting it before the footfall (slowly: the pelvis descends as the leg reaches forward).
_LIFT_SLACK = 4.0
_LAND_SLACK = 2.0


@dataclass(frozen=True)
class _Style:
    """Gait and posture of one style (walking; runs are derived in :func:`_gait_for`).

    Lengths in metres for a 1.75 m body, times in seconds, angles in radians.
    """

    step_length: float  # distance between consecutive footfalls
    step_time: float  # time between consecutive footfalls (60 / cadence in steps per minute)
    step_width: float  # lateral distance between left and right ankle lines (< 0: crossing)
    stance: float  # stance fraction of a gait cycle (0.6 → 20% double support)
    run_stance: float  # the same when running (< 0.5: flight phases)
    lift: float  # swing-foot ankle lift above its planted height
    carriage: float  # pelvis carriage height as a fraction of thigh + shin (knee bend)
    bounce: float  # extra vertical bob of the pelvis at midstance
    sway: float  # lateral pelvis shift towards the stance foot
    pelvis_twist: float  # pelvis yaw amplitude (leg side forward with its leg)
    pelvis_list: float  # pelvis roll amplitude (hip drop on the swing side)
    lean: float  # forward torso lean
    head_drop: float  # forward head flexion on top of the lean
    arm_swing: float  # shoulder flexion amplitude, opposite to the legs
    arm_forward: float  # mean shoulder flexion
    elbow: float  # mean elbow flexion
    arm_abduction: float  # arms held away from the body
    shoulder_droop: float  # clavicles lowered (negative: raised)
    shoulder_protraction: float  # clavicles rolled forward
    chest_twist: float  # shoulder-line counter-rotation amplitude
    toe_out: float  # foot yaw away from the walking direction
    clavicle: float  # shoulder → upper-arm joint (shoulder width)
    hip_width: float  # Hips → hip joint, lateral


_NORMAL = _Style(
    step_length=0.66, step_time=0.53, step_width=0.12, stance=0.60, run_stance=0.32, lift=0.10,
    carriage=0.975, bounce=0.0, sway=0.025, pelvis_twist=0.08, pelvis_list=0.06, lean=0.04,
    head_drop=0.0, arm_swing=0.30, arm_forward=0.05, elbow=0.25, arm_abduction=0.10,
    shoulder_droop=0.0, shoulder_protraction=0.0, chest_twist=0.08, toe_out=0.12, clavicle=0.14,
    hip_width=0.09,
)  # fmt: skip

_STYLE_TABLE: dict[str, _Style] = {
    "active": dataclasses.replace(
        _NORMAL, step_length=0.76, step_time=0.47, stance=0.58, run_stance=0.28, lift=0.13, bounce=0.01,
        pelvis_twist=0.12, pelvis_list=0.05, lean=0.08, arm_swing=0.50, arm_forward=0.08, elbow=0.55,
        chest_twist=0.12,
    ),
    "elderly": dataclasses.replace(
        _NORMAL, step_length=0.42, step_time=0.60, step_width=0.15, stance=0.64, run_stance=0.40,
        lift=0.06, carriage=0.93, sway=0.03, pelvis_twist=0.04, pelvis_list=0.04, lean=0.30,
        head_drop=0.15, arm_swing=0.10, arm_forward=0.15, elbow=0.45, arm_abduction=0.12,
        shoulder_droop=0.05, shoulder_protraction=0.15, chest_twist=0.03, toe_out=0.20, clavicle=0.13,
    ),
    "exhausted": dataclasses.replace(
        _NORMAL, step_length=0.50, step_time=0.68, step_width=0.13, stance=0.62, run_stance=0.38,
        lift=0.035, carriage=0.95, sway=0.035, pelvis_twist=0.05, pelvis_list=0.05, lean=0.20,
        head_drop=0.45, arm_swing=0.12, arm_forward=0.0, elbow=0.10, arm_abduction=0.06,
        shoulder_droop=0.20, shoulder_protraction=0.15, chest_twist=0.04,
    ),
    "feminine": dataclasses.replace(
        _NORMAL, step_length=0.60, step_time=0.48, step_width=0.01, lift=0.09, carriage=0.98,
        bounce=0.005, sway=0.05, pelvis_twist=0.14, pelvis_list=0.12, lean=-0.02, head_drop=-0.03,
        arm_swing=0.25, arm_forward=0.0, elbow=0.35, arm_abduction=0.06, chest_twist=0.05,
        toe_out=0.05, clavicle=0.125, hip_width=0.10,
    ),
    "masculine": dataclasses.replace(
        _NORMAL, step_length=0.70, step_time=0.55, step_width=0.22, carriage=0.97, sway=0.015,
        pelvis_twist=0.06, pelvis_list=0.03, lean=0.02, arm_swing=0.35, elbow=0.30,
        arm_abduction=0.22, shoulder_droop=-0.05, chest_twist=0.20, toe_out=0.25, clavicle=0.165,
    ),
    "normal": _NORMAL,
    "youthful": dataclasses.replace(
        _NORMAL, step_length=0.70, step_time=0.45, step_width=0.11, run_stance=0.30, lift=0.18,
        carriage=0.98, bounce=0.025, sway=0.02, pelvis_twist=0.10, lean=0.0, head_drop=-0.05,
        arm_swing=0.55, arm_forward=0.10, elbow=0.45, arm_abduction=0.12, shoulder_droop=-0.05,
        chest_twist=0.12, toe_out=0.08,
    ),
}  # fmt: skip

#: Style labels, named as in the Bandai-Namco dataset ("normal" is the neutral style).
STYLES: tuple[str, ...] = tuple(_STYLE_TABLE)


@dataclass
class SyntheticTake:
    """One generated take.

    Attributes:
        name: unique id, ``synthetic_{content}_{style}_{index:03d}``.
        positions: ``(frames, 21, 3)`` float32 canonical global positions, metres, Y up.
        fps: frames per second.
        labels: ``content``, ``style``, ``take`` (the zero-padded index) and ``actor``.
        contacts: ``(frames, 2)`` bool ground-truth foot contact; column 0 left foot, 1 right.
    """

    name: str
    positions: np.ndarray
    fps: float
    labels: dict[str, str]
    contacts: np.ndarray


@dataclass(frozen=True)
class _Gait:
    """What one take does: a style's parameters for its content, varied per take and scaled."""

    style: _Style
    stance: float  # stance fraction of a cycle
    lift_peak: float  # swing progress (0..1) at which the ankle is highest
    toe_pitch: float  # toe-down / toe-up amplitude of the swing foot, radians
    pelvis_over: float  # fraction of a stance at which the pelvis passes over the planted foot
    running: bool
    scale: float  # body size relative to the 1.75 m rest skeleton


@dataclass(frozen=True)
class _Heading:
    """Body heading over time: a turn spread over the take plus a slow drift, radians."""

    turn: float  # total turn over the take (positive: left)
    duration: float  # seconds
    drift: float  # radians per second
    wander: float  # amplitude of a slow sinusoidal wander
    wander_phase: float

    def __call__(self, t: np.ndarray) -> np.ndarray:
        """Heading ``(n,)`` radians at times ``t`` ``(n,)`` seconds (0 at ``t = 0``)."""
        u = np.clip(t / self.duration, 0.0, 1.0)
        turned = self.turn * (u - np.sin(2 * np.pi * u) / (2 * np.pi))
        wander = self.wander * (np.sin(2 * np.pi * t / 5.0 + self.wander_phase) - np.sin(self.wander_phase))
        return turned + self.drift * t + wander


@dataclass(frozen=True)
class _Steps:
    """Planned footfalls, in time order, alternating sides.

    Attributes:
        times: ``(k,)`` footfall times, seconds.
        lift_off: ``(k,)`` lift-off times of the same feet, seconds.
        sides: ``(k,)`` +1 left, -1 right.
        feet: ``(k, 2)`` planted ankle ground position (x, z), metres.
        foot_yaw: ``(k,)`` planted foot yaw, radians.
        pelvis: ``(k, 2)`` pelvis ground position (x, z) when it passes over the planted foot, metres.
        pelvis_time: ``(k,)`` times at which it does, seconds.
    """

    times: np.ndarray
    lift_off: np.ndarray
    sides: np.ndarray
    feet: np.ndarray
    foot_yaw: np.ndarray
    pelvis: np.ndarray
    pelvis_time: np.ndarray


@dataclass(frozen=True)
class _PelvisPath:
    """The pelvis' ground path, gait phase and rotation as functions of time (seconds)."""

    gait: _Gait
    steps: _Steps
    heading: _Heading
    spline: CubicSpline  # pelvis ground (x, z) through the steps' pelvis_time and pelvis

    def ground(self, t: np.ndarray) -> np.ndarray:
        """Pelvis ground position ``(n, 2)`` (x, z) metres at times ``t`` ``(n,)``."""
        return self.spline(t)

    def phase(self, t: np.ndarray) -> np.ndarray:
        """Gait phase ``(n,)`` in cycles: integer at left footfalls, +0.5 at right ones."""
        steps = self.steps
        first_left = 0 if steps.sides[0] > 0 else 1
        return np.interp(t, steps.times, (np.arange(len(steps.times)) - first_left) / 2)

    def rotation(self, t: np.ndarray) -> np.ndarray:
        """Global pelvis rotation ``(n, 3, 3)`` at times ``t``."""
        return _pelvis_rotation(self.gait, self.heading(t), self.phase(t))


def _rng(seed: int, content: str, style: str, index: int) -> np.random.Generator:
    """A generator seeded by a stable hash of the take's identity (not Python's ``hash``)."""
    key = f"stylemotion.synthetic|{seed}|{content}|{style}|{index}".encode()
    return np.random.default_rng(int.from_bytes(hashlib.sha256(key).digest()[:16], "little"))


def _check(value: str, valid: tuple[str, ...], what: str) -> None:
    if value not in valid:
        raise ConfigError(f"data.{what}s: unknown {what} {value!r}; valid {what}s: {', '.join(valid)}")


def _gait_for(style: str, content: str, rng: np.random.Generator) -> _Gait:
    """A take's gait: the style's parameters for walking or running, with per-take variation."""
    s = _STYLE_TABLE[style]
    running = content == "run"
    if running:
        s = dataclasses.replace(
            s, step_length=s.step_length * 1.6, step_time=s.step_time * 0.62,
            step_width=s.step_width * 0.5, lift=s.lift + 0.15, carriage=s.carriage - 0.04,
            bounce=s.bounce + 0.03, sway=s.sway * 0.5, lean=s.lean + 0.12, arm_swing=s.arm_swing * 1.3,
            elbow=1.3 + 0.3 * s.elbow, pelvis_list=s.pelvis_list * 0.5,
        )  # fmt: skip
    scale = rng.uniform(0.95, 1.05)
    jitter = rng.normal(0.0, 1.0, size=5)
    s = dataclasses.replace(
        s,
        step_length=s.step_length * scale * (1 + 0.04 * jitter[0]),
        step_time=s.step_time * np.sqrt(scale) * (1 + 0.03 * jitter[1]),
        step_width=s.step_width * scale,
        lift=s.lift * scale * (1 + 0.08 * jitter[2]),
        sway=s.sway * scale,
        arm_swing=s.arm_swing * (1 + 0.08 * jitter[3]),
        lean=s.lean + 0.02 * jitter[4],
    )
    return _Gait(
        style=s,
        stance=s.run_stance if running else s.stance,
        lift_peak=0.3,
        toe_pitch=0.2 + 1.5 * s.lift,
        pelvis_over=0.42 if running else 0.5,
        running=running,
        scale=scale,
    )


def _heading_for(content: str, duration: float, rng: np.random.Generator) -> _Heading:
    """The take's heading curve: ±90° (±10%) turns for turning takes, small drift otherwise."""
    turn = {"walk-turn-left": 1.0, "walk-turn-right": -1.0}.get(content, 0.0)
    return _Heading(
        turn=turn * np.pi / 2 * (1 + 0.1 * np.clip(rng.standard_normal(), -2, 2)),
        duration=duration,
        drift=0.02 * rng.standard_normal(),
        wander=0.03 * rng.uniform(),
        wander_phase=rng.uniform(0, 2 * np.pi),
    )


def _plan_steps(gait: _Gait, heading: _Heading, start: float, end: float, rng: np.random.Generator) -> _Steps:
    """Footfalls covering ``[start, end]`` seconds with per-step random length, width and timing."""
    s = gait.style
    n = int(np.ceil((end - start) / (0.85 * s.step_time))) + 3
    noise = np.clip(rng.standard_normal((4, n)), -2.5, 2.5)
    durations = s.step_time * (1 + 0.04 * noise[0])
    lengths = s.step_length * (1 + 0.05 * noise[1])
    widths = s.step_width + 0.012 * gait.scale * noise[2]
    sides = np.where((np.arange(n) + (rng.uniform() < 0.5)) % 2 == 0, 1.0, -1.0)
    times = start + np.concatenate([[0.0], np.cumsum(durations[:-1])])
    stance = 2 * gait.stance * durations
    over = times + gait.pelvis_over * stance
    yaw = heading(over) + 0.02 * noise[3]
    advance = lengths[1:, None] * facing_direction(heading((over[:-1] + over[1:]) / 2))
    centre = np.concatenate([np.zeros((1, 2)), np.cumsum(advance, axis=0)])
    lateral = sides[:, None] * left_direction(yaw)
    return _Steps(
        times=times,
        lift_off=times + stance,
        sides=sides,
        feet=centre + lateral * widths[:, None] / 2,
        foot_yaw=yaw + sides * s.toe_out,
        pelvis=centre + lateral * s.sway,
        pelvis_time=over,
    )


def _min_jerk(u: np.ndarray) -> np.ndarray:
    """Minimum-jerk 0 → 1 profile with zero velocity and acceleration at both ends."""
    return u**3 * (10 - 15 * u + 6 * u**2)


@dataclass(frozen=True)
class _Foot:
    """One foot over ``n`` frames.

    Attributes:
        ankle: ``(n, 3)`` ankle positions, metres.
        toes: ``(n, 3)`` ball-of-foot positions, metres.
        yaw: ``(n,)`` foot yaw, radians.
        contact: ``(n,)`` bool, planted (ankle and toes exactly still on the ground).
        swing: ``(n,)`` swing progress, 0 at lift-off (and during stance) to 1 at the footfall.
        spots: ``(2, n, 2)`` ground (x, z) of the ankle's last footfall and of its next one.
        lift_time: ``(n,)`` time of the last lift-off (or the coming one, while planted), seconds.
        land_time: ``(n,)`` time of the next footfall, seconds.
    """

    ankle: np.ndarray
    toes: np.ndarray
    yaw: np.ndarray
    contact: np.ndarray
    swing: np.ndarray
    spots: np.ndarray
    lift_time: np.ndarray
    land_time: np.ndarray


def _foot_track(steps: _Steps, side: float, t: np.ndarray, gait: _Gait) -> _Foot:
    """One foot at times ``t`` ``(n,)`` seconds; ``side`` +1 left, -1 right.

    The steps must cover ``t`` with a spare footfall of each side before and after.
    """
    own = steps.sides == side
    land, lift, feet, yaw = steps.times[own], steps.lift_off[own], steps.feet[own], steps.foot_yaw[own]
    j = np.searchsorted(land, t, side="right") - 1
    u = np.clip((t - lift[j]) / (land[j + 1] - lift[j]), 0.0, 1.0)
    progress = _min_jerk(u)
    foot_yaw = yaw[j] + progress * (yaw[j + 1] - yaw[j])
    clearance = max(0.0, _FEET_CLEARANCE * gait.scale - gait.style.step_width)
    ground = feet[j] + progress[:, None] * (feet[j + 1] - feet[j])
    ground += side * clearance * np.sin(np.pi * u)[:, None] * left_direction(foot_yaw)
    peak_u = u ** (np.log(0.5) / np.log(gait.lift_peak))  # maps lift_peak to 0.5
    ankle_y = gait.scale * _ANKLE_HEIGHT + gait.style.lift * 16 * peak_u**2 * (1 - peak_u) ** 2
    ankle = np.stack([ground[:, 0], ankle_y, ground[:, 1]], axis=-1)
    toes = _toes(ankle, foot_yaw, u, gait)
    return _Foot(ankle, toes, foot_yaw, t < lift[j], u, np.stack([feet[j], feet[j + 1]]), lift[j], land[j + 1])


def _toes(ankle: np.ndarray, foot_yaw: np.ndarray, swing: np.ndarray, gait: _Gait) -> np.ndarray:
    """Toe positions ``(n, 3)``: toe-off (toes down) then heel strike (toes up) during the swing.

    The pitch never takes the toes below their height with the foot flat on the ground.
    """
    foot = _FOOT * gait.scale
    length, rest_angle = np.hypot(foot[1], foot[2]), np.arctan2(-foot[1], foot[2])
    lowest = np.arcsin(np.clip((ankle[:, 1] - gait.scale * _TOE_HEIGHT) / length, -1, 1)) - rest_angle
    pitch = np.minimum(gait.toe_pitch * np.sin(2 * np.pi * swing), lowest)
    return ankle + np.einsum("nab,b->na", rotation_y(foot_yaw) @ rotation_x(pitch), foot)


def _rest_offsets(gait: _Gait) -> np.ndarray:
    """``(21, 3)`` rest offsets of each joint from its parent, metres, scaled to the take's body."""
    s = gait.style
    offsets = np.zeros((NUM_JOINTS, 3))
    for side, suffix in ((1.0, "_L"), (-1.0, "_R")):
        mirror = np.array([side, 1.0, 1.0])
        offsets[JOINT_INDEX["Shoulder" + suffix]] = _CLAVICLE_BASE * mirror
        offsets[JOINT_INDEX["UpperArm" + suffix]] = [side * s.clavicle, 0.0, 0.0]
        offsets[JOINT_INDEX["LowerArm" + suffix]] = [0.0, -_UPPER_ARM, 0.0]
        offsets[JOINT_INDEX["Hand" + suffix]] = [0.0, -_FOREARM, 0.0]
        offsets[JOINT_INDEX["UpperLeg" + suffix]] = [side * s.hip_width, -_PELVIS_DROP, 0.0]
        offsets[JOINT_INDEX["LowerLeg" + suffix]] = [0.0, -_THIGH, 0.0]
        offsets[JOINT_INDEX["Foot" + suffix]] = [0.0, -_SHIN, 0.0]
        offsets[JOINT_INDEX["Toes" + suffix]] = _FOOT
    offsets[JOINT_INDEX["Spine"]], offsets[JOINT_INDEX["Chest"]] = _SPINE, _CHEST
    offsets[JOINT_INDEX["Neck"]], offsets[JOINT_INDEX["Head"]] = _NECK, _HEAD
    return offsets * gait.scale


def _pelvis_roll(gait: _Gait, phase: np.ndarray) -> np.ndarray:
    """Pelvis roll ``(n,)`` radians at gait phase ``phase``: the swing side's hip drops."""
    return gait.style.pelvis_list * np.cos(2 * np.pi * (phase - gait.stance / 2))


def _pelvis_rotation(gait: _Gait, yaw: np.ndarray, phase: np.ndarray) -> np.ndarray:
    """Global pelvis rotations ``(n, 3, 3)`` at heading ``yaw`` and gait phase ``phase`` ``(n,)``.

    The pelvis twists so that each hip goes forward with its leg, rolls (swing hip drops) and tips
    forward with a third of the torso lean.
    """
    twist = -gait.style.pelvis_twist * np.cos(2 * np.pi * phase)  # left hip forward at left footfall
    return rotation_y(yaw + twist) @ rotation_z(_pelvis_roll(gait, phase)) @ rotation_x(0.3 * gait.style.lean)


def _global_rotations(gait: _Gait, yaw: np.ndarray, phase: np.ndarray) -> np.ndarray:
    """Global rotations ``(n, 21, 3, 3)`` of the pelvis, torso, head and arms (legs: the pelvis').

    Args:
        gait: the take's gait.
        yaw: ``(n,)`` body heading, radians.
        phase: ``(n,)`` gait phase in cycles (integer at left footfalls).
    """
    s = gait.style
    cycle = np.cos(2 * np.pi * phase)  # +1 when the left foot lands (left leg forward)
    chest_yaw = yaw + s.chest_twist * cycle  # shoulders counter-rotate
    rotations = np.empty(yaw.shape + (NUM_JOINTS, 3, 3))
    rotations[:, JOINT_INDEX["Hips"]] = _pelvis_rotation(gait, yaw, phase)
    spine_yaw = yaw + (s.chest_twist - s.pelvis_twist) / 2 * cycle
    rotations[:, JOINT_INDEX["Spine"]] = rotation_y(spine_yaw) @ rotation_x(0.5 * s.lean)
    pelvis_roll = _pelvis_roll(gait, phase)
    chest = rotation_y(chest_yaw) @ rotation_z(-0.5 * pelvis_roll) @ rotation_x(s.lean)
    rotations[:, JOINT_INDEX["Chest"]] = chest
    rotations[:, JOINT_INDEX["Neck"]] = rotation_y(yaw + 0.3 * s.chest_twist * cycle) @ rotation_x(s.lean + s.head_drop)
    rotations[:, JOINT_INDEX["Head"]] = rotations[:, JOINT_INDEX["Neck"]]
    for side, suffix in ((1.0, "_L"), (-1.0, "_R")):
        shoulder = chest @ rotation_y(-side * s.shoulder_protraction) @ rotation_z(-side * s.shoulder_droop)
        flexion = s.arm_forward - side * s.arm_swing * cycle  # left arm back when the left leg leads
        upper = rotation_y(chest_yaw) @ rotation_z(side * s.arm_abduction * np.ones_like(yaw)) @ rotation_x(-flexion)
        lower = upper @ rotation_x(-(s.elbow + 0.5 * np.maximum(flexion, 0.0)))
        rotations[:, JOINT_INDEX["Shoulder" + suffix]] = shoulder
        rotations[:, JOINT_INDEX["UpperArm" + suffix]] = upper
        rotations[:, JOINT_INDEX["LowerArm" + suffix]] = lower
        rotations[:, JOINT_INDEX["Hand" + suffix]] = lower
        for leg in ("UpperLeg", "LowerLeg", "Foot", "Toes"):
            rotations[:, JOINT_INDEX[leg + suffix]] = rotations[:, JOINT_INDEX["Hips"]]
    return rotations


def _bob(gait: _Gait, phase: np.ndarray) -> np.ndarray:
    """Vertical pelvis bob ``(n,)`` metres around the carriage height, at gait phase ``phase``.

    Walking: an inverted pendulum, highest at midstance and lowest in double support, by as much as
    straight legs need to reach feet a step apart. Running: lowest at midstance, highest in flight.
    """
    s = gait.style
    step_phase = 2 * phase  # cycles of single steps: integer at every footfall
    if gait.running:
        return s.bounce * np.cos(2 * np.pi * (step_phase - gait.stance - 0.5))
    legs = (_THIGH + _SHIN) * gait.scale
    drop = s.carriage * legs - np.sqrt((_REACH * legs) ** 2 - (gait.stance * s.step_length) ** 2)
    trough = 0.5 + 0.5 * np.cos(2 * np.pi * (step_phase - gait.stance + 0.5))
    return s.bounce - (max(drop, 0.0) + 2 * s.bounce) * trough


def _pelvis_limit(
    gait: _Gait, pelvis: _PelvisPath, times: np.ndarray, hip_offset: np.ndarray, spot: np.ndarray
) -> np.ndarray:
    """Highest pelvis ``(n,)`` metres whose hip joint reaches an ankle planted at ``spot``.

    Args:
        gait: the take's gait.
        pelvis: the pelvis' ground path and rotation.
        times: ``(n,)`` seconds.
        hip_offset: ``(3,)`` rest offset of the leg's hip joint from the Hips joint, metres.
        spot: ``(n, 2)`` ground (x, z) of the planted ankle, metres.
    """
    legs = (_THIGH + _SHIN) * gait.scale
    hip = np.einsum("nab,b->na", pelvis.rotation(times), hip_offset)  # hip joint, pelvis at the origin
    ground = np.linalg.norm(pelvis.ground(times) + hip[:, [0, 2]] - spot, axis=-1)
    reach = np.sqrt(np.maximum((_REACH * legs) ** 2 - ground**2, 0.0))
    return gait.scale * _ANKLE_HEIGHT - hip[:, 1] + reach


def _pelvis_height(
    gait: _Gait, pelvis: _PelvisPath, t: np.ndarray, feet: list[_Foot], offsets: np.ndarray
) -> np.ndarray:
    """Pelvis height ``(n,)`` metres at times ``t``: a smooth minimum of carriage and reach.

    A planted leg limits the height to what it reaches with ``_REACH`` of its length. A swinging
    leg does not (its knee bends), but so that the height stays smooth, the limit its foot had at
    lift-off fades out quickly, and the limit it will have at the footfall fades in over the swing
    (the pelvis descends as the leg reaches forward).
    """
    legs = (_THIGH + _SHIN) * gait.scale
    limits = [
        gait.scale * (_ANKLE_HEIGHT + _PELVIS_DROP) + gait.style.carriage * legs
        + _bob(gait, pelvis.phase(t))
    ]  # fmt: skip
    for foot, joint in zip(feet, ("UpperLeg_L", "UpperLeg_R"), strict=True):
        offset = offsets[JOINT_INDEX[joint]]
        planted = _pelvis_limit(gait, pelvis, t, offset, foot.spots[0])
        lifted = _pelvis_limit(gait, pelvis, foot.lift_time, offset, foot.spots[0])
        landing = _pelvis_limit(gait, pelvis, foot.land_time, offset, foot.spots[1])
        limits.append(np.where(foot.contact, planted, lifted + _LIFT_SLACK * legs * foot.swing))
        limits.append(np.where(foot.contact, np.inf, landing + _LAND_SLACK * legs * (1 - foot.swing)))
    return -_SOFTMIN_M * logsumexp(-np.stack(limits) / _SOFTMIN_M, axis=0)


def _within_reach(foot: _Foot, hip: np.ndarray, legs: float, gait: _Gait) -> _Foot:
    """The foot with its swinging ankle drawn towards ``hip`` ``(n, 3)`` where the leg is short.

    The hip-ankle distance of a swinging foot becomes a smooth minimum of itself and ``_REACH`` of
    the leg length (the leg extends as the foot reaches forward, and the foot comes down from above);
    planted feet are within reach by construction of the pelvis height and stay where they are.
    """
    reach = foot.ankle - hip
    dist = np.linalg.norm(reach, axis=-1, keepdims=True)
    drawn = -_SOFTMIN_M * np.logaddexp(-dist / _SOFTMIN_M, -_REACH * legs / _SOFTMIN_M)
    ankle = np.where(foot.contact[:, None], foot.ankle, hip + reach * (drawn / dist))
    return dataclasses.replace(foot, ankle=ankle, toes=_toes(ankle, foot.yaw, foot.swing, gait))


def _pose_legs(positions: np.ndarray, feet: list[_Foot], gait: _Gait) -> None:
    """Write knees, ankles and toes into ``positions`` ``(n, 21, 3)`` (hip joints already posed)."""
    for foot, suffix in zip(feet, ("_L", "_R"), strict=True):
        hip = positions[:, JOINT_INDEX["UpperLeg" + suffix]]
        foot = _within_reach(foot, hip, (_THIGH + _SHIN) * gait.scale, gait)
        pole = np.stack([np.sin(foot.yaw), np.zeros_like(foot.yaw), np.cos(foot.yaw)], axis=-1)
        positions[:, JOINT_INDEX["LowerLeg" + suffix]] = two_bone_ik(
            hip, foot.ankle, pole, _THIGH * gait.scale, _SHIN * gait.scale, law="distances"
        )[0]
        positions[:, JOINT_INDEX["Foot" + suffix]] = foot.ankle
        positions[:, JOINT_INDEX["Toes" + suffix]] = foot.toes


def generate_take(
    content: str, style: str, index: int, seed: int = 0, fps: float = 30.0, duration_s: float = 8.0
) -> SyntheticTake:
    """Generate one deterministic take of stylized locomotion.

    Args:
        content: one of :data:`CONTENTS`.
        style: one of :data:`STYLES`.
        index: take number within the (content, style) pair; different indices vary body size
            (scale 0.95–1.05), gait timing and every step.
        seed: dataset seed; the same arguments always give bit-identical output.
        fps: frames per second.
        duration_s: length of the take, seconds (at least two frames).

    Returns:
        The take: ``(frames, 21, 3)`` float32 positions (metres, Y up; pelvis above the origin and
        facing +Z at frame 0) and ``(frames, 2)`` ground-truth foot contacts (left, right).

    Raises:
        ValueError: on an unknown content or style, or fewer than two frames.
    """
    _check(content, CONTENTS, "content")
    _check(style, STYLES, "style")
    num_frames = int(round(duration_s * fps))
    if num_frames < 2:
        raise ConfigError(f"data.fps, data.duration_s: a take needs at least 2 frames, got duration {duration_s} s at "
                          f"{fps} fps")
    rng = _rng(seed, content, style, index)
    gait = _gait_for(style, content, rng)
    heading = _heading_for(content, duration_s, rng)
    t = np.arange(num_frames) / fps
    margin = 3 * gait.style.step_time
    steps = _plan_steps(gait, heading, -margin, t[-1] + margin, rng)
    pelvis = _PelvisPath(gait, steps, heading, CubicSpline(steps.pelvis_time, steps.pelvis))
    feet = [_foot_track(steps, side, t, gait) for side in (1.0, -1.0)]
    offsets = _rest_offsets(gait)
    global_rot = _global_rotations(gait, heading(t), pelvis.phase(t))
    ground = pelvis.ground(t)
    height = _pelvis_height(gait, pelvis, t, feet, offsets)
    translations = np.broadcast_to(offsets, (num_frames, NUM_JOINTS, 3)).copy()
    translations[:, JOINT_INDEX["Hips"]] = np.stack([ground[:, 0], height, ground[:, 1]], axis=-1)
    positions = forward_kinematics(local_rotations(global_rot, CANONICAL_PARENTS), translations, CANONICAL_PARENTS)
    _pose_legs(positions, feet, gait)
    positions[:, :, [0, 2]] -= positions[0, JOINT_INDEX["Hips"], [0, 2]]
    return SyntheticTake(
        name=f"synthetic_{content}_{style}_{index:03d}",
        positions=positions.astype(np.float32),
        fps=float(fps),
        labels={"content": content, "style": style, "take": f"{index:03d}", "actor": "synthetic"},
        contacts=np.stack([foot.contact for foot in feet], axis=-1),
    )


def generate_takes(
    takes_per_pair: int = 4,
    seed: int = 0,
    fps: float = 30.0,
    duration_s: float = 8.0,
    styles: Sequence[str] | None = None,
    contents: Sequence[str] | None = None,
) -> list[SyntheticTake]:
    """Generate ``takes_per_pair`` takes for every (content, style) pair.

    Args:
        takes_per_pair: takes per (content, style) pair, indices ``0 .. takes_per_pair − 1``.
        seed: dataset seed (see :func:`generate_take`).
        fps: frames per second.
        duration_s: length of each take, seconds.
        styles: subset of :data:`STYLES` (default all).
        contents: subset of :data:`CONTENTS` (default all).

    Returns:
        Takes ordered by content, then style, then index.

    Raises:
        ValueError: on an unknown style or content.
    """
    styles = STYLES if styles is None else tuple(styles)
    contents = CONTENTS if contents is None else tuple(contents)
    for style in styles:
        _check(style, STYLES, "style")
    for content in contents:
        _check(content, CONTENTS, "content")
    return [
        generate_take(content, style, i, seed=seed, fps=fps, duration_s=duration_s)
        for content in contents
        for style in styles
        for i in range(takes_per_pair)
    ]
