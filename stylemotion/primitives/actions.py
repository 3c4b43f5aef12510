"""Takes of one action cut into its primitives, whatever the action: a walk or run at its foot contacts
(:mod:`stylemotion.primitives.segmentation`), an arm content (``raise-up-right-hand``, ``wave-both-hands``) at its
hands' rest and top (:mod:`stylemotion.primitives.arm`). Callers that serve any primitive segment through here.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

from stylemotion.primitives.arm import segment_arm_takes
from stylemotion.primitives.segmentation import (
    ACTIONS,
    Segmentation,
    SegmentSettings,
    action_of,
    is_arm_content,
    segment_takes,
)

if TYPE_CHECKING:
    from stylemotion.datasets.base import Take


def of_action(content: str, action: str, actions: Sequence[str] = ACTIONS) -> bool:
    """Whether a take of ``content`` is one of ``action``: a locomotion action's by :func:`action_of`, an arm
    content's (``raise-up-right-hand``) when it is that content."""
    return content == action if is_arm_content(action) else action_of(content, actions) == action


def segment_action(takes: Iterable[Take], action: str, settings: SegmentSettings | None = None) -> Segmentation:
    """The takes of ``action`` (:func:`of_action`) segmented: a locomotion action's by :func:`segment_takes`, an arm
    content's by :func:`stylemotion.primitives.arm.segment_arm_takes` (no foot-contact settings)."""
    settings = settings or SegmentSettings()
    chosen = [t for t in takes if of_action(t.content, action, settings.actions)]
    if is_arm_content(action):
        return segment_arm_takes(chosen)
    return segment_takes(chosen, settings)


def segment_actions(takes: Sequence[Take], actions: Iterable[str], settings: SegmentSettings | None = None
                    ) -> Segmentation:
    """:func:`segment_action` of each of ``actions``, merged in the order given."""
    out = Segmentation()
    for action in dict.fromkeys(actions):
        seg = segment_action(takes, action, settings)
        out.clips += seg.clips
        out.rejections += seg.rejections
        out.takes += seg.takes
    return out
