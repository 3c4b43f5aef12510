"""Arm motion primitives: a raise-up or wave take cut into ``raise`` and ``lower`` clips (for the Morphable
Graph's arm primitive, Du Fig. 3.9/3.10 and §4.5.3's "hand reaching a target at the end of an arm primitive").

:mod:`stylemotion.primitives` cuts walks and runs at foot contacts; arm takes (Bandai's ``raise-up-*-hand``
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
  the slowest frame within ``search_s`` after ``h`` is back below the low level.

Clips are :class:`stylemotion.primitives.Clip` (frames of the source range, so positions start at the origin
facing +Z like every clip) with ``action`` = the take's content (e.g. ``raise-up-left-hand``: one primitive
per content, hands never mixed) and ``primitive`` = ``raise`` or ``lower``. A take without an active hand,
that does not come back down, or whose clip would be shorter than ``min_frames`` gives a rejection reason
instead.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from stylemotion.contacts import foot_contacts
from stylemotion.datasets.base import Take
from stylemotion.primitives import Clip
from stylemotion.skeleton import CANONICAL_JOINTS

#: Arm primitives, in take order.
ARM_PRIMITIVES = ("raise", "lower")
#: Content prefixes of arm takes (Bandai dataset 2).
ARM_CONTENTS = ("raise-up", "wave")
HANDS = ("Hand_L", "Hand_R")


@dataclass(frozen=True)
class ArmSettings:
    """Thresholds of :func:`segment_arm_take` (see the module doc).

    Attributes:
        min_raise_m: height range (m) that makes a hand active.
        threshold: ``f``, share of the height range that counts as leaving rest / reaching the top.
        search_s: window (s) searched for the speed minimum beside each crossing.
        min_frames: shortest clip kept.
    """

    min_raise_m: float = 0.2
    threshold: float = 0.1
    search_s: float = 0.5
    min_frames: int = 8

    def __post_init__(self) -> None:
        if not self.min_raise_m > 0 or not 0 < self.threshold < 0.5 or not self.search_s >= 0 or self.min_frames < 2:
            raise ValueError(f"ArmSettings need min_raise_m > 0, 0 < threshold < 0.5, search_s ≥ 0, min_frames ≥ 2; "
                             f"got {self}")


def is_arm_content(content: str) -> bool:
    return any(content == p or content.startswith(p + "-") for p in ARM_CONTENTS)


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


def segment_arm_take(take: Take, settings: ArmSettings | None = None) -> tuple[list[Clip], str | None]:
    """The ``raise`` and ``lower`` clips of one arm take (see the module doc), or no clip and the reason."""
    if not is_arm_content(take.content):
        raise ValueError(f"take {take.name}: content {take.content!r} is not an arm motion ({list(ARM_CONTENTS)})")
    positions = np.asarray(take.positions)
    found = arm_keyframes(positions, take.fps, settings)
    if isinstance(found, str):
        return [], f"{take.name}: {found}"
    ranges, _ = found
    contacts = foot_contacts(positions, take.fps)
    clips = [Clip(action=take.content, primitive=p, style=take.style, take=take.name, content=take.content,
                  start=a, stop=b, fps=float(take.fps), frames=np.asarray(take.frames[a:b], dtype=np.float32),
                  contacts=contacts[a:b]) for p, (a, b) in ranges.items()]
    return clips, None


def arm_clips(takes: Iterable[Take], content: str, primitive: str, settings: ArmSettings | None = None
              ) -> tuple[list[Clip], list[str]]:
    """The ``primitive`` clips of the takes of ``content`` and the reasons of the takes that gave none."""
    if primitive not in ARM_PRIMITIVES:
        raise ValueError(f"unknown arm primitive {primitive!r}; one of {list(ARM_PRIMITIVES)}")
    clips, rejected = [], []
    for take in takes:
        if take.content != content:
            continue
        got, reason = segment_arm_take(take, settings)
        clips += [c for c in got if c.primitive == primitive]
        if reason:
            rejected.append(reason)
    return clips, rejected
