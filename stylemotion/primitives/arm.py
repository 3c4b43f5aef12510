"""Arm motion primitives: a raise-up or wave take cut into ``raise``, ``wave`` and ``lower`` clips (for the Morphable
Graph's arm primitive, Du Fig. 3.9/3.10 and §4.5.3's "hand reaching a target at the end of an arm primitive").

:mod:`stylemotion.primitives.segmentation` cuts walks and runs at foot contacts; arm takes (Bandai's ``raise-up-*-hand``
and ``wave-*-hand``: rest, raise, hold or wave, lower, rest) have no steps. Here the *active* hands are those
whose height (Y, metres) varies by at least ``min_raise_m`` over the take; ``h(t)`` is their mean height and
``s(t)`` the largest of their speeds (m/s). With ``lo``/``hi`` the lowest/highest ``h``, the take is cut at
speed minima near where ``h`` crosses ``lo + f·(hi − lo)`` (leaving rest) and ``hi − f·(hi − lo)`` (reaching
the top), ``f = threshold``:

(ties: the frame nearest the crossing)

* ``raise``: from the slowest frame within ``search_s`` before the first upward crossing of the low level, to
  the slowest frame within ``search_s`` after the first crossing of the high level — its last frame is the
  keyframe where the hand has arrived;
* ``lower``: from the slowest frame within ``search_s`` before the last time ``h`` is at the high level, to
  the slowest frame within ``search_s`` after ``h`` is back below the low level;
* ``wave`` (``wave-*`` contents only): the hold from the last frame of ``raise`` to the first of ``lower``
  cut into single cycles of the active hands' side-to-side motion (:func:`wave_cycles`). The hold is put in
  the body frame: hand positions relative to the root's ground projection, rotated by the mean facing
  (:func:`stylemotion.representation.facing_yaw`) of the hold so the body faces +Z (+X its left), which makes
  the cut independent of where the take faces. Per active hand, the dominant horizontal axis is the first
  principal axis of the hand's ``(x, z)`` over the hold, signed to point to the hand's outside (+X for the
  left hand, −X for the right); ``w(t)`` is the hand's position along it (m). Two active hands that move
  mirrored (their ``w`` positively correlated) give the mean of the two; hands that move in parallel give
  the half difference ``(w_L − w_R) / 2``, positive towards the body's left. The extremes are the local maxima
  of ``w`` (found over the whole take, kept in the hold) with a prominence of at least ``min_wave_m / 2``
  (the hand farthest out: towards the body's outside, or for hands in parallel towards its left), and a cycle
  runs from one extreme to the next, both frames included, so every cycle starts and ends at the same phase
  (consecutive cycles share that frame).
  The parts of the hold before the first and after the last extreme are partial cycles and dropped. A hold
  with fewer than two extremes gives a rejection (no oscillation); a cycle whose amplitude (the lower of its
  two extremes minus the lowest ``w`` between them, m) is below ``min_wave_m`` or that is shorter than
  ``min_frames`` is rejected alone.

Clips are :class:`stylemotion.primitives.segmentation.Clip` (frames of the source range, so positions start at the
origin facing +Z like every clip) with ``action`` = the take's content (e.g. ``raise-up-left-hand``: one primitive
per content, hands never mixed) and ``primitive`` = ``raise``, ``wave`` or ``lower``. A take without an
active hand, that does not come back down, or whose clip would be shorter than ``min_frames`` gives a
rejection reason instead. Asking a ``raise-up-*`` content for ``wave`` is an error.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from stylemotion.geometry import direction_yaw, facing_direction, rotate_yaw
from stylemotion.primitives.contacts import foot_contacts
from stylemotion.primitives.segmentation import (
    ARM_CONTENTS,
    Clip,
    Rejection,
    Segmentation,
    check_arm_primitive,
    content_primitives,
    is_arm_content,
)
from stylemotion.representation import ROOT_JOINT, facing_yaw
from stylemotion.skeleton import CANONICAL_JOINTS

if TYPE_CHECKING:  # the data-set package loads scipy: not needed to import this module (command start-up)
    from stylemotion.datasets.base import Take

HANDS = ("Hand_L", "Hand_R")


@dataclass(frozen=True)
class ArmSettings:
    """Thresholds of :func:`segment_arm_take` (see the module doc).

    Attributes:
        min_raise_m: height range (m) that makes a hand active.
        threshold: ``f``, share of the height range that counts as leaving rest / reaching the top.
        search_s: window (s) searched for the speed minimum beside each crossing.
        min_frames: shortest clip kept.
        min_wave_m: smallest amplitude (m, extreme to extreme along the hand's side-to-side axis) of a
            ``wave`` cycle; extremes need half of it as prominence.
    """

    min_raise_m: float = 0.2
    threshold: float = 0.1
    search_s: float = 0.5
    min_frames: int = 8
    min_wave_m: float = 0.05

    def __post_init__(self) -> None:
        if (not self.min_raise_m > 0 or not 0 < self.threshold < 0.5 or not self.search_s >= 0 or self.min_frames < 2
                or not self.min_wave_m > 0):
            raise ValueError(f"ArmSettings need min_raise_m > 0, 0 < threshold < 0.5, search_s ≥ 0, min_frames ≥ 2, "
                             f"min_wave_m > 0; got {self}")


def arm_keyframes(positions: np.ndarray, fps: float, settings: ArmSettings | None = None
                  ) -> tuple[dict[str, tuple[int, int]], list[str]] | str:
    """``{"raise": (start, stop), "lower": (start, stop)}`` frame ranges (stop exclusive) and the active hands of
    ``(T, 21, 3)`` positions (m, Y up), or the reason there are none."""
    settings = settings or ArmSettings()
    idx = [CANONICAL_JOINTS.index(h) for h in HANDS]
    heights = positions[:, idx, 1]
    active = [i for i, j in enumerate(idx) if np.ptp(heights[:, i]) >= settings.min_raise_m]
    if not active:
        return f"no hand rises by {settings.min_raise_m} m (ranges {np.round(np.ptp(heights, 0), 3).tolist()} m)"
    h = heights[:, active].mean(1)
    speed = np.linalg.norm(np.gradient(positions[:, [idx[i] for i in active]], axis=0), axis=-1).max(1) * fps
    lo, hi = float(h.min()), float(h.max())
    low, high = lo + settings.threshold * (hi - lo), hi - settings.threshold * (hi - lo)
    w = max(1, int(round(settings.search_s * fps)))
    above_low, above_high = np.flatnonzero(h > low), np.flatnonzero(h >= high)
    t_a, t_b, t_c = int(above_low[0]), int(above_high[0]), int(above_high[-1])
    back = np.flatnonzero(h[t_c:] <= low)
    if t_a == 0:
        return "the hand is already raised at the first frame"
    if not len(back):
        return "the hand does not come back down to rest"
    t_d = t_c + int(back[0])

    def slowest(lo_frame: int, hi_frame: int, latest: bool) -> int:
        """The slowest frame in ``[lo_frame, hi_frame]``; ties go to the one nearest the crossing."""
        lo_frame, hi_frame = max(0, lo_frame), min(len(h) - 1, hi_frame)
        window = speed[lo_frame:hi_frame + 1]
        return lo_frame + (len(window) - 1 - int(np.argmin(window[::-1])) if latest else int(np.argmin(window)))

    raise_start = slowest(t_a - w, t_a, latest=True)
    raise_end = slowest(t_b, min(t_b + w, t_c), latest=False)
    lower_start = slowest(max(t_c - w, raise_end), t_c, latest=True)
    lower_end = slowest(t_d, t_d + w, latest=False)
    ranges = {"raise": (raise_start, raise_end + 1), "lower": (lower_start, lower_end + 1)}
    short = [f"{p} {b - a} frames" for p, (a, b) in ranges.items() if b - a < settings.min_frames]
    if short:
        return f"clip shorter than min_frames={settings.min_frames}: {', '.join(short)}"
    return ranges, [HANDS[i] for i in active]


def wave_signal(positions: np.ndarray, fps: float, hold: tuple[int, int], hands: list[str],
                frames: tuple[int, int] | None = None) -> np.ndarray:
    """``w(t)`` (m): the active hands' position along their side-to-side axis in the body frame, positive at the
    extreme where cycles are cut (module doc), over the take frames ``frames = (start, stop)`` (stop exclusive;
    default the hold). The facing, the axes, their centre and the two hands' correlation are those of the frames
    ``hold = (start, stop)``."""
    a, b = hold
    c, d = hold if frames is None else frames
    yaw = facing_yaw(positions, fps)[a:b]
    heading = float(direction_yaw(facing_direction(yaw).mean(0)))
    ground = positions[c:d, ROOT_JOINT].copy()
    ground[:, 1] = 0.0
    signals = []
    for hand in hands:
        local = rotate_yaw(positions[c:d, CANONICAL_JOINTS.index(hand)] - ground, -heading)[:, [0, 2]]
        held = local[a - c:b - c] - local[a - c:b - c].mean(0)
        axis = np.linalg.eigh(held.T @ held)[1][:, -1]  # first principal axis of the hand's (x, z) over the hold
        outside = 1.0 if hand == "Hand_L" else -1.0
        if axis[0] * outside < 0 or (axis[0] == 0 and axis[1] < 0):
            axis = -axis
        signals.append((local - local[a - c:b - c].mean(0)) @ axis)
    if len(signals) == 1:
        return signals[0]
    left, right = signals
    mirrored = float(np.mean(left[a - c:b - c] * right[a - c:b - c])) >= 0
    return (left + right) / 2 if mirrored else (left - right) / 2


def wave_cycles(positions: np.ndarray, fps: float, hold: tuple[int, int], hands: list[str],
                settings: ArmSettings | None = None) -> tuple[list[tuple[int, int]], list[str]] | str:
    """The ``wave`` cycles ``(start, stop)`` (take frames, stop exclusive) of the hold ``(start, stop)`` of
    ``(T, 21, 3)`` positions and the reasons of the cycles rejected, or the reason the hold has none.

    The extremes are looked for in ``w`` over the whole take and kept when they lie in the hold, so that one at
    or next to the hold's first or last frame is judged (local maximum, prominence) against the frames beyond.
    """
    from scipy.signal import find_peaks  # scipy is not needed to import this module (command start-up)

    settings = settings or ArmSettings()
    a, b = hold
    if b - a < 3:
        return f"wave: hold of {b - a} frames"
    s = wave_signal(positions, fps, hold, hands, frames=(0, len(positions)))
    extremes = [int(e) for e in find_peaks(s, prominence=settings.min_wave_m / 2)[0] if a <= e < b]
    if len(extremes) < 2:
        return (f"wave: no oscillation ({len(extremes)} extreme(s) of prominence ≥ {settings.min_wave_m / 2} m; "
                f"side-to-side range {np.ptp(s[a:b]):.3f} m over the hold [{a}:{b}])")
    cycles, rejected = [], []
    for e0, e1 in zip(extremes[:-1], extremes[1:]):
        amplitude = min(s[e0], s[e1]) - float(s[e0:e1 + 1].min())
        if amplitude < settings.min_wave_m:
            rejected.append(f"wave cycle [{e0}:{e1 + 1}]: amplitude {amplitude:.3f} m < min_wave_m="
                            f"{settings.min_wave_m}")
        elif e1 + 1 - e0 < settings.min_frames:
            rejected.append(f"wave cycle [{e0}:{e1 + 1}]: shorter than min_frames={settings.min_frames}")
        else:
            cycles.append((e0, e1 + 1))
    return cycles, rejected


def _segment(take: Take, settings: ArmSettings | None, primitives: Iterable[str] | None
             ) -> tuple[list[Clip], list[str]]:
    """The clips of ``primitives`` (default all of the content's) of one arm take and the rejection reasons."""
    if not is_arm_content(take.content):
        raise ValueError(f"take {take.name}: content {take.content!r} is not an arm motion ({list(ARM_CONTENTS)})")
    primitives = content_primitives(take.content) if primitives is None else tuple(primitives)
    for primitive in primitives:
        check_arm_primitive(take.content, primitive)
    positions = np.asarray(take.positions)
    found = arm_keyframes(positions, take.fps, settings)
    if isinstance(found, str):
        return [], [f"{take.name}: {found}"]
    ranges, hands = found
    cut: list[tuple[str, int, int]] = [(p, *ranges[p]) for p in ("raise",) if p in primitives]
    rejected = []
    if "wave" in primitives:
        cycles = wave_cycles(positions, take.fps, (ranges["raise"][1] - 1, ranges["lower"][0] + 1), hands, settings)
        if isinstance(cycles, str):
            rejected.append(f"{take.name}: {cycles}")
        else:
            cut += [("wave", a, b) for a, b in cycles[0]]
            rejected += [f"{take.name}: {r}" for r in cycles[1]]
    cut += [(p, *ranges[p]) for p in ("lower",) if p in primitives]
    contacts = foot_contacts(positions, take.fps)
    clips = [Clip(action=take.content, primitive=p, style=take.style, take=take.name, content=take.content,
                  start=a, stop=b, fps=float(take.fps), frames=np.asarray(take.frames[a:b], dtype=np.float32),
                  contacts=contacts[a:b]) for p, a, b in cut]
    return clips, rejected


def segment_arm_take(take: Take, settings: ArmSettings | None = None, primitives: Iterable[str] | None = None
                     ) -> tuple[list[Clip], str | None]:
    """The clips of one arm take in take order (``primitives``, default the content's: ``raise``, the ``wave``
    cycles of a wave take, ``lower``; see the module doc) and the rejection reasons (``; ``-joined, None when
    nothing was rejected). ValueError for a content that is no arm motion or lacks one of ``primitives``."""
    clips, rejected = _segment(take, settings, primitives)
    return clips, "; ".join(rejected) or None


def segment_arm_takes(takes: Iterable[Take], settings: ArmSettings | None = None) -> Segmentation:
    """Every arm take of ``takes`` cut into its content's primitives (:func:`segment_arm_take`), as a
    :class:`~stylemotion.primitives.segmentation.Segmentation` (a take without clips, or a wave cycle, is a
    rejection naming why; takes of other contents are listed in ``ignored``)."""
    out = Segmentation()
    for take in takes:
        if not is_arm_content(take.content):
            out.ignored.append((take.name, take.content))
            continue
        clips, rejected = _segment(take, settings, None)
        out.clips.extend(clips)
        out.rejections.extend(Rejection(take.name, take.content, take.style, take.content, None, None, reason,
                                        "step" if clips else "take") for reason in rejected)
    return out


def arm_clips(takes: Iterable[Take], content: str, primitive: str, settings: ArmSettings | None = None
              ) -> tuple[list[Clip], list[str]]:
    """The ``primitive`` clips of the takes of ``content`` and the reasons of the takes (for ``wave``: also of
    the single cycles) that gave none; ValueError for a primitive ``content`` lacks (``wave`` of a raise-up)."""
    check_arm_primitive(content, primitive)
    clips, rejected = [], []
    for take in takes:
        if take.content != content:
            continue
        got, reasons = _segment(take, settings, (primitive,))
        clips += got
        rejected += reasons
    return clips, rejected
