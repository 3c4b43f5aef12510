"""The user's example of a new style: read by :mod:`stylemotion.datasets.user_motion` (``<BVH>[:start-end]`` →
canonical positions, on the run's skeleton), then cut into the primitives of a run.

The converted take is labelled with the new style's name and the run's action and cut by
:func:`stylemotion.primitives.segmentation.segment_action` with the run's segmentation settings.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from stylemotion.datasets.user_motion import (
    ConvertedExample,
    ExampleSpec,
    UserMotionError,
    convert_example,
    on_run_skeleton,
    parse_example,
)
from stylemotion.primitives.segmentation import Clip, Segmentation, SegmentSettings, parse_primitive, segment_action

__all__ = ["EXAMPLE_FILE", "MAX_REASONS", "ConvertedExample", "CutExample", "ExampleSpec", "StyleExampleError",
           "convert_example", "cut_example", "on_run_skeleton", "parse_example"]

#: A ``stylemotion-style`` input that cannot be used: the one error of a user's motion
#: (:class:`stylemotion.datasets.user_motion.UserMotionError`), under the name this package's callers know.
StyleExampleError = UserMotionError

#: Rejected steps listed at most in the "no complete step" message.
MAX_REASONS = 6
#: Where a style folder keeps the converted example (``positions`` (frames, 21, 3) metres, ``fps``, ``joint_names``).
EXAMPLE_FILE = "example/example.npz"


@dataclass
class CutExample:
    """The example's clips for each primitive of a run.

    Attributes:
        segmentation: the example take's segmentation (clips, rejected and border steps).
        clips: run primitive → the clips of that primitive cut from the example.
        used: run primitive → the clips its model is conditioned on: its own, or, where the example has
            none of that primitive, every clip of the same action (the thesis' example is one clip of any
            primitive); primitives of another action than the example's are absent.
        borrowed: run primitives whose ``used`` clips are of other primitives.
        skipped: run primitives of another action than the example's.
    """

    segmentation: Segmentation
    clips: dict[str, list[Clip]]
    used: dict[str, list[Clip]]
    borrowed: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)


def cut_example(example: ConvertedExample, style: str, action: str, primitives: Sequence[str],
                settings: SegmentSettings | Mapping[str, Any] | None) -> CutExample:
    """Segment the example as a take of ``action`` and pick the clips of each run primitive.

    Raises:
        StyleExampleError: no clip of any primitive of the run's ``action`` (no complete step); the
            message lists why each step was not cut.
    """
    segmentation = segment_action([example.take(style, action)], action, SegmentSettings.from_dict(settings))
    clips = {p: [c for c in segmentation.clips if f"{c.action}_{c.primitive}" == p] for p in primitives}
    same_action = [c for c in segmentation.clips if c.action == action]
    ours = [p for p in primitives if parse_primitive(p)[0] == action]
    if not any(clips[p] for p in ours):
        shown = segmentation.rejections[:MAX_REASONS]
        reasons = "; ".join(r.reason + ("" if r.start is None else f" (frames {r.start}-{r.stop} at {example.fps:g} "
                                                                   "fps)") for r in shown) or "no step found"
        if len(segmentation.rejections) > len(shown):
            reasons += f"; … {len(segmentation.rejections) - len(shown)} more"
        cut = ", ".join(sorted({c.primitive for c in same_action})) or "none"
        raise StyleExampleError(
            f"example={example.spec}: no complete step of the run's primitives {ours} can be cut from it "
            f"({example.positions.shape[0]} frames at {example.fps:g} fps after conversion; primitives cut: {cut}). "
            f"Why: {reasons}. Give a longer {action} with at least one whole step between two support transfers")
    used, borrowed = {}, []
    for p in ours:
        used[p] = clips[p] or same_action
        if not clips[p]:
            borrowed.append(p)
    return CutExample(segmentation, clips, used, borrowed, [p for p in primitives if p not in ours])
