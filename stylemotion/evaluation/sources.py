"""What the evaluation evaluates: anything that samples motions of a primitive, plus what it targets.

A :class:`SampleSource` has ``sample(n, seed) -> MotionSamples`` (:mod:`stylemotion.sampling`):
the trained :class:`~stylemotion.models.vae.PrimitiveVAE` and
:class:`~stylemotion.models.cvae.StyleCVAE` are sources, and so is :class:`RealClipSource`
(real clips drawn with replacement: an "oracle model" for tests and reference rows).
:class:`EvalModel` wraps a source with the primitive it models, the style it targets and the style
example it was conditioned on; :func:`load_model` makes one from a checkpoint.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import numpy as np
import torch

from stylemotion.io.errors import UserInputError
from stylemotion.models.autoencoder import IncompatibleModelError
from stylemotion.models.checkpoints import load_generative
from stylemotion.models.cvae import StyleCVAE
from stylemotion.models.zero_shot import ZeroShotStyleVAE
from stylemotion.primitives import Clip, time_normalize
from stylemotion.sampling import MotionSamples, pad_motions

#: Row name of the neutral model (the thesis' "neutral"), trained on the neutral style's clips.
NEUTRAL = "neutral"


class MixedAutoencodersError(IncompatibleModelError):
    """Models of one evaluation were trained on features of different autoencoders."""


class MissingExampleError(UserInputError, ValueError):
    """A style model's example clip cannot be found (or does not match) in the evaluation data."""


@runtime_checkable
class SampleSource(Protocol):
    """Anything that draws motions of one primitive."""

    def sample(self, n: int, seed: int | None = None) -> MotionSamples:  # pragma: no cover - protocol
        """``n`` motions (see :class:`stylemotion.sampling.MotionSamples`), reproducible for a seed."""
        ...


@dataclass
class EvalModel:
    """A generative model under evaluation.

    Attributes:
        name: its row in the tables: ``neutral`` for the plain VAE, else its style.
        primitive: ``<action>_<primitive>``, e.g. ``walk_leftStance``.
        style: the data's style label it should produce (the neutral style for ``neutral``).
        source: draws its samples.
        examples: the style example clips it was conditioned on (records with ``take``, ``start``,
            ``stop``, ``encoded_frames``, … as saved by :mod:`stylemotion.datamodules.features`); empty for
            the neutral model.
        autoencoder: the autoencoder it was trained on (``path``, ``fingerprint``, …), or None.
        checkpoint: its checkpoint path, or None.
        timeline_frames: the primitive's canonical length, frames.
        target_gram: ``(C, C)`` the model's own record of ``Gram(Φ(example))``, or None.
        dataset: name of the dataset it was trained on, or None.
        example_length: how its examples were encoded: ``canonical`` (resampled to the timeline,
            the default) or ``natural`` (as recorded).
    """

    name: str
    primitive: str
    style: str
    source: SampleSource
    examples: list[dict[str, Any]] = field(default_factory=list)
    autoencoder: dict[str, Any] | None = None
    checkpoint: str | None = None
    timeline_frames: int | None = None
    target_gram: torch.Tensor | None = None
    dataset: str | None = None
    example_length: str | None = "canonical"

    @property
    def label(self) -> str:
        return f"{self.primitive}/{self.name}"


def load_model(path: str | Path, neutral_style: str = "normal", autoencoder=None) -> EvalModel:
    """An :class:`EvalModel` from a PrimitiveVAE or StyleCVAE checkpoint (loaded on the CPU, eval mode).

    Args:
        path: the checkpoint.
        neutral_style: data style of the neutral model when its spec names several content styles.
        autoencoder: an already loaded autoencoder to attach (must be the model's own: same weights);
            None takes the one embedded in the checkpoint (or recorded) on first use.

    Raises:
        FileNotFoundError, IncompatibleModelError: no file, or not a trained primitive model
        (:func:`stylemotion.models.checkpoints.load_generative` reads it).
    """
    model = load_generative(path, autoencoder)
    if isinstance(model, ZeroShotStyleVAE):
        raise IncompatibleModelError(f"{path} is a zero-shot style network: it samples only given a style example "
                                     "(bind one with model.bind_example(...), or evaluate it with "
                                     "scripts/zero_shot_loso.py)")
    spec = model.spec
    styled = isinstance(model, StyleCVAE)
    if styled:
        name = style = str(spec["style"])
    else:
        contents = list(spec.get("content_styles") or [neutral_style])
        name, style = NEUTRAL, contents[0] if len(contents) == 1 else neutral_style
    return EvalModel(name=name, primitive=str(spec["primitive"]), style=style, source=model,
                     examples=[dict(e) for e in spec.get("style_examples") or []] if styled else [],
                     autoencoder=dict(spec["autoencoder"]), checkpoint=str(path),
                     timeline_frames=int(spec["timeline_frames"]),
                     # a centred style term keeps a covariance, not the thesis' Gram that Table 5.1 recomputes
                     target_gram=(model.style_gram.detach().clone()
                                  if styled and not model.hparams.get("style_centred", False) else None),
                     dataset=spec.get("dataset"), example_length=spec.get("example_length") or "canonical")


def check_one_autoencoder(models: Sequence[EvalModel], fingerprint: str | None = None) -> str | None:
    """The one autoencoder fingerprint all models share (and ``fingerprint`` if given).

    Raises:
        MixedAutoencodersError: naming each autoencoder and the checkpoints trained on it.
    """
    groups: dict[str, list[str]] = defaultdict(list)
    paths: dict[str, str] = {}
    for m in models:
        if m.autoencoder is None:
            continue
        fp = str(m.autoencoder.get("fingerprint"))
        groups[fp].append(m.checkpoint or m.label)
        paths[fp] = str(m.autoencoder.get("path"))
    if fingerprint is not None and groups and set(groups) != {fingerprint}:
        others = {fp: v for fp, v in groups.items() if fp != fingerprint}
        raise MixedAutoencodersError(
            f"the evaluation's autoencoder has weights {fingerprint}, but these models were trained on features of "
            "another autoencoder: " + "; ".join(f"weights {fp} ({paths[fp]}): {v}" for fp, v in others.items())
            + ". Evaluate them with their own autoencoder_ckpt, in a separate evaluation")
    if len(groups) > 1:
        raise MixedAutoencodersError(
            "the models were trained on features of different autoencoders and cannot share one evaluation "
            "(Table 5.1 re-encodes every sample with one autoencoder): "
            + "; ".join(f"weights {fp} ({paths[fp]}): {v}" for fp, v in groups.items())
            + ". Evaluate each group separately")
    return fingerprint if fingerprint is not None else next(iter(groups), None)


def motions_from_clips(clips: Sequence[Clip], length: int) -> MotionSamples:
    """Real clips as :class:`MotionSamples`: recorded positions and frames (padded by holding the last
    frame), real durations, and frames resampled to the canonical ``length`` (``normalized_frames``).
    ``features`` is empty ``(n, 0, 0)`` (real clips have no sampled features)."""
    if not clips:
        raise ValueError("no clip")
    positions, num_frames = pad_motions([c.positions for c in clips])
    frames, _ = pad_motions([c.frames for c in clips])
    normalized = torch.from_numpy(np.stack([time_normalize(c.frames, length) for c in clips]))
    duration = torch.tensor([c.duration_s for c in clips], dtype=torch.float32)
    return MotionSamples(positions, frames, num_frames, duration, torch.zeros(len(clips), 0, 0), normalized,
                         float(clips[0].fps))


class RealClipSource:
    """Real clips drawn uniformly with replacement, as a :class:`SampleSource` (an oracle model).

    Args:
        clips: the clips to draw from.
        length: the canonical timeline, frames.
    """

    def __init__(self, clips: Sequence[Clip], length: int):
        self.motions = motions_from_clips(clips, length)

    def sample(self, n: int, seed: int | None = None) -> MotionSamples:
        if n < 1:
            raise ValueError(f"n must be ≥ 1, got {n}")
        index = torch.from_numpy(np.random.default_rng(seed).integers(0, len(self.motions), n))
        return self.motions.subset(index)
