"""Clips of several styles, each paired with another clip of its style as its example (for
:class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE`).

Built on :class:`~stylemotion.datamodules.features.FeatureDataModule` by composition: one
FeatureDataModule of the primitive whose content styles are the served styles (``styles``, default every
style of the data, minus ``exclude_styles``) encodes the clips and computes the feature and duration
statistics exactly as for a :class:`~stylemotion.models.vae.PrimitiveVAE` (over the served styles' train
clips). An excluded style has no clip in any split (leave-one-style-out training).

Canonical timeline (``timeline``): ``neutral`` (default) = the median length of the neutral style's
train clips, the timeline of the neutral VAE and of every per-style StyleCVAE of the same data, so all
of them and this model share one (the evaluation compares motions on it); ``median`` = the median over
the served styles' train clips; or a number of frames.

Items: those of :class:`~stylemotion.datamodules.features.FeatureDataset` (``features``, ``duration_s``,
``positions``, ``num_frames``) plus

* ``style``: int64 index into :attr:`MultiStyleDataModule.style_names` (the data's styles);
* ``example_features``: ``(C, T')`` raw features of the item's example, another train-split clip of
  the same style: drawn afresh each time a train item is read (the global torch RNG, seeded by
  Lightning's ``seed_everything``), drawn once (``pair_seed``) for val/test items; a style with a single
  train clip pairs it with itself;
* ``example_index``: that clip's index in the train split.

Style examples of every style of the data, served or excluded (:meth:`MultiStyleDataModule.example_clip`):
the clip a StyleCVAE of that style is conditioned on by default: ``ClipDataModule.style_example`` with the
same ``example`` spec, segmentation and split as :class:`FeatureDataModule` uses, encoded at the
canonical length (:meth:`MultiStyleDataModule.example_features`).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from typing import Any

import torch
from torch.utils.data import Dataset

from stylemotion.datamodules.base import SplitDataModule
from stylemotion.datamodules.clips import ClipDataModule, NoClipsError
from stylemotion.datamodules.features import (
    MIN_TRAIN_CLIPS,
    SPLITS,
    FeatureDataModule,
    FeatureDataset,
    TooFewClipsError,
    describe_clip,
    encode_examples,
)
from stylemotion.datasets import TakeSet
from stylemotion.models.autoencoder import MotionAutoencoder
from stylemotion.models.checkpoints import load_autoencoder
from stylemotion.primitives.segmentation import Clip, parse_primitive

log = logging.getLogger(__name__)

#: Named canonical timelines (besides a number of frames).
TIMELINES = ("neutral", "median")


class PairedFeatureDataset(Dataset):
    """The encoded clips of one split, each with an example clip of its style from the train split.

    Args:
        base: the split's clips (features, durations, positions).
        style: ``(n,)`` int64 style index of each clip.
        pool: the train split's clips (where examples come from); ``base`` itself for the train split.
        pool_style: ``(m,)`` int64 style index of each pool clip.
        fixed_seed: None draws a new example at every read (train); a seed draws each item's example once.

    Raises:
        TooFewClipsError: a style of ``base`` has no clip in ``pool``.
    """

    def __init__(self, base: FeatureDataset, style: torch.Tensor, pool: FeatureDataset, pool_style: torch.Tensor,
                 fixed_seed: int | None = None):
        self.base, self.style, self.pool, self.pool_style = base, style, pool, pool_style
        self.same_pool = pool is base
        self.members = {int(s): torch.nonzero(pool_style == s).squeeze(1) for s in torch.unique(style)}
        empty = [s for s, m in self.members.items() if len(m) == 0]
        if empty:
            raise TooFewClipsError(f"style index(es) {empty} have clips but no train-split clip to take examples from")
        self.partners: torch.Tensor | None = None
        if fixed_seed is not None:
            generator = torch.Generator().manual_seed(int(fixed_seed))
            self.partners = torch.tensor([self._draw(i, generator) for i in range(len(base))], dtype=torch.int64)

    @property
    def features(self) -> torch.Tensor:
        """``(n, C, T')`` the split's raw features."""
        return self.base.features

    @property
    def clips(self) -> list[Clip]:
        return self.base.clips

    def _draw(self, index: int, generator: torch.Generator | None = None) -> int:
        """A pool index of the same style as item ``index`` (not the item itself when the pool is its split)."""
        members = self.members[int(self.style[index])]
        if self.same_pool and len(members) > 1:
            j = int(torch.randint(len(members) - 1, (), generator=generator))
            return int(members[j + int(j >= int(torch.searchsorted(members, index)))])
        return int(members[int(torch.randint(len(members), (), generator=generator))])

    def __len__(self) -> int:
        return len(self.base)

    def __getitem__(self, index: int) -> dict[str, torch.Tensor]:
        partner = self._draw(index) if self.partners is None else int(self.partners[index])
        return {**self.base[index], "style": self.style[index], "example_features": self.pool.features[partner],
                "example_index": torch.tensor(partner, dtype=torch.int64)}


def _feature_module(**kwargs: Any) -> FeatureDataModule:
    """A FeatureDataModule built outside any ``__init__`` (see ``features._clip_module``)."""
    return FeatureDataModule(**kwargs)


def _clip_module(**kwargs: Any) -> ClipDataModule:
    return ClipDataModule(**kwargs)


class MultiStyleDataModule(SplitDataModule):
    """Autoencoder features of one primitive's clips of several styles, with example pairs (see the module doc).

    Args:
        data: a ``data`` config node as a plain mapping; ignored with ``takeset``.
        takeset: an already built :class:`TakeSet` (Python use).
        primitive: ``<action>_<primitive>``, e.g. ``walk_leftStance``.
        autoencoder_ckpt: path of the trained :class:`MotionAutoencoder` checkpoint.
        autoencoder: an already loaded autoencoder (Python use; takes precedence over the path).
        styles: styles to serve; None = every style of the data.
        exclude_styles: styles left out of every split (e.g. the one style a leave-one-out model never sees).
        neutral_style: the data's neutral style (its clips set the ``neutral`` timeline).
        example: how each style's example clip is picked (a ClipDataModule ``example`` spec; None = the
            default, as a StyleCVAE's).
        timeline: ``neutral``, ``median`` or frames (see the module doc).
        segment: segmentation overrides (see :class:`ClipDataModule`).
        batch_size, eval_batch_size, num_workers: DataLoader settings.
        min_train_clips: fewest training clips accepted (all served styles together).
        feature_scale, std_floor: feature normalization (see :class:`FeatureDataModule`).
        split: split settings; None = ``data.split``.
        pair_seed: draws the val/test items' examples.
    """

    def __init__(
        self,
        data: Mapping[str, Any] | None = None,
        takeset: TakeSet | None = None,
        primitive: str = "walk_leftStance",
        autoencoder_ckpt: str | None = None,
        autoencoder: MotionAutoencoder | None = None,
        styles: Sequence[str] | None = None,
        exclude_styles: Sequence[str] = (),
        neutral_style: str = "normal",
        example: Mapping[str, Any] | None = None,
        timeline: str | int = "neutral",
        segment: Mapping[str, Any] | None = None,
        batch_size: int = 64,
        eval_batch_size: int | None = None,
        num_workers: int = 0,
        min_train_clips: int = MIN_TRAIN_CLIPS,
        feature_scale: str = "global",
        std_floor: float = 1e-3,
        split: Mapping[str, Any] | None = None,
        pair_seed: int = 0,
    ):
        super().__init__(data, takeset, batch_size, eval_batch_size, num_workers, split)
        self.action, self.primitive_name = parse_primitive(primitive)
        if autoencoder is None and not autoencoder_ckpt:
            raise ValueError("MultiStyleDataModule needs autoencoder_ckpt=<path of a trained MotionAutoencoder "
                             "checkpoint> (or an autoencoder object)")
        if not (timeline in TIMELINES or (isinstance(timeline, int) and not isinstance(timeline, bool)
                                          and timeline >= 2)):
            raise ValueError(f"datamodule.timeline must be one of {TIMELINES} or a number of frames ≥ 2, got "
                             f"{timeline!r}")
        for key, value in (("styles", styles), ("exclude_styles", exclude_styles)):
            if isinstance(value, str):
                raise ValueError(f"datamodule.{key} must be a list of style names, got the string {value!r} "
                                 f"(write [{value}])")
        self.save_hyperparameters(ignore=["takeset", "autoencoder"])
        self.primitive = primitive
        self.autoencoder_ckpt = autoencoder_ckpt
        self._autoencoder = autoencoder
        self.requested_styles = None if styles is None else list(styles)
        self.exclude_styles = list(exclude_styles or [])
        self.neutral_style = neutral_style
        self.example_spec = dict(example or {})
        self.timeline = timeline
        self.segment = dict(segment or {})
        self.min_train_clips = min_train_clips
        self.feature_scale, self.std_floor = feature_scale, std_floor
        self.pair_seed = int(pair_seed)
        self.features: FeatureDataModule | None = None
        self.neutral_clips: ClipDataModule | None = None
        self.style_names: list[str] = []
        self.styles: list[str] = []
        self._example_features: dict[str, torch.Tensor] = {}
        self.summary: dict[str, Any] = {}

    # -- what the model reads

    @property
    def autoencoder(self) -> MotionAutoencoder:
        """The frozen autoencoder (loaded from ``autoencoder_ckpt`` on first use)."""
        if self._autoencoder is None:
            self._autoencoder = load_autoencoder(self.autoencoder_ckpt)
        return self._autoencoder

    def _ready(self) -> FeatureDataModule:
        if self.features is None:
            raise RuntimeError("call setup() first")
        return self.features

    @property
    def timeline_frames(self) -> int:
        return self._ready().timeline_frames

    @property
    def feature_mean(self) -> torch.Tensor:
        return self._ready().feature_mean

    @property
    def feature_std(self) -> torch.Tensor:
        return self._ready().feature_std

    @property
    def duration_stats(self) -> torch.Tensor:
        return self._ready().duration_stats

    # -- building

    def _check_styles(self, data_styles: list[str]) -> list[str]:
        """The served styles; ValueError naming the key for a style the data does not have."""
        for key, names in (("styles", self.requested_styles or []), ("exclude_styles", self.exclude_styles),
                           ("neutral_style", [self.neutral_style])):
            unknown = [s for s in names if s not in data_styles]
            if unknown:
                raise ValueError(f"datamodule.{key}: style(s) {unknown} are not in dataset {self.takeset.name!r} "
                                 f"(styles: {data_styles})")
        served = [s for s in (self.requested_styles or data_styles) if s not in self.exclude_styles]
        if not served:
            raise ValueError(f"no style left to train on: styles {self.requested_styles or data_styles}, "
                             f"datamodule.exclude_styles {self.exclude_styles}")
        return served

    def setup(self, stage: str | None = None) -> None:
        if self.features is not None:
            return
        self.style_names = self.takeset.label_values("style")
        self.styles = self._check_styles(self.style_names)
        common = {"takeset": self.takeset, "segment": self.segment, "split": self.split_cfg}
        # the neutral clips set the timeline; their segmentation finds the style examples as a StyleCVAE's does
        self.neutral_clips = _clip_module(action=self.action, primitives=[self.primitive_name],
                                          styles=[self.neutral_style], example=self.example_spec, example_styles=[],
                                          **common)
        self.neutral_clips.setup()
        length = self.neutral_clips.length if self.timeline == "neutral" else self.timeline
        self.features = _feature_module(
            primitive=self.primitive, autoencoder_ckpt=self.autoencoder_ckpt, autoencoder=self.autoencoder,
            content_styles=self.styles, timeline=length, batch_size=self.batch_size,
            eval_batch_size=self.eval_batch_size, num_workers=self.num_workers, min_train_clips=self.min_train_clips,
            feature_scale=self.feature_scale, std_floor=self.std_floor, **common)
        self.features.setup(stage)
        index = {s: i for i, s in enumerate(self.style_names)}
        labels = {p: torch.tensor([index[c.style] for c in self.features.datasets[p].clips], dtype=torch.int64)
                  for p in SPLITS}
        train = self.features.datasets["train"]
        for part in SPLITS:
            base = self.features.datasets[part]
            self.datasets[part] = PairedFeatureDataset(base, labels[part], train, labels["train"],
                                                       None if part == "train" else self.pair_seed + SPLITS.index(part))
        counts = {p: {s: int((labels[p] == index[s]).sum()) for s in self.styles} for p in SPLITS}
        self.summary = {**self.features.summary, "styles": self.styles, "excluded_styles": self.exclude_styles,
                        "clips_per_style": counts}
        log.info("%s: styles %s (excluded %s), clips per style %s", self.primitive, self.styles, self.exclude_styles,
                 counts)

    # -- style examples

    def example_clip(self, style: str) -> Clip:
        """The example clip of ``style`` (any style of the data), picked as a StyleCVAE's (see the module doc)."""
        self._ready()
        if style not in self.style_names:
            raise ValueError(f"style {style!r} is not in dataset {self.takeset.name!r} (styles: {self.style_names})")
        return self.neutral_clips.style_example(style)

    def example_features(self, style: str) -> torch.Tensor:
        """``(C, T')`` raw features of :meth:`example_clip` at the canonical length."""
        if style not in self._example_features:
            clip = self.example_clip(style)
            self._example_features[style] = encode_examples(self.autoencoder, [clip], self.timeline_frames)[0]
        return self._example_features[style]

    def model_spec(self) -> dict[str, Any]:
        """Plain values a model records about its data (after :meth:`setup`): those of
        :meth:`FeatureDataModule.model_spec` plus the served and excluded styles and each style's example."""
        spec = self._ready().model_spec()
        examples = {}
        for style in self.style_names:
            try:
                examples[style] = {**describe_clip(self.example_clip(style)), "encoded_frames": self.timeline_frames}
            except NoClipsError as err:  # a style without candidates simply records none
                log.info("no example clip of style %s: %s", style, err)
        return {**spec, "styles": list(self.styles), "excluded_styles": list(self.exclude_styles),
                "neutral_style": self.neutral_style, "style_names": list(self.style_names),
                "style_examples_by_style": examples, "example_length": "canonical"}

    # -- loaders

    def check_part(self, part: str) -> None:
        self._ready().check_part(part)
