"""Autoencoder features of motion primitive clips, as a Lightning DataModule (thesis §5.3, §5.4.1).

The clips of one primitive (``walk_leftStance``, …) come from
:class:`stylemotion.datamodules.clips.ClipDataModule`, time-normalized to the primitive's canonical length
``L`` frames; the trained, frozen :class:`~stylemotion.models.autoencoder.MotionAutoencoder` encodes
them once, at :meth:`FeatureDataModule.setup`, into features ``Y`` of shape ``(channels, steps)``
(256 × ceil(L/2)). Each clip's real duration travels with it, so the models learn (and sample)
durations along with the motion.

Items are dicts:

* ``features``: ``(channels, steps)`` float32 raw features (the model normalizes them);
* ``duration_s``: the clip's real duration, seconds;
* ``positions``: ``(frames, 21, 3)`` float32 the clip as recorded (metres, from the origin facing
  +Z, at the data's fps), padded to the split's longest clip by holding the last pose;
* ``num_frames``: valid frames of ``positions``.

The feature normalization statistics (each channel's mean over the train split's clips and time
steps, and one common scale for all channels — or per-channel scales with ``feature_scale:
channel``; none with ``feature_scale: none``, the thesis' raw features, preset ``experiment=style_cvae_thesis``)
and the log-duration statistics are computed here and copied into the model's buffers,
so they travel in the model's checkpoint. The common scale keeps the channels' relative sizes, as
the thesis' unnormalized features do: per-channel z-scores make a channel that neutral walking
barely uses, but a style does, very expensive to change, so the style term can hardly move it.
The autoencoder is identified by its path and a fingerprint of its weights
(:func:`stylemotion.models.checkpoints.autoencoder_info`), stored in the model's hyperparameters
as plain values (the model's checkpoint also embeds the autoencoder itself).

Style examples (for :class:`~stylemotion.models.cvae.StyleCVAE`): with ``style`` set, one clip per
entry of ``examples`` (each entry is a :class:`~stylemotion.datamodules.clips.ClipDataModule` ``example``
spec: ``pick``, ``primitive``, ``content``, …; default one median clip of the same primitive from
straight walking/running) is encoded either resampled to the canonical length (``example_length:
canonical``, like the content clips) or as recorded (``natural``, e.g. for examples of several
steps). The frames an example is encoded at must be at least as many as the autoencoder's
receptive field (:func:`receptive_field`).

Examples from outside the dataset (``stylemotion-style``: a user's own BVH file): ``example_clips``
gives the clips themselves (cut with :func:`stylemotion.primitives.actions.segment_action` like the
dataset's, at the data's fps) instead of ``examples`` specs; the style then need not be a style of
the dataset. ``example_records`` adds plain values to each clip's record in the model's
``spec.style_examples`` (e.g. the file, its sha256 and the clip's frames in it).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import torch
from torch.utils.data import Dataset

from stylemotion.datamodules.base import SplitDataModule
from stylemotion.datamodules.clips import ClipDataModule, NoClipsError
from stylemotion.datasets import TakeSet
from stylemotion.io.errors import UserInputError
from stylemotion.models.autoencoder import MotionAutoencoder
from stylemotion.models.checkpoints import autoencoder_info, load_autoencoder
from stylemotion.models.sampling import pad_motions
from stylemotion.primitives.segmentation import Clip, parse_primitive, time_normalize
from stylemotion.representation import FRAME_DIM, REPRESENTATION
from stylemotion.skeleton import CANONICAL_JOINTS, NUM_JOINTS

log = logging.getLogger(__name__)

SPLITS = ("train", "val", "test")
EXAMPLE_LENGTHS = ("canonical", "natural")
FEATURE_SCALES = ("global", "channel", "none")
#: Default minimum of training clips of a primitive: fewer and a 2,000-dimensional VAE just
#: memorizes them (the thesis trains on hundreds of neutral clips per primitive).
MIN_TRAIN_CLIPS = 32


class TooFewClipsError(UserInputError, ValueError):
    """A primitive has too few clips in a split to train or validate a model."""


class ReceptiveFieldError(UserInputError, ValueError):
    """A style example (or the canonical length of the content clips) is shorter than the
    autoencoder's receptive field."""


def receptive_field(autoencoder: MotionAutoencoder) -> int:
    """Fewest frames a clip needs so that at least one hidden unit sees no zero padding: the
    encoder's kernel width (15 frames in the thesis)."""
    return int(autoencoder.hparams["kernel_size"])


@torch.no_grad()
def encode_frames(autoencoder: MotionAutoencoder, frames: torch.Tensor | np.ndarray,
                  chunk_size: int = 1024) -> torch.Tensor:
    """Raw frames ``(n, T, 66)`` → features ``(n, channels, ceil(T/2))`` float32, in chunks."""
    frames = torch.as_tensor(np.asarray(frames) if isinstance(frames, np.ndarray) else frames, dtype=torch.float32)
    if frames.shape[0] == 0:
        return torch.zeros(0, int(autoencoder.hparams["hidden_units"]), (frames.shape[1] + 1) // 2)
    return torch.cat([autoencoder.encode(frames[i:i + chunk_size]) for i in range(0, len(frames), chunk_size)])


def encode_examples(autoencoder: MotionAutoencoder, clips: Sequence[Clip], length: int | None) -> list[torch.Tensor]:
    """Features ``(channels, steps_i)`` of style example clips.

    Args:
        autoencoder: the frozen autoencoder.
        clips: example clips (any primitive and length).
        length: resample every clip to this many frames first; None encodes them as recorded.

    Raises:
        ReceptiveFieldError: a clip, as encoded, is shorter than :func:`receptive_field`.
    """
    need = receptive_field(autoencoder)
    out = []
    for clip in clips:
        frames = clip.frames if length is None else time_normalize(clip.frames, length)
        if len(frames) < need:
            raise ReceptiveFieldError(
                f"style example {clip.describe()} has {clip.num_frames} frames"
                + ("" if length is None else f" (resampled to {len(frames)})")
                + f", fewer than the autoencoder's receptive field of {need} frames (its kernel width): its "
                "Gram matrix would mostly measure zero padding. Pick a longer example (datamodule.examples="
                "[{pick: take, take: ..., start: ...}] or another primitive), add examples, encode it at the "
                "canonical length (datamodule.example_length=canonical), or use an autoencoder with a "
                "narrower kernel")
        out.append(encode_frames(autoencoder, frames[None])[0])
    return out


def describe_clip(clip: Clip) -> dict[str, Any]:
    """Plain-value record of a clip (saved in checkpoints to say which example a model used)."""
    return {"take": clip.take, "start": int(clip.start), "stop": int(clip.stop), "action": clip.action,
            "primitive": clip.primitive, "style": clip.style, "content": clip.content,
            "frames": int(clip.num_frames), "duration_s": float(clip.duration_s)}


class FeatureDataset(Dataset):
    """Encoded clips in memory.

    Attributes:
        features: ``(clips, channels, steps)`` float32 raw features.
        duration_s: ``(clips,)`` float32 durations, seconds.
        positions: ``(clips, frames, 21, 3)`` float32 recorded positions, padded (see module doc).
        num_frames: ``(clips,)`` int64 valid frames.
        clips: the source clips.
    """

    def __init__(self, clips: Sequence[Clip], features: torch.Tensor, channels: int, steps: int):
        self.clips = list(clips)
        self.features = features
        self.duration_s = torch.tensor([c.duration_s for c in self.clips], dtype=torch.float32)
        if self.clips:
            self.positions, self.num_frames = pad_motions([c.positions for c in self.clips])
        else:
            self.positions, self.num_frames = torch.zeros(0, 2, NUM_JOINTS, 3), torch.zeros(0, dtype=torch.int64)
        assert features.shape[1:] == (channels, steps) or not self.clips

    def __len__(self) -> int:
        return len(self.clips)

    def __getitem__(self, index: int) -> dict[str, torch.Tensor]:
        return {"features": self.features[index], "duration_s": self.duration_s[index],
                "positions": self.positions[index], "num_frames": self.num_frames[index]}


def _check_example_clips(clips: Sequence[Clip], records: Sequence[Mapping[str, Any]] | None, style: str | None,
                         examples: Sequence[Mapping[str, Any]] | None) -> None:
    """ValueError unless external example clips come with a style, without specs, one record per clip."""
    if not style:
        raise ValueError("example_clips are a style's examples: set style=<its name> as well")
    if examples:
        raise ValueError("give either examples (specs of the dataset's clips) or example_clips (clips from "
                         "elsewhere), not both")
    if not clips:
        raise ValueError(f"example_clips of style {style!r} is empty: give at least one clip")
    if records is not None and len(records) != len(clips):
        raise ValueError(f"example_records has {len(records)} entries for {len(clips)} example clips; give one "
                         "per clip")


def _clip_module(**kwargs: Any) -> ClipDataModule:
    """A ClipDataModule built outside any ``__init__`` (Lightning's ``save_hyperparameters`` would
    otherwise also record the calling constructor's arguments, the autoencoder among them)."""
    return ClipDataModule(**kwargs)


class FeatureDataModule(SplitDataModule):
    """Autoencoder features of one primitive's clips, plus the style example(s) of one style.

    Args:
        data: a ``data`` config node as a plain mapping (see ``configs/data/``); ignored with ``takeset``.
        takeset: an already built :class:`TakeSet` (Python use).
        primitive: ``<action>_<primitive>``, e.g. ``walk_leftStance``.
        autoencoder_ckpt: path of the trained :class:`MotionAutoencoder` checkpoint.
        autoencoder: an already loaded autoencoder (Python use; takes precedence over the path).
        content_styles: styles of the content (training) clips: the neutral database, ``[normal]``.
        style: the style whose example(s) condition a :class:`StyleCVAE`; None for a plain VAE.
        examples: example specs (see the module doc); None = one default example.
        example_clips: the style's example clips themselves, from outside the dataset (Python use; see
            the module doc); instead of ``examples``.
        example_records: one mapping of plain values per clip of ``example_clips``, recorded with it.
        example_length: ``canonical`` or ``natural`` (see the module doc).
        timeline: canonical length, ``median`` (at least the autoencoder's receptive field) or frames (see
            :class:`ClipDataModule`).
        segment: segmentation overrides (see :class:`ClipDataModule`).
        batch_size, eval_batch_size, num_workers: DataLoader settings.
        min_train_clips: fewest training clips accepted (validation needs at least one clip).
        feature_scale: ``global`` (every channel centred on its mean and divided by one common
            scale, the root mean channel variance: the features keep their relative sizes, as the
            thesis' unnormalized features), ``channel`` (z-scores per channel; see the module doc) or ``none``
            (mean 0, scale 1: the raw features, as the thesis' VAE models ``Y = Φ(X)``).
        std_floor: smallest feature scale.
        split: split settings; None = ``data.split``.
    """

    def __init__(
        self,
        data: Mapping[str, Any] | None = None,
        takeset: TakeSet | None = None,
        primitive: str = "walk_leftStance",
        autoencoder_ckpt: str | None = None,
        autoencoder: MotionAutoencoder | None = None,
        content_styles: Sequence[str] = ("normal",),
        style: str | None = None,
        examples: Sequence[Mapping[str, Any]] | None = None,
        example_clips: Sequence[Clip] | None = None,
        example_records: Sequence[Mapping[str, Any]] | None = None,
        example_length: str = "canonical",
        timeline: str | int = "median",
        segment: Mapping[str, Any] | None = None,
        batch_size: int = 64,
        eval_batch_size: int | None = None,
        num_workers: int = 0,
        min_train_clips: int = MIN_TRAIN_CLIPS,
        feature_scale: str = "global",
        std_floor: float = 1e-3,
        split: Mapping[str, Any] | None = None,
    ):
        super().__init__(data, takeset, batch_size, eval_batch_size, num_workers, split)
        self.action, self.primitive_name = parse_primitive(primitive)
        if autoencoder is None and not autoencoder_ckpt:
            raise ValueError("FeatureDataModule needs autoencoder_ckpt=<path of a trained MotionAutoencoder "
                             "checkpoint> (or an autoencoder object)")
        if example_length not in EXAMPLE_LENGTHS:
            raise ValueError(f"example_length must be one of {EXAMPLE_LENGTHS}, got {example_length!r}")
        if feature_scale not in FEATURE_SCALES:
            raise ValueError(f"feature_scale must be one of {FEATURE_SCALES}, got {feature_scale!r}")
        if min_train_clips < 1 or batch_size < 1:
            raise ValueError(f"need min_train_clips ≥ 1 and batch_size ≥ 1, got {min_train_clips}, {batch_size}")
        if example_clips is not None:
            _check_example_clips(example_clips, example_records, style, examples)
        self.save_hyperparameters(ignore=["takeset", "autoencoder", "example_clips"])
        self.primitive = primitive
        self.autoencoder_ckpt = autoencoder_ckpt
        self._autoencoder = autoencoder
        self.content_styles = [content_styles] if isinstance(content_styles, str) else list(content_styles)
        self.style = style
        self.example_specs = [dict(e) for e in examples] if examples else [{}]
        self.example_clips = None if example_clips is None else list(example_clips)
        self.example_records = [dict(r) for r in example_records or [{}] * len(self.example_clips or [])]
        self.example_length = example_length
        self.min_train_clips = min_train_clips
        self.feature_scale = feature_scale
        self.std_floor = std_floor
        self.clip_data = _clip_module(
            data=data, takeset=takeset, action=self.action, primitives=[self.primitive_name],
            styles=self.content_styles, timeline=timeline, example=self.example_specs[0],
            example_styles=[style] if style and self.example_clips is None else [], segment=segment, split=split,
            batch_size=batch_size)
        self.datasets: dict[str, FeatureDataset] = {}
        self.feature_mean: torch.Tensor | None = None
        self.feature_std: torch.Tensor | None = None
        self.duration_stats: torch.Tensor | None = None
        self.style_features: list[torch.Tensor] = []
        self.style_examples: list[dict[str, Any]] = []
        self.summary: dict[str, Any] = {}

    # -- the autoencoder

    @property
    def autoencoder(self) -> MotionAutoencoder:
        """The frozen autoencoder (loaded from ``autoencoder_ckpt`` on first use)."""
        if self._autoencoder is None:
            self._autoencoder = load_autoencoder(self.autoencoder_ckpt)
        return self._autoencoder

    @property
    def autoencoder_info(self) -> dict[str, Any]:
        return autoencoder_info(self.autoencoder, self.autoencoder_ckpt)

    @property
    def takeset(self) -> TakeSet:
        return self.clip_data.takeset

    @property
    def fps(self) -> float:
        return self.clip_data.fps

    @property
    def timeline_frames(self) -> int:
        if self.clip_data.length is None:
            raise RuntimeError("call setup() first")
        return int(self.clip_data.length)

    # -- building

    def prepare_data(self) -> None:
        self.clip_data.prepare_data()

    def setup(self, stage: str | None = None) -> None:
        if self.datasets:
            return
        ae = self.autoencoder
        ae.check_compatible(fps=self.fps, frame_dim=FRAME_DIM, representation=REPRESENTATION,
                            joint_names=CANONICAL_JOINTS)
        self.clip_data.min_length = receptive_field(ae)  # a "median" timeline shorter than the kernel is stretched
        self.clip_data.setup()
        clips = self.clip_data.clips
        counts = {part: len(clips[part]) for part in SPLITS}
        if counts["train"] < self.min_train_clips or counts["val"] < 1:
            raise TooFewClipsError(
                f"primitive {self.primitive} has {counts['train']} training and {counts['val']} validation clips of "
                f"style(s) {self.content_styles} in dataset {self.clip_data.takeset.name!r}; training needs at "
                f"least {self.min_train_clips} training clips (datamodule.min_train_clips) and 1 validation clip. "
                "Use more takes of this action, other content styles, or other split fractions")
        length = self.timeline_frames
        if length < receptive_field(ae):
            raise ReceptiveFieldError(
                f"the canonical length of {self.primitive} is {length} frames, shorter than the autoencoder's "
                f"receptive field of {receptive_field(ae)} frames; set datamodule.timeline to at least that")
        channels, steps = int(ae.hparams["hidden_units"]), (length + 1) // 2
        for part in SPLITS:
            source = self.clip_data.datasets[part]
            self.datasets[part] = FeatureDataset(clips[part], encode_frames(ae, source.frames), channels, steps)
        train = self.datasets["train"]
        flat = train.features.transpose(1, 2).reshape(-1, channels).double()
        if self.feature_scale == "none":  # the raw features: no centre, no scale
            self.feature_mean, self.feature_std = torch.zeros(channels), torch.ones(channels)
        else:
            self.feature_mean = flat.mean(0).float()
            std = flat.std(0, unbiased=False)
            if self.feature_scale == "global":  # one scale for every channel: the root mean variance
                std = torch.full_like(std, float(std.square().mean().sqrt()))
            self.feature_std = std.clamp_min(self.std_floor).float()
        logs = train.duration_s.double().log()
        self.duration_stats = torch.tensor([logs.mean(), logs.std(unbiased=False).clamp_min(1e-3),
                                            train.duration_s.min(), train.duration_s.max()], dtype=torch.float32)
        if self.style:
            self._encode_style_examples()
        self.summary = {"primitive": self.primitive, "content_styles": self.content_styles, "clips": counts,
                        "timeline_frames": length, "features": [channels, steps], "style": self.style,
                        "style_examples": self.style_examples}
        log.info("%s features %s×%s of %s clips: %s", self.primitive, channels, steps, self.content_styles, counts)

    def _encode_style_examples(self) -> None:
        if self.example_clips is not None:
            self._encode_clips(self.example_clips, self.example_records)
            return
        clips = []
        for i, spec in enumerate(self.example_specs):
            source = self.clip_data if i == 0 else _clip_module(
                takeset=self.clip_data.takeset, action=self.action, primitives=[self.primitive_name],
                styles=self.content_styles, timeline=self.timeline_frames, example=spec,
                example_styles=[self.style], segment=self.hparams.segment, split=self.clip_data.split_cfg)
            try:
                clips.append(source.style_example(self.style))
            except NoClipsError as err:
                raise NoClipsError(f"style model {self.primitive}/{self.style} needs an example clip (spec "
                                   f"{spec or 'default'}): {err}") from err
        self._encode_clips(clips, [{}] * len(clips))

    def _encode_clips(self, clips: Sequence[Clip], records: Sequence[Mapping[str, Any]]) -> None:
        """Encode the example ``clips`` and record each (with its extra ``records`` values)."""
        for clip in clips:
            if abs(clip.fps - self.fps) > 1e-6 * self.fps:
                raise ValueError(f"style example {clip.describe()} is at {clip.fps:g} fps, the data at {self.fps:g} "
                                 "fps: convert it to the data's frame rate first")
        length = self.timeline_frames if self.example_length == "canonical" else None
        self.style_features = encode_examples(self.autoencoder, clips, length)
        self.style_examples = [{**describe_clip(c), "encoded_frames": int(length or c.num_frames), **dict(r)}
                               for c, r in zip(clips, records)]

    def model_spec(self) -> dict[str, Any]:
        """Plain values a model records about its data (after :meth:`setup`)."""
        if not self.datasets:
            raise RuntimeError("call setup() first")
        return {"primitive": self.primitive, "action": self.action, "feature_channels": int(self.feature_mean.numel()),
                "feature_steps": int(self.datasets["train"].features.shape[-1]),
                "timeline_frames": self.timeline_frames, "fps": float(self.fps),
                "autoencoder": self.autoencoder_info, "dataset": self.clip_data.takeset.name,
                "content_styles": list(self.content_styles),
                "clips": {p: len(self.datasets[p]) for p in SPLITS}, "style": self.style,
                "style_examples": [dict(e) for e in self.style_examples],
                "example_length": self.example_length if self.style else None}

    # -- loaders

    def check_part(self, part: str) -> None:
        if not len(self.datasets[part]):
            raise TooFewClipsError(f"the {part!r} split of primitive {self.primitive} holds no clip of style(s) "
                                   f"{self.content_styles}")
