"""Segmentation of walks and runs into motion primitives at foot-contact keyframes (thesis §4.3,
§5.2, Fig. 4.5 and 5.1), and canonical timelines (§4.4.1).

Each single-support phase is a step; its clip runs from the keyframe of the support transfer onto
the planted foot (the middle of the double support of a walk or the flight of a run) to the next
one, in six primitives per action (``leftStance``, ``rightStance``, ``begin…``/``end…`` from and
into standing). Every step becomes a clip or a reported rejection; clips start at the origin facing
+Z; :func:`time_normalize` resamples a clip to its primitive's canonical length while it keeps its
real duration. The full specification (support states, keyframes, the six primitives, what is
rejected, placement, timelines) is ``docs/primitives.md``.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, fields
from functools import cached_property
from typing import TYPE_CHECKING, Any

import numpy as np

from stylemotion.primitives.contacts import ContactSettings, foot_contacts, leg_length, planted_point_speed
from stylemotion.representation import FRAME_DIM, ROOT_JOINT, VELOCITY_DIMS, frames_to_positions

if TYPE_CHECKING:  # the data-set package loads scipy: not needed to read the settings (command start-up)
    from stylemotion.datasets.base import Take

#: The six primitives of each locomotion action (DFKI walk graph naming).
PRIMITIVES: tuple[str, ...] = (
    "beginLeftStance", "beginRightStance", "leftStance", "rightStance", "endLeftStance", "endRightStance",
)
#: Index (0 = left, 1 = right, as in the contact arrays) of the planted foot of each primitive.
STANCE_FOOT: dict[str, int] = {p: 0 if "Left" in p or p.startswith("left") else 1 for p in PRIMITIVES}
#: Locomotion actions segmented by default.
ACTIONS: tuple[str, ...] = ("walk", "run")
#: Arm primitives, in take order (``wave`` only for :data:`WAVE_CONTENTS`).
ARM_PRIMITIVES = ("raise", "wave", "lower")
#: Content prefixes of arm takes (Bandai dataset 2).
ARM_CONTENTS = ("raise-up", "wave")
#: Content prefixes of the arm takes that have ``wave`` cycles.
WAVE_CONTENTS = ("wave",)
_SIDE = ("Left", "Right")
_FOOT = ("left", "right")


def parse_primitive(name: str) -> tuple[str, str]:
    """``"walk_leftStance"`` → ``("walk", "leftStance")``; an arm primitive ``<arm content>_<raise|wave|lower>``
    (``raise-up-left-hand_raise``, ``wave-both-hands_wave``; ``wave`` only of wave contents) → ``(content,
    primitive)``; a ValueError listing both kinds otherwise."""
    content, _, arm_primitive = str(name).rpartition("_")
    if arm_primitive in ARM_PRIMITIVES and is_arm_content(content):
        check_arm_primitive(content, arm_primitive)
        return content, arm_primitive
    action, _, primitive = str(name).partition("_")
    if action not in ACTIONS or primitive not in PRIMITIVES:
        valid = [f"{a}_{p}" for a in ACTIONS for p in PRIMITIVES]
        raise ValueError(f"unknown motion primitive {name!r}; use <action>_<primitive>, one of {valid}, or an arm "
                         f"primitive <raise-up-…|wave-…>_<{'|'.join(ARM_PRIMITIVES)}> (e.g. raise-up-right-hand_raise)")
    return action, primitive


def check_primitive(primitive: str, action: str | None = None) -> str:
    """``primitive`` itself, or a ValueError naming the valid primitives (of ``action``: an arm content's own)."""
    if action is not None and is_arm_content(action):
        check_arm_primitive(action, primitive)
    elif primitive not in PRIMITIVES and (action is not None or primitive not in ARM_PRIMITIVES):
        raise ValueError(f"unknown motion primitive {primitive!r}; the primitives are {list(PRIMITIVES)}"
                         + ("" if action is not None else f" and the arm primitives {list(ARM_PRIMITIVES)}"))
    return primitive


def stance_foot(primitive: str) -> int | None:
    """0 if ``primitive`` (a name of :data:`PRIMITIVES` or :data:`ARM_PRIMITIVES`) plants the left foot, 1 the
    right, None for an arm primitive (both feet stand)."""
    return STANCE_FOOT.get(primitive)


def _of_kind(content: str, prefixes: tuple[str, ...]) -> bool:
    return any(content == p or content.startswith(p + "-") for p in prefixes)


def is_arm_content(content: str) -> bool:
    return _of_kind(content, ARM_CONTENTS)


def content_primitives(content: str) -> tuple[str, ...]:
    """The arm primitives of an arm content, in take order (``wave`` only for :data:`WAVE_CONTENTS`)."""
    waves = _of_kind(content, WAVE_CONTENTS)
    return tuple(p for p in ARM_PRIMITIVES if waves or p != "wave")


def check_arm_primitive(content: str, primitive: str) -> None:
    """A ValueError unless ``primitive`` is an arm primitive that ``content``'s takes have."""
    if primitive not in ARM_PRIMITIVES:
        raise ValueError(f"unknown arm primitive {primitive!r}; one of {list(ARM_PRIMITIVES)}")
    if primitive not in content_primitives(content):
        valid = ", ".join(f"{content}_{p}" for p in content_primitives(content))
        raise ValueError(f"content {content!r} has no {primitive!r} primitive ({primitive} needs a "
                         f"{'|'.join(WAVE_CONTENTS)}-… content); use one of {valid}")


def action_of(content: str, actions: Sequence[str] = ACTIONS) -> str | None:
    """The locomotion action of a content label (``walk-turn-left`` → ``walk``), or None.

    A content belongs to action ``a`` when it is ``a`` or starts with ``a-``.
    """
    for action in actions:
        if content == action or content.startswith(action + "-"):
            return action
    return None


@dataclass(frozen=True)
class SegmentSettings:
    """Parameters of :func:`segment_take`.

    Attributes:
        contacts: foot contact thresholds.
        actions: locomotion actions to segment (contents are matched by :func:`action_of`).
        min_step_s: shortest accepted clip, seconds.
        max_step_s: longest accepted clip, seconds.
        min_stance_fraction: share of a clip's frames the planted foot must touch the ground.
        rest_speed: root ground speed below which double support counts as standing, leg
            lengths per second.
        min_rest_s: shortest standing still that counts as rest, seconds.
    """

    contacts: ContactSettings = field(default_factory=ContactSettings)
    actions: tuple[str, ...] = ACTIONS
    min_step_s: float = 0.1
    max_step_s: float = 1.5
    min_stance_fraction: float = 0.15
    rest_speed: float = 0.12
    min_rest_s: float = 0.15

    def __post_init__(self) -> None:
        object.__setattr__(self, "actions", tuple(self.actions))  # a config's list, hashable like the default

    @classmethod
    def from_dict(cls, values: Mapping[str, Any] | SegmentSettings | None) -> SegmentSettings:
        """Settings from plain values (e.g. a Hydra node); ``contacts`` may be a mapping."""
        if isinstance(values, SegmentSettings):
            return values
        values = dict(values or {})
        contacts = values.get("contacts")
        for keys, where in ((set(values), cls), (set(contacts or {}), ContactSettings)):
            unknown = sorted(keys - {f.name for f in fields(where)})
            if unknown:
                raise ValueError(f"unknown {where.__name__} option(s) {unknown}; valid: "
                                 f"{sorted(f.name for f in fields(where))}")
        if isinstance(contacts, Mapping):
            values["contacts"] = ContactSettings(**contacts)
        if "actions" in values:
            values["actions"] = tuple(values["actions"])
        return cls(**values)


@dataclass
class Clip:
    """One motion primitive instance.

    Attributes:
        action: ``walk`` or ``run``, or an arm content (``raise-up-right-hand``, :mod:`stylemotion.primitives.arm`).
        primitive: one of :data:`PRIMITIVES` (of an arm content: :data:`ARM_PRIMITIVES`).
        style: the take's style label.
        take: the take's name.
        content: the take's content label (e.g. ``walk-turn-left``).
        start: first source frame.
        stop: one past the last source frame (the clip holds ``stop - start`` frames).
        fps: frames per second.
        frames: ``(frames, 66)`` float32 frames of the source range (placement-free).
        contacts: ``(frames, 2)`` bool foot contacts ``[left, right]`` of the source range.
    """

    action: str
    primitive: str
    style: str
    take: str
    content: str
    start: int
    stop: int
    fps: float
    frames: np.ndarray
    contacts: np.ndarray

    @property
    def num_frames(self) -> int:
        return self.stop - self.start

    @property
    def duration_s(self) -> float:
        """Real duration, seconds (first to last frame)."""
        return (self.num_frames - 1) / self.fps

    @property
    def stance_foot(self) -> int | None:
        """0 if the left foot is planted, 1 if the right, None for an arm primitive."""
        return stance_foot(self.primitive)

    @cached_property
    def positions(self) -> np.ndarray:
        """``(frames, 21, 3)`` positions, metres, root starting at the origin facing +Z."""
        return frames_to_positions(self.frames, self.fps).astype(np.float32)

    def describe(self) -> str:
        return f"{self.action} {self.primitive} {self.style} {self.take}[{self.start}:{self.stop}]"


@dataclass(frozen=True)
class Rejection:
    """A take or a step that did not become a clip.

    Attributes:
        take, action, style, content: the take's identity.
        start, stop: source frame range of the step (None for a whole take).
        reason: why, in words.
        kind: ``take`` (the whole take), ``step`` (a step that fits no primitive) or
            ``border`` (a step cut by the start or end of the take).
    """

    take: str
    action: str
    style: str
    content: str
    start: int | None
    stop: int | None
    reason: str
    kind: str


@dataclass
class TakeSegmentation:
    """The segmentation of one take, with what plots need.

    Attributes:
        take: the take's name.
        contacts: ``(frames, 2)`` bool contacts ``[left, right]``.
        action, style, content: the take's action and labels.
        keyframes: sorted source frames of all keyframes (transfers and rest boundaries).
        phases: ``(foot, start, stop)`` single-support phases (0 = left).
        rests: ``(start, stop)`` standing-still runs.
        clips: clips cut from this take.
        rejections: its rejected and border steps (or the whole take).
    """

    take: str
    contacts: np.ndarray
    action: str = ""
    style: str = ""
    content: str = ""
    keyframes: list[int] = field(default_factory=list)
    phases: list[tuple[int, int, int]] = field(default_factory=list)
    rests: list[tuple[int, int]] = field(default_factory=list)
    clips: list[Clip] = field(default_factory=list)
    rejections: list[Rejection] = field(default_factory=list)

    @property
    def complete_steps(self) -> int:
        """Steps whose both transfers lie in the take: the ones that should become clips."""
        return len(self.clips) + sum(r.kind == "step" for r in self.rejections)


@dataclass
class Segmentation:
    """Clips and reports of many takes.

    Attributes:
        clips: all clips, in take order.
        rejections: rejected takes, rejected steps and border steps.
        takes: per-take results (segmented takes only).
        ignored: ``(take, content)`` of takes whose content is no locomotion action.
    """

    clips: list[Clip] = field(default_factory=list)
    rejections: list[Rejection] = field(default_factory=list)
    takes: list[TakeSegmentation] = field(default_factory=list)
    ignored: list[tuple[str, str]] = field(default_factory=list)

    @property
    def complete_steps(self) -> int:
        return sum(t.complete_steps for t in self.takes)

    def counts(self) -> Counter[tuple[str, str, str]]:
        """Clip counts per (action, primitive, style)."""
        return Counter((c.action, c.primitive, c.style) for c in self.clips)

    def select(self, action: str | None = None, primitives: Iterable[str] | None = None,
               styles: Iterable[str] | None = None) -> list[Clip]:
        """Clips of one action, some primitives and some styles (None: all)."""
        prims = None if primitives is None else {check_primitive(p, action) for p in primitives}
        styles = None if styles is None else set(styles)
        return [c for c in self.clips if (action is None or c.action == action)
                and (prims is None or c.primitive in prims) and (styles is None or c.style in styles)]


# ---------------------------------------------------------------------------------------------
# Segmentation


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open runs of true values in a ``(frames,)`` bool array."""
    m = np.asarray(mask, dtype=np.int8)
    edges = np.diff(np.concatenate([[0], m, [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def support_phases(contacts: np.ndarray) -> list[tuple[int, int, int]]:
    """Single-support phases ``(foot, start, stop)`` of ``(frames, 2)`` contacts.

    Consecutive phases of the same foot (separated only by double support or flight) are merged.
    """
    left, right = contacts[:, 0], contacts[:, 1]
    phases = sorted([(a, b, 0) for a, b in _runs(left & ~right)] + [(a, b, 1) for a, b in _runs(right & ~left)])
    merged: list[tuple[int, int, int]] = []
    for a, b, foot in phases:
        if merged and merged[-1][0] == foot:
            merged[-1] = (foot, merged[-1][1], b)
        else:
            merged.append((foot, a, b))
    return merged


def rest_runs(positions: np.ndarray, contacts: np.ndarray, fps: float, settings: SegmentSettings,
              leg: float) -> list[tuple[int, int]]:
    """Standing-still runs ``(start, stop)``: both feet down, root slow, long enough."""
    root = np.asarray(positions, dtype=np.float64)[:, ROOT_JOINT, :][:, [0, 2]]
    speed = np.linalg.norm(np.gradient(root, axis=0), axis=-1) * fps
    still = contacts[:, 0] & contacts[:, 1] & (speed < settings.rest_speed * leg)
    min_len = max(1, int(round(settings.min_rest_s * fps)))
    return [(a, b) for a, b in _runs(still) if b - a >= min_len]


def segment_take(take: Take, settings: SegmentSettings | None = None) -> TakeSegmentation:
    """Cut one walk or run take into primitive clips (see the module docstring).

    Args:
        take: a take whose content maps to one of ``settings.actions``.
        settings: segmentation parameters.

    Returns:
        The take's clips, its keyframes and phases, and every step that did not become a clip.
    """
    settings = settings or SegmentSettings()
    action = action_of(take.content, settings.actions)
    if action is None:
        raise ValueError(f"take {take.name}: content {take.content!r} is none of the locomotion actions "
                         f"{list(settings.actions)}")
    fps = float(take.fps)
    n = take.num_frames

    def reject(reason: str, kind: str, start: int | None = None, stop: int | None = None) -> Rejection:
        return Rejection(take.name, action, take.style, take.content, start, stop, reason, kind)

    min_frames = int(np.ceil(settings.min_step_s * fps)) + 3
    if n < min_frames:
        return TakeSegmentation(take.name, np.zeros((n, 2), bool), action, take.style, take.content, rejections=[reject(
            f"take too short for a step: {n} frames ({n / fps:.2f} s at {fps:g} fps); a step needs at least "
            f"{min_frames} frames (min_step_s={settings.min_step_s} plus a contact on each side)", "take")])
    contacts = foot_contacts(take.positions, fps, settings.contacts)
    result = TakeSegmentation(take.name, contacts, action, take.style, take.content)
    if not contacts.any():
        result.rejections.append(reject("no foot contact detected in the whole take (feet never low and "
                                        "slow at once)", "take"))
        return result
    for foot in (0, 1):
        if not contacts[:, foot].any():
            result.rejections.append(reject(f"only the {_FOOT[1 - foot]} foot touches the ground; the "
                                            f"{_FOOT[foot]} foot never does", "take"))
            return result
    leg = float(leg_length(take.positions))
    phases = support_phases(contacts)
    rests = rest_runs(take.positions, contacts, fps, settings, leg)
    result.phases, result.rests = phases, rests
    if not phases:
        result.rejections.append(reject("no single-support phase: the feet never alternate", "take"))
        return result

    def rest_in(lo: int, hi: int) -> tuple[int, int] | None:
        for r in rests:
            if r[0] >= lo and r[1] <= hi:
                return r
        return None

    keyframes: set[int] = set()
    for j, (foot, a, b) in enumerate(phases):
        side = _SIDE[foot]
        # incoming boundary: a transfer from the previous phase, a rest, or the take's start
        before = rest_in(phases[j - 1][2] if j else 0, a)
        if before is not None:
            k0, kind0 = before[1] - 1, "begin"
        elif j > 0:
            k0, kind0 = (phases[j - 1][2] + a - 1) // 2, "transfer"
        else:
            k0, kind0 = None, "border"
        after = rest_in(b, phases[j + 1][1] if j + 1 < len(phases) else n)
        if after is not None:
            k1, kind1 = after[0], "end"
        elif j + 1 < len(phases):
            k1, kind1 = (b + phases[j + 1][1] - 1) // 2, "transfer"
        else:
            k1, kind1 = None, "border"
        for k in (k0, k1):
            if k is not None:
                keyframes.add(k)
        lo, hi = (0 if k0 is None else k0), (n if k1 is None else k1 + 1)  # borders reach the take's ends
        if kind0 == "border" or kind1 == "border":
            where = "start" if kind0 == "border" else "end"
            result.rejections.append(reject(
                f"{_FOOT[foot]} stance cut by the take's {where}: its support transfer is not in the take",
                "border", lo, hi))
            continue
        if kind0 == "begin" and kind1 == "end":
            result.rejections.append(reject(
                f"single {_FOOT[foot]}-stance step between two rests fits no primitive (begin and end at once)",
                "step", lo, hi))
            continue
        primitive = {"begin": f"begin{side}Stance", "end": f"end{side}Stance"}.get(
            kind0 if kind0 == "begin" else kind1, f"{_FOOT[foot]}Stance")
        reason = _check_step(contacts[lo:hi], foot, fps, settings)
        if reason is not None:
            result.rejections.append(reject(f"{primitive}: {reason}", "step", lo, hi))
            continue
        result.clips.append(Clip(action, primitive, take.style, take.name, take.content, lo, hi, fps,
                                 take.frames[lo:hi], contacts[lo:hi]))
    result.keyframes = sorted(keyframes)
    return result


def _check_step(contacts: np.ndarray, foot: int, fps: float, settings: SegmentSettings) -> str | None:
    """Why a step's ``(frames, 2)`` contacts fit no primitive, or None if they fit."""
    duration = (contacts.shape[0] - 1) / fps
    if duration < settings.min_step_s:
        return f"too short ({duration:.3f} s < min_step_s {settings.min_step_s} s)"
    if duration > settings.max_step_s:
        return (f"too long ({duration:.2f} s > max_step_s {settings.max_step_s} s; a missed contact of the "
                f"{_FOOT[1 - foot]} foot?)")
    stance, swing = contacts[:, foot], contacts[:, 1 - foot]
    if swing.all():
        return f"the swing foot ({_FOOT[1 - foot]}) never leaves the ground"
    share = stance.mean()
    if share < settings.min_stance_fraction:
        return (f"the planted foot ({_FOOT[foot]}) touches the ground in only {share:.0%} of the frames "
                f"(< min_stance_fraction {settings.min_stance_fraction:.0%})")
    if len(_runs(stance)) > 1:
        return f"the {_FOOT[foot]} foot leaves the ground and lands again with no {_FOOT[1 - foot]}-foot support (hop)"
    return None


def segment_takes(takes: Iterable[Take], settings: SegmentSettings | None = None) -> Segmentation:
    """Segment every locomotion take; other contents are listed in ``ignored``."""
    settings = settings or SegmentSettings()
    out = Segmentation()
    for take in takes:
        if action_of(take.content, settings.actions) is None:
            out.ignored.append((take.name, take.content))
            continue
        seg = segment_take(take, settings)
        out.takes.append(seg)
        out.clips.extend(seg.clips)
        out.rejections.extend(seg.rejections)
    return out


def stance_speeds(positions: np.ndarray, fps: float, stance_foot: int,
                  contacts: np.ndarray | None = None) -> dict[str, float]:
    """How still the planted foot is in a stance clip, against the swinging foot.

    Speeds are of each foot's slower point (:func:`stylemotion.primitives.contacts.planted_point_speed`).

    Args:
        positions: ``(frames, 21, 3)`` clip positions, metres.
        fps: frames per second of the clip.
        stance_foot: 0 (left planted) or 1 (right planted).
        contacts: ``(frames, 2)`` bool contacts; gives ``planted_contact`` when given.

    Returns:
        ``planted_mid`` and ``swing_mid``: mean horizontal speed (m/s) of the planted and the
        swing foot over the middle half of the clip (frames ``n//4`` to ``n - n//4``);
        ``planted_contact``: the planted foot's mean speed over its contact frames (NaN if none).
    """
    speed = planted_point_speed(positions, fps)
    n = speed.shape[0]
    lo, hi = n // 4, max(n - n // 4, n // 4 + 1)
    out = {"planted_mid": float(speed[lo:hi, stance_foot].mean()),
           "swing_mid": float(speed[lo:hi, 1 - stance_foot].mean())}
    if contacts is not None:
        on = np.asarray(contacts, dtype=bool)[:, stance_foot]
        out["planted_contact"] = float(speed[on, stance_foot].mean()) if on.any() else float("nan")
    return out


# ---------------------------------------------------------------------------------------------
# Canonical timelines


def canonical_timelines(clips: Iterable[Clip], statistic: str = "median") -> dict[tuple[str, str], int]:
    """Canonical length in frames of each (action, primitive): the median (or mean/max/min) of
    its clips' lengths, rounded to a whole frame."""
    funcs = {"median": np.median, "mean": np.mean, "max": np.max, "min": np.min}
    if statistic not in funcs:
        raise ValueError(f"unknown timeline statistic {statistic!r}; one of {sorted(funcs)}")
    lengths: dict[tuple[str, str], list[int]] = {}
    for c in clips:
        lengths.setdefault((c.action, c.primitive), []).append(c.num_frames)
    return {key: int(round(float(funcs[statistic](v)))) for key, v in sorted(lengths.items())}


def _interp(frames: np.ndarray, src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """Linear interpolation of ``(..., n, c)`` samples at increasing times ``src`` to ``dst``
    (clamped to the end values outside ``src``)."""
    n = src.shape[0]
    idx = np.clip(np.searchsorted(src, dst, side="right") - 1, 0, n - 2)
    w = np.clip((dst - src[idx]) / (src[idx + 1] - src[idx]), 0.0, 1.0)[:, None]
    return frames[..., idx, :] * (1.0 - w) + frames[..., idx + 1, :] * w


def time_normalize(frames: np.ndarray, length: int) -> np.ndarray:
    """Resample a clip's frames to ``length`` frames spanning the same first-to-last interval.

    Channels are interpolated linearly in normalized time. For 66-dim frames the root velocity
    and yaw-rate channels (forward differences: frame ``t`` holds the motion from ``t`` to
    ``t + 1``) are interpolated at the middle of each frame interval, and keep their per-second
    units, so the result integrated at :func:`playback_fps` follows the original root path.

    Args:
        frames: ``(..., frames, channels)`` with frames ≥ 2 (e.g. 66-dim frames).
        length: target number of frames, ≥ 2.

    Returns:
        ``(..., length, channels)`` float32.
    """
    frames = np.asarray(frames, dtype=np.float64)
    n = frames.shape[-2]
    if n < 2 or length < 2:
        raise ValueError(f"time normalization needs at least 2 frames in and out, got {n} → {length}")
    src, dst = np.linspace(0.0, 1.0, n), np.linspace(0.0, 1.0, length)
    out = _interp(frames, src, dst)
    if frames.shape[-1] == FRAME_DIM:
        rates = slice(VELOCITY_DIMS.start, FRAME_DIM)
        mid_src = (np.arange(n - 1) + 0.5) / (n - 1)
        mid_dst = (np.arange(length - 1) + 0.5) / (length - 1)
        moved = _interp(frames[..., :-1, rates], mid_src, mid_dst) if n > 2 else \
            np.repeat(frames[..., :1, rates], length - 1, axis=-2)
        out[..., :-1, rates] = moved
        out[..., -1, rates] = moved[..., -1, :]
    return out.astype(np.float32)


def playback_fps(length: int, duration_s: float) -> float:
    """Frame rate at which a clip normalized to ``length`` frames lasts ``duration_s`` seconds."""
    if duration_s <= 0:
        raise ValueError(f"duration must be positive, got {duration_s}")
    return (length - 1) / duration_s


def restore_duration(frames: np.ndarray, duration_s: float, fps: float) -> np.ndarray:
    """Resample time-normalized frames to ``fps`` over ``duration_s`` seconds.

    Args:
        frames: ``(..., length, channels)`` time-normalized frames.
        duration_s: real (e.g. sampled) duration, seconds.
        fps: output frame rate.

    Returns:
        ``(..., round(duration_s·fps) + 1, channels)`` float32.
    """
    return time_normalize(frames, max(2, int(round(duration_s * fps)) + 1))
