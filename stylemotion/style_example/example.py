"""The user's example(s) of a new style: read by :mod:`stylemotion.datasets.user_motion` (``<BVH>[:start-end]`` →
canonical positions, on the run's skeleton), then cut into the primitives of a run.

Each converted take is labelled with the new style's name and the run's action and cut by
:func:`stylemotion.primitives.actions.segment_action` with the run's segmentation settings.

Several examples (``example=[a.bvh:0-600,b.bvh]``, issue 27): :func:`parse_examples` checks each item (a bad one is
named by its place, ``example[2]=…``), :func:`cut_examples` cuts each and pools their clips: a primitive's model is
conditioned on the clips of that primitive of **every** example (borrowing the action's other clips only where no
example has one). The models pool those clips as they pool one example's several clips: the CVAE's Gram target is
the mean Gram matrix over all clips (:func:`stylemotion.models.style.mean_gram`), the zero-shot network's condition
the mean embedding (and anchor) over all clips (:meth:`stylemotion.models.zero_shot.ZeroShotStyleVAE.condition`),
so each clip counts once whichever example it came from, and one example is exactly the single-example path.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from stylemotion.datasets.user_motion import (
    ConvertedExample,
    ExampleSpec,
    UserMotionError,
    convert_example,
    on_run_skeleton,
    parse_example,
)
from stylemotion.primitives.actions import segment_action
from stylemotion.primitives.segmentation import Clip, Segmentation, SegmentSettings, is_arm_content, parse_primitive

__all__ = ["EXAMPLE_FILE", "MAX_EXAMPLES", "MAX_REASONS", "ConvertedExample", "CutExample", "ExampleSpec",
           "StyleExampleError", "convert_example", "cut_example", "cut_examples", "example_file", "on_run_skeleton",
           "parse_example", "parse_examples"]

#: A ``stylemotion-style`` input that cannot be used: the one error of a user's motion
#: (:class:`stylemotion.datasets.user_motion.UserMotionError`), under the name this package's callers know.
StyleExampleError = UserMotionError

#: Rejected steps listed at most in the "no complete step" message.
MAX_REASONS = 6
#: Where a style folder keeps the converted example (``positions`` (frames, 21, 3) metres, ``fps``, ``joint_names``).
EXAMPLE_FILE = "example/example.npz"
#: Examples one style may be made from (``example=[…]``; the k = 1 … 8 curve of issue 27 fits).
MAX_EXAMPLES = 16


def example_file(index: int) -> str:
    """Where a style folder keeps example ``index`` (0-based): :data:`EXAMPLE_FILE` for the first,
    ``example/example_<index + 1>.npz`` for the others."""
    return EXAMPLE_FILE if index == 0 else f"example/example_{index + 1}.npz"


def parse_examples(value: Any, key: str = "example") -> list[ExampleSpec]:
    """``<BVH>[:start-end]`` or a list of them → one :class:`ExampleSpec` per example.

    A single value gives ``[parse_example(value, key)]`` (exactly the single-example path); the items of a list
    (or tuple, or an OmegaConf ``ListConfig``) are named ``<key>[<i>]`` (1-based) in every message about them.

    Raises:
        StyleExampleError: an empty list, more than :data:`MAX_EXAMPLES` items, an item that is not text, a bad
            item (naming it: ``example[2]=walk.bvh:9-3: …``), or one example given twice.
    """
    if hasattr(value, "_content") and not isinstance(value, str):  # an OmegaConf container
        from omegaconf import OmegaConf

        value = OmegaConf.to_container(value, resolve=True)
    if not isinstance(value, (list, tuple)):
        if isinstance(value, Mapping):
            raise StyleExampleError(f"{key}={value}: give a BVH file or a list of them ({key}=walk.bvh:120-480 or "
                                    f"'{key}=[a.bvh,b.bvh:0-600]'), not a mapping")
        return [parse_example(value, key)]
    if not value:
        raise StyleExampleError(f"{key}=[] is empty: give at least one BVH file ({key}=walk.bvh or "
                                f"'{key}=[a.bvh,b.bvh:0-600]')")
    if len(value) > MAX_EXAMPLES:
        raise StyleExampleError(f"{key}= lists {len(value)} examples; at most {MAX_EXAMPLES} are taken (each is read, "
                                "converted and encoded in full)")
    specs = []
    for i, item in enumerate(value, 1):
        if not isinstance(item, (str, os.PathLike)):
            raise StyleExampleError(f"{key}[{i}]={item!r}: each example must be a BVH file with an optional "
                                    "frame range (walk.bvh:120-480)")
        specs.append(parse_example(os.fspath(item), f"{key}[{i}]"))
    seen: dict[ExampleSpec, str] = {}
    for spec in specs:
        if spec in seen:
            raise StyleExampleError(f"{spec.key}={spec} is {seen[spec]} again: give each example once (a clip "
                                    "given twice would count twice)")
        seen[spec] = spec.key
    return specs


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
        records: run primitive → plain values of each ``used`` clip in the user's file
            (:meth:`ConvertedExample.record`: file, sha256, its frames in the file).
        origin: run primitive → the example (0-based, of :func:`cut_examples`' list) of each ``used`` clip.
        segmentations: every example's segmentation, in order (``segmentation`` is the first's).
    """

    segmentation: Segmentation
    clips: dict[str, list[Clip]]
    used: dict[str, list[Clip]]
    borrowed: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)
    records: dict[str, list[dict[str, Any]]] = field(default_factory=dict)
    origin: dict[str, list[int]] = field(default_factory=dict)
    segmentations: list[Segmentation] = field(default_factory=list)


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
            f"{example.spec.key}={example.spec}: no complete step of the run's primitives {ours} can be cut from it "
            f"({example.positions.shape[0]} frames at {example.fps:g} fps after conversion; primitives cut: {cut}). "
            f"Why: {reasons}. " + (f"Give a {action} take whose hand rises from rest and comes back down"
                                   if is_arm_content(action) else
                                   f"Give a longer {action} with at least one whole step between two support "
                                   "transfers"))
    used, borrowed = {}, []
    for p in ours:
        used[p] = clips[p] or same_action
        if not clips[p]:
            borrowed.append(p)
    return CutExample(segmentation, clips, used, borrowed, [p for p in primitives if p not in ours],
                      {p: [example.record(c) for c in u] for p, u in used.items()},
                      {p: [0] * len(u) for p, u in used.items()}, [segmentation])


def cut_examples(examples: Sequence[ConvertedExample], style: str, action: str, primitives: Sequence[str],
                 settings: SegmentSettings | Mapping[str, Any] | None) -> CutExample:
    """Cut every example (:func:`cut_example`) and pool their clips (see the module doc): ``clips[p]`` and
    ``used[p]`` are the examples' clips of ``p`` in order; a primitive no example has a clip of takes every
    clip of the action of every example (``borrowed``). One example gives exactly :func:`cut_example`'s result.

    Raises:
        StyleExampleError: no examples, or an example without a complete step (naming it).
    """
    if not examples:
        raise StyleExampleError("no example given: give example=<BVH>[:start-end] or a list of them")
    cuts = [cut_example(e, style, action, primitives, settings) for e in examples]
    if len(cuts) == 1:
        return cuts[0]
    ours = list(cuts[0].used)
    clips = {p: [c for cut in cuts for c in cut.clips[p]] for p in primitives}
    used: dict[str, list[Clip]] = {}
    records: dict[str, list[dict[str, Any]]] = {}
    origin: dict[str, list[int]] = {}
    borrowed = []
    for p in ours:
        own = any(cut.clips[p] for cut in cuts)
        picked = [(i, c, r) for i, cut in enumerate(cuts) for c, r in zip(cut.used[p], cut.records[p])
                  if not own or p not in cut.borrowed]
        used[p], origin[p], records[p] = [c for _, c, _ in picked], [i for i, _, _ in picked], [r for *_, r in picked]
        if not own:
            borrowed.append(p)
    return replace(cuts[0], clips=clips, used=used, borrowed=borrowed, records=records, origin=origin,
                   segmentations=[cut.segmentation for cut in cuts])
