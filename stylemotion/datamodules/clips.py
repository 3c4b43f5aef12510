"""Motion primitive clips as a Lightning DataModule, and one style example clip per style.

The takes of a dataset are segmented (:func:`stylemotion.primitives.segmentation.segment_takes`) and the clips
of one action, some primitives and some styles are served time-normalized to one canonical length
(thesis §4.4.1, §5.3). The split is the dataset's seeded split by take
(:meth:`stylemotion.datasets.TakeSet.split` with the data config's ``split`` settings), so a clip
is in the split of the take it was cut from, exactly like the windows of
:mod:`stylemotion.datamodules.windows`.

Items are dicts:

* ``frames``: ``(length, 66)`` float32 raw frames, time-normalized (velocity channels per second);
* ``duration_s``: the clip's real duration, seconds (to play it back at ``(length-1)/duration_s`` fps);
* ``style``: index into :attr:`ClipDataModule.style_names`;
* ``primitive``: index into :data:`stylemotion.primitives.segmentation.PRIMITIVES` followed by ``ARM_PRIMITIVES``.

Style examples (the thesis conditions each style model on a single clip): for each style one clip
of ``example.primitive`` (default: the first selected primitive), cut from takes of
``example.content`` (default: the action itself, i.e. straight walking, as in the thesis §5.4.3),
picked by ``example.pick``:

* ``median``: the clip whose duration is closest to the median duration of the candidates
  (a typical step; ties go to the first by take name and frame);
* ``first``: the first candidate by take name and frame;
* ``index``: candidate number ``example.index`` by take name and frame;
* ``take``: the clip of take ``example.take`` (starting at ``example.start`` if given).

``example.split`` (``all``, ``train``, ``val`` or ``test``) restricts where examples come from.
"""

from __future__ import annotations

import logging
from collections import Counter
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import torch
from torch.utils.data import Dataset

from stylemotion.datamodules.base import SplitDataModule
from stylemotion.datasets import TakeSet
from stylemotion.io.errors import UserInputError
from stylemotion.primitives.actions import segment_action
from stylemotion.primitives.segmentation import (
    ARM_PRIMITIVES,
    PRIMITIVES,
    Clip,
    Segmentation,
    SegmentSettings,
    check_primitive,
    is_arm_content,
    time_normalize,
)
from stylemotion.representation import FRAME_DIM

log = logging.getLogger(__name__)

SPLITS = ("train", "val", "test")
EXAMPLE_PICKS = ("median", "first", "index", "take")
#: What the items' ``primitive`` index counts in.
PRIMITIVE_INDEX = PRIMITIVES + ARM_PRIMITIVES
DEFAULT_EXAMPLE: dict[str, Any] = {"primitive": None, "content": None, "pick": "median", "index": 0,
                                   "take": None, "start": None, "split": "all"}


class NoClipsError(UserInputError, ValueError):
    """A selection (split, primitive, style or style example) holds no clip."""


class ClipDataset(Dataset):
    """Time-normalized clips in memory.

    Attributes:
        clips: the source clips (with their take, frame range and labels).
        frames: ``(clips, length, 66)`` float32 raw frames.
        duration_s: ``(clips,)`` float32 real durations, seconds.
        style: ``(clips,)`` int64 style indices.
        primitive: ``(clips,)`` int64 primitive indices (into ``PRIMITIVES + ARM_PRIMITIVES``).
    """

    def __init__(self, clips: Sequence[Clip], length: int, style_names: Sequence[str]):
        self.clips = list(clips)
        self.length = length
        style_index = {s: i for i, s in enumerate(style_names)}
        frames = [time_normalize(c.frames, length) for c in self.clips]
        self.frames = torch.from_numpy(np.stack(frames)) if frames else torch.zeros(0, length, FRAME_DIM)
        self.duration_s = torch.tensor([c.duration_s for c in self.clips], dtype=torch.float32)
        self.style = torch.tensor([style_index[c.style] for c in self.clips], dtype=torch.int64)
        self.primitive = torch.tensor([PRIMITIVE_INDEX.index(c.primitive) for c in self.clips], dtype=torch.int64)

    def __len__(self) -> int:
        return len(self.clips)

    def __getitem__(self, index: int) -> dict[str, torch.Tensor]:
        return {"frames": self.frames[index], "duration_s": self.duration_s[index],
                "style": self.style[index], "primitive": self.primitive[index]}


class ClipDataModule(SplitDataModule):
    """Train/val/test primitive clips of one action, filtered by primitive and style.

    Args:
        data: a ``data`` config node as a plain mapping (``name``, loader options, ``split``);
            see ``configs/data/``. Ignored when ``takeset`` is given.
        takeset: an already built :class:`TakeSet` (Python use; not saved in checkpoints).
        action: ``walk`` or ``run`` (see :data:`stylemotion.primitives.segmentation.ACTIONS`), or an arm content
            (``raise-up-right-hand``, cut by :mod:`stylemotion.primitives.arm`).
        primitives: primitives to serve (names from :data:`~stylemotion.primitives.segmentation.PRIMITIVES`; of an
            arm content, from ``ARM_PRIMITIVES``).
        styles: styles to serve; None = every style of the dataset.
        timeline: ``"median"`` (the median length of the selected train clips, all selected
            primitives together, at least ``min_length``) or a fixed number of frames.
        example: how style examples are picked (see the module docstring); missing keys take
            the defaults ``pick=median, content=<action>, split=all``.
        example_styles: styles that need an example; None = every style of the dataset.
        segment: :class:`~stylemotion.primitives.segmentation.SegmentSettings` values (``contacts`` as a dict).
        batch_size: training batch size (clips).
        eval_batch_size: validation/test batch size; None = ``batch_size``.
        num_workers: DataLoader worker processes.
        split: split settings (``seed``, ``val_fraction``, ``test_fraction``); None = ``data.split``.
        segmentation: the takeset's ``action`` takes already segmented with these ``segment``
            settings (Python use, e.g. one segmentation shared by the primitives of an evaluation);
            None segments them in :meth:`setup`.
        min_length: fewest frames of the ``median`` timeline (e.g. an autoencoder's receptive field: Bandai's run
            steps last 12 frames at 30 fps, the encoder's kernel 15).
    """

    def __init__(
        self,
        data: Mapping[str, Any] | None = None,
        takeset: TakeSet | None = None,
        action: str = "walk",
        primitives: Sequence[str] = ("leftStance",),
        styles: Sequence[str] | None = ("normal",),
        timeline: str | int = "median",
        example: Mapping[str, Any] | None = None,
        example_styles: Sequence[str] | None = None,
        segment: Mapping[str, Any] | None = None,
        batch_size: int = 64,
        eval_batch_size: int | None = None,
        num_workers: int = 0,
        split: Mapping[str, Any] | None = None,
        segmentation: Segmentation | None = None,
        min_length: int = 2,
    ):
        super().__init__(data, takeset, batch_size, eval_batch_size, num_workers, split)
        primitives = [primitives] if isinstance(primitives, str) else list(primitives)
        if not primitives:
            raise ValueError(f"select at least one primitive of {list(PRIMITIVES)}")
        for p in primitives:
            check_primitive(p, action)
        if not (timeline == "median" or (isinstance(timeline, int) and timeline >= 2)):
            raise ValueError(f"timeline must be 'median' or a number of frames ≥ 2, got {timeline!r}")
        unknown = sorted(set(example or {}) - set(DEFAULT_EXAMPLE))
        if unknown:
            raise ValueError(f"unknown style example option(s) {unknown}; valid: {sorted(DEFAULT_EXAMPLE)}")
        self.example_cfg = {**DEFAULT_EXAMPLE, **dict(example or {})}
        if self.example_cfg["pick"] not in EXAMPLE_PICKS:
            raise ValueError(f"unknown example pick {self.example_cfg['pick']!r}; one of {list(EXAMPLE_PICKS)}")
        if self.example_cfg["primitive"] is not None:
            check_primitive(self.example_cfg["primitive"], action)
        if self.example_cfg["split"] not in ("all",) + SPLITS:
            raise ValueError(f"example split must be 'all' or one of {list(SPLITS)}, got "
                             f"{self.example_cfg['split']!r}")
        self.save_hyperparameters(ignore=["takeset", "segmentation"])
        self.action = action
        self.primitives = primitives
        self.requested_styles = None if styles is None else ([styles] if isinstance(styles, str) else list(styles))
        self.timeline = timeline
        self.min_length = int(min_length)
        self.requested_example_styles = None if example_styles is None else list(example_styles)
        self.segment_settings = SegmentSettings.from_dict(dict(segment or {}))
        if action not in self.segment_settings.actions and not is_arm_content(action):
            raise ValueError(f"unknown action {action!r}; segmented actions: {list(self.segment_settings.actions)} "
                             "and the arm contents (raise-up-…, wave-…)")
        self.segmentation: Segmentation | None = None
        self._given_segmentation = segmentation
        self.split_of: dict[str, str] = {}
        self.clips: dict[str, list[Clip]] = {}
        self.length: int | None = None
        self.style_names: list[str] = []
        self._examples: dict[str, Clip] = {}

    @property
    def example_primitive(self) -> str:
        return self.example_cfg["primitive"] or self.primitives[0]

    # -- building

    def setup(self, stage: str | None = None) -> None:
        if self.segmentation is not None:
            return
        takeset = self.takeset
        dataset_styles = takeset.label_values("style")
        self.style_names = dataset_styles
        wanted = self.requested_styles if self.requested_styles is not None else dataset_styles
        for style in wanted + (self.requested_example_styles or []):
            if style not in dataset_styles:
                raise NoClipsError(f"style {style!r} is not in dataset {takeset.name!r} (styles: {dataset_styles})")
        if self._given_segmentation is not None:
            self.segmentation = self._given_segmentation
        else:
            self.segmentation = segment_action(takeset.takes, self.action, self.segment_settings)
        for part, members in takeset.split(**self.split_cfg).items():
            for take in members:
                self.split_of[take.name] = part
        selected = self.segmentation.select(self.action, self.primitives, wanted)
        for part in SPLITS:
            self.clips[part] = [c for c in selected if self.split_of.get(c.take) == part]
        if not self.clips["train"]:
            raise NoClipsError(self._empty_message("train", wanted))
        if self.timeline == "median":
            median = int(round(float(np.median([c.num_frames for c in self.clips["train"]]))))
            self.length = max(2, self.min_length, median)
        else:
            self.length = int(self.timeline)
        for part in SPLITS:
            self.datasets[part] = ClipDataset(self.clips[part], self.length, self.style_names)
        log.info("%s %s clips of %s, %d frames each: %s", self.action, "+".join(self.primitives), takeset.name,
                 self.length, {p: len(self.clips[p]) for p in SPLITS})

    def _empty_message(self, part: str, styles: Sequence[str]) -> str:
        seg = self.segmentation
        counts = Counter((c.primitive, c.style) for c in seg.clips if c.action == self.action)
        have = ", ".join(f"{p}/{s}: {n}" for (p, s), n in sorted(counts.items())) or "none"
        return (f"no {self.action} clip of primitive(s) {self.primitives} and style(s) {list(styles)} in the "
                f"{part!r} split of dataset {self.takeset.name!r} (split settings {self.split_cfg or 'defaults'}). "
                f"Clips per primitive/style in the whole dataset: {have}. Begin/end primitives need takes that "
                "start or stop standing still; run stylemotion-segment for a report.")

    # -- style examples

    def style_example(self, style: str) -> Clip:
        """The one example clip of ``style`` (see the module docstring for how it is picked)."""
        if self.segmentation is None:
            self.setup()
        if style not in self._examples:
            self._examples[style] = self._pick_example(style)
        return self._examples[style]

    def style_examples(self) -> dict[str, Clip]:
        """``{style: clip}`` for every example style (default: every style of the dataset)."""
        if self.segmentation is None:
            self.setup()
        styles = self.requested_example_styles if self.requested_example_styles is not None else self.style_names
        return {s: self.style_example(s) for s in styles}

    def example_frames(self, style: str) -> torch.Tensor:
        """``(length, 66)`` float32 time-normalized frames of :meth:`style_example`."""
        return torch.from_numpy(time_normalize(self.style_example(style).frames, self.length))

    def _pick_example(self, style: str) -> Clip:
        cfg = self.example_cfg
        primitive = self.example_primitive
        content = cfg["content"] or self.action
        candidates = [c for c in self.segmentation.clips
                      if c.action == self.action and c.primitive == primitive and c.style == style
                      and c.content == content
                      and (cfg["split"] == "all" or self.split_of.get(c.take) == cfg["split"])]
        candidates.sort(key=lambda c: (c.take, c.start))
        where = f"{self.action} {primitive} clip of style {style!r} from {content!r} takes" + (
            "" if cfg["split"] == "all" else f" in the {cfg['split']!r} split")
        if not candidates:
            with_clips = sorted({c.style for c in self.segmentation.clips if c.action == self.action
                                 and c.primitive == primitive and c.content == content})
            raise NoClipsError(f"style {style!r} has no example clip: no {where} in dataset "
                               f"{self.takeset.name!r}; styles with such clips: {with_clips}")
        if cfg["pick"] == "first":
            return candidates[0]
        if cfg["pick"] == "index":
            if not 0 <= cfg["index"] < len(candidates):
                raise NoClipsError(f"example index {cfg['index']} is out of range: there are {len(candidates)} "
                                   f"candidate {where}")
            return candidates[cfg["index"]]
        if cfg["pick"] == "take":
            chosen = [c for c in candidates if c.take == cfg["take"]
                      and (cfg["start"] is None or c.start == cfg["start"])]
            if not chosen:
                takes = sorted({c.take for c in candidates})
                raise NoClipsError(f"no {where} in take {cfg['take']!r}"
                                   + ("" if cfg["start"] is None else f" starting at frame {cfg['start']}")
                                   + f"; takes with candidates: {takes[:20]}{' …' if len(takes) > 20 else ''}")
            return chosen[0]
        durations = np.array([c.duration_s for c in candidates])
        return candidates[int(np.argmin(np.abs(durations - np.median(durations))))]

    # -- loaders

    def check_part(self, part: str) -> None:
        if not len(self.datasets[part]):
            raise NoClipsError(self._empty_message(part, self.requested_styles or self.style_names))

