"""The real clips an evaluation compares models with, for one primitive.

The takes are segmented and split exactly as for training (:class:`stylemotion.datamodules.clips.ClipDataModule`
with the data's seeded split by take), and every clip of the primitive, of every style, is
time-normalized to the models' canonical length. From them:

* **training data**: the neutral style's train-split clips (what the neutral VAE and the content of
  every style CVAE were fitted on; the "training data" row of Tables 5.2/5.3, the mean motion of
  Table 5.1's neutral column, and the reference of the nearest-training-clip distance);
* **classifier clips**: train-split clips of all styles (fitting) and val+test clips (held out);
* **ground truth of a model** (:meth:`PrimitiveData.ground_truth`): the clips of the model's style
  that the model never saw — every clip of that style except its style example clip(s), and, for
  the neutral style, except the train split; with ``style_truth="heldout"`` a style model's too
  are the held-out splits' clips only.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from stylemotion.datamodules.clips import ClipDataModule
from stylemotion.datasets import TakeSet
from stylemotion.evaluation.sources import MissingExampleError
from stylemotion.models.loading import EvalModel
from stylemotion.primitives.actions import of_action
from stylemotion.primitives.contacts import foot_signals
from stylemotion.primitives.segmentation import Clip, Segmentation, parse_primitive, stance_foot


@dataclass
class PrimitiveData:
    """Real clips of one primitive on one canonical timeline (see the module doc).

    Attributes:
        primitive: ``<action>_<primitive>``.
        length: canonical timeline, frames.
        fps: the data's frame rate.
        neutral_style: the data's neutral style label (``normal``).
        clips: the segmented clips of the data (``ClipDataModule`` set up with every style).
        rest_heights: ``(2, 2)`` resting heights of (foot, [heel, ball]), metres: median over the
            action's train-split takes (the reference of the foot-skating contact test).
        heldout_splits: the splits :meth:`heldout` returns (``val`` and ``test``; ``val`` alone reads no test
            clip).
        style_truth: ``all`` (a style model's ground truth: every clip of its style but its example) or
            ``heldout`` (the held-out splits' clips of its style only).
    """

    primitive: str
    length: int
    fps: float
    neutral_style: str
    clips: ClipDataModule
    rest_heights: np.ndarray
    heldout_splits: tuple[str, ...] = ("val", "test")
    style_truth: str = "all"

    @property
    def stance_foot(self) -> int | None:
        """0 if the primitive plants the left foot, 1 if the right, None for an arm primitive."""
        return stance_foot(parse_primitive(self.primitive)[1])

    @property
    def styles(self) -> list[str]:
        return list(self.clips.style_names)

    def split(self, part: str, style: str | None = None) -> list[Clip]:
        """Clips of a split (``train``, ``val``, ``test``), optionally of one style."""
        return [c for c in self.clips.clips[part] if style is None or c.style == style]

    def heldout(self, style: str | None = None) -> list[Clip]:
        """Val + test clips (of one style); val only when :attr:`heldout_splits` says so."""
        return [c for part in self.heldout_splits for c in self.split(part, style)]

    def style_clips(self, style: str) -> list[Clip]:
        """Every clip of ``style`` in every split."""
        return self.split("train", style) + self.heldout(style)

    def training_data(self) -> list[Clip]:
        """The neutral style's train-split clips."""
        return self.split("train", self.neutral_style)

    def find_example(self, record: Mapping[str, Any]) -> Clip:
        """The clip a style example record (``take``, ``start``, ``stop``, ``primitive``) names.

        Raises:
            MissingExampleError: it is not in this data.
        """
        seg = self.clips.segmentation
        take, start, stop = record.get("take"), record.get("start"), record.get("stop")
        for clip in seg.clips:
            if clip.take == take and clip.start == start and clip.stop == stop and (
                    record.get("primitive") in (None, clip.primitive)):
                return clip
        raise MissingExampleError(
            f"style example {take}[{start}:{stop}] ({record.get('primitive')}, style {record.get('style')}) is not a "
            f"clip of dataset {self.clips.takeset.name!r} as segmented now: evaluate with the data (and segmentation "
            "settings) the model was trained on")

    def ground_truth(self, model: EvalModel, examples: Sequence[Clip] = ()) -> list[Clip]:
        """Clips of ``model.style`` the model never saw (see the module doc)."""
        skip = {(c.take, c.start) for c in examples}
        neutral_or_heldout = model.style == self.neutral_style or self.style_truth == "heldout"
        pool = self.heldout(model.style) if neutral_or_heldout else self.style_clips(model.style)
        return [c for c in pool if (c.take, c.start) not in skip]


def primitive_data(takeset: TakeSet, primitive: str, length: int, neutral_style: str = "normal",
                   segment: Mapping[str, Any] | None = None, split: Mapping[str, Any] | None = None,
                   segmentation: Segmentation | None = None,
                   heldout_splits: Sequence[str] = ("val", "test"), style_truth: str = "all") -> PrimitiveData:
    """Segment, split and time-normalize the real clips of ``primitive`` (see :class:`PrimitiveData`).

    Args:
        takeset: the dataset.
        primitive: ``<action>_<primitive>``.
        length: canonical timeline, frames (the models').
        neutral_style: the neutral style label; must be a style of the data.
        segment: segmentation overrides (as for training).
        split: split settings (as for training; the data config's ``split``).
        segmentation: the action's takes already segmented with ``segment``
            (:func:`stylemotion.primitives.actions.segment_action`); None segments them here.
        heldout_splits: the splits held out of the models (:attr:`PrimitiveData.heldout_splits`).
        style_truth: a style model's ground truth (:attr:`PrimitiveData.style_truth`).
    """
    action, name = parse_primitive(primitive)
    module = ClipDataModule(takeset=takeset, action=action, primitives=[name], styles=None, timeline=int(length),
                            example_styles=[], segment=dict(segment or {}), split=dict(split or {}),
                            segmentation=segmentation)
    module.setup()
    if neutral_style not in module.style_names:
        raise ValueError(f"the neutral style {neutral_style!r} is not a style of dataset {takeset.name!r} "
                         f"(styles: {module.style_names}); set neutral_style")
    takes = [t for t in takeset.takes if of_action(t.content, action, module.segment_settings.actions)
             and module.split_of.get(t.name) == "train"]
    if not takes:
        raise ValueError(f"dataset {takeset.name!r} has no {action} take in the train split")
    rest = np.median(np.stack([foot_signals(t.positions, takeset.fps).rest_heights for t in takes]), axis=0)
    return PrimitiveData(primitive, int(length), float(takeset.fps), neutral_style, module, rest,
                         tuple(heldout_splits), str(style_truth))
