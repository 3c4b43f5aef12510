"""The one loading path of a trained model: a checkpoint → the model its hyperparameters name.

:func:`load_generative` rebuilds a :class:`~stylemotion.models.vae.PrimitiveVAE`,
:class:`~stylemotion.models.cvae.StyleCVAE` or :class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE`
from its checkpoint (read, and its autoencoder resolved, by :mod:`stylemotion.models.checkpoints`, the
checkpoint records, which import no model class). :func:`load_model` wraps a PrimitiveVAE or StyleCVAE in
an :class:`EvalModel`: the primitive it models, the style it targets (:data:`NEUTRAL` for the plain VAE)
and the style examples it was conditioned on, as evaluation, synthesis and new styles use it;
:func:`zero_shot_model` does the same for a ZeroShotStyleVAE bound to one style's example clip(s).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol, runtime_checkable

import lightning.pytorch as pl
import torch

from stylemotion.models.autoencoder import IncompatibleModelError, MotionAutoencoder
from stylemotion.models.checkpoints import GENERATIVE_KINDS, KINDS, checkpoint_kind, read_checkpoint, restore
from stylemotion.models.cvae import StyleCVAE
from stylemotion.models.sampling import MotionSamples
from stylemotion.models.vae import PrimitiveVAE
from stylemotion.models.zero_shot import ZeroShotStyleVAE


def model_class(kind: str) -> type[pl.LightningModule]:
    """The LightningModule class of a checkpoint kind (see :data:`KINDS`)."""
    classes = {"autoencoder": MotionAutoencoder, "vae": PrimitiveVAE, "cvae": StyleCVAE,
               "zero_shot": ZeroShotStyleVAE}
    if kind not in classes:
        raise ValueError(f"unknown checkpoint kind {kind!r}; kinds: {list(KINDS)}")
    return classes[kind]


def load_generative(path: str | os.PathLike, autoencoder: MotionAutoencoder | None = None) -> pl.LightningModule:
    """A trained :class:`~stylemotion.models.vae.PrimitiveVAE`, :class:`~stylemotion.models.cvae.StyleCVAE`
    or :class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE` (class from its hyperparameters), eval mode, CPU.

    ``stylemotion.load(path)`` (:mod:`stylemotion.loading`) reads this and every other model the commands write
    (run folders, Morphable Graph files) behind one ``sample``/``describe``; it loads checkpoints through here.

    Args:
        path: its checkpoint (``~`` expanded).
        autoencoder: an already loaded autoencoder to attach (must be the model's own: same
            weights); None resolves it on first use (see :func:`~stylemotion.models.checkpoints.resolve_autoencoder`).

    Raises:
        FileNotFoundError, IncompatibleModelError: no file, or not a trained primitive model.
    """
    path = Path(path).expanduser()
    checkpoint = read_checkpoint(path, "model checkpoint")
    hparams = checkpoint.get("hyper_parameters") or {}
    kind = checkpoint_kind(hparams)
    if kind not in GENERATIVE_KINDS:
        raise IncompatibleModelError(f"{path} is not a trained PrimitiveVAE/StyleCVAE/ZeroShotStyleVAE checkpoint "
                                     f"(no data spec in its hyperparameters; it has {sorted(hparams)[:12]})")
    model = restore(model_class(kind), checkpoint, str(path))
    model.checkpoint_file = str(path.resolve())
    if autoencoder is not None:
        model.attach_autoencoder(autoencoder)
    return model


#: Row name of the neutral model (the thesis' "neutral"), trained on the neutral style's clips.
NEUTRAL = "neutral"


@runtime_checkable
class SampleSource(Protocol):
    """Anything that draws motions of one primitive."""

    def sample(self, n: int, seed: int | None = None) -> MotionSamples:  # pragma: no cover - protocol
        """``n`` motions (see :class:`stylemotion.models.sampling.MotionSamples`), reproducible for a seed."""
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
        kind: what the model is, named in reports: ``vae``, ``cvae``, ``zero_shot`` (a zero-shot network bound to
            an example, :func:`zero_shot_model`), or None (any other source).
        example_clips: the example clips themselves when they are not clips of the evaluation's data (a user's
            motion file; anything with ``frames`` ``(frames, 66)``, ``positions``, ``duration_s``, ``describe()``);
            None: ``examples`` name clips of the data, found there.
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
    kind: str | None = None
    example_clips: list[Any] | None = None

    @property
    def label(self) -> str:
        return f"{self.primitive}/{self.name}"

    @property
    def unbound(self) -> bool:
        """Whether its source is a zero-shot network still waiting for its example clips (:meth:`bind`)."""
        return isinstance(self.source, ZeroShotStyleVAE)

    def bind(self, clips: Sequence[Any]) -> None:
        """Bind a zero-shot network's source to its example ``clips`` (``frames`` ``(frames, 66)`` each: encoded by
        its autoencoder at the canonical length, as its training examples were); other sources are left as
        they are. ``target_gram`` becomes the clips' mean Gram (:attr:`BoundExample.target_gram`)."""
        if self.unbound:
            self.source = self.source.bind_example(list(clips), self.style, self.examples)
            self.target_gram = self.source.target_gram


#: Row-name prefix of a zero-shot network bound to a style's example (``zero_shot:<style>``).
ZERO_SHOT_PREFIX = "zero_shot:"


def zero_shot_model(network: ZeroShotStyleVAE, style: str, records: Sequence[dict[str, Any]],
                    clips: Sequence[Any] | None = None, user_clips: bool = False) -> EvalModel:
    """A zero-shot network as the evaluation's model of ``style``, row ``zero_shot:<style>``.

    Args:
        network: the network (its autoencoder is the one recorded in its spec).
        style: the data's style its samples should show (its ground truth, its recognition target).
        records: plain-value records of the example clip(s) (``take``, ``start``, ``stop``, …).
        clips: the example clips; given: bound now, else bound by :meth:`EvalModel.bind` once found in the data.
        user_clips: ``clips`` are not clips of the data (a user's recording): the evaluation takes them as they
            are (:attr:`EvalModel.example_clips`) instead of looking ``records`` up in the data.
    """
    model = EvalModel(f"{ZERO_SHOT_PREFIX}{style}", str(network.spec["primitive"]), str(style), network,
                      [dict(r) for r in records], dict(network.spec["autoencoder"]), network.checkpoint_file,
                      int(network.timeline_frames), None, network.spec.get("dataset"), "canonical", "zero_shot",
                      list(clips) if user_clips and clips is not None else None)
    if clips is not None:
        model.bind(clips)
    return model


def load_model(path: str | Path, neutral_style: str = "normal", autoencoder=None,
               zero_shot: bool = False) -> EvalModel:
    """An :class:`EvalModel` from a PrimitiveVAE or StyleCVAE checkpoint (loaded on the CPU, eval mode).

    Args:
        path: the checkpoint.
        neutral_style: data style of the neutral model when its spec names several content styles.
        autoencoder: an already loaded autoencoder to attach (must be the model's own: same weights);
            None takes the one embedded in the checkpoint (or recorded) on first use.
        zero_shot: also take a zero-shot network: returned unbound (``kind`` ``zero_shot``, no style yet), for
            the evaluation to make one :func:`zero_shot_model` per example
            (:func:`stylemotion.evaluation.sources.zero_shot_models`).

    Raises:
        FileNotFoundError, IncompatibleModelError: no file, or not a trained primitive model
        (:func:`load_generative` reads it), or a zero-shot network without ``zero_shot``.
    """
    model = load_generative(path, autoencoder)
    if isinstance(model, ZeroShotStyleVAE):
        if zero_shot:
            return EvalModel("zero_shot", str(model.spec["primitive"]), "", model,
                             autoencoder=dict(model.spec["autoencoder"]), checkpoint=str(path),
                             timeline_frames=int(model.timeline_frames), dataset=model.spec.get("dataset"),
                             kind="zero_shot")
        raise IncompatibleModelError(f"{path} is a zero-shot style network: it samples only given a style example "
                                     "(in Python: stylemotion.load(path).sample(n, example='walk.bvh'); "
                                     "model.bind_example(...); stylemotion-eval binds it to the styles' examples; "
                                     "its leave-one-style-out evaluation: python scripts/benchmarks.py run zero_shot)")
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
                     # a centred, summed or pose-only style term keeps another matrix than the Gram that Table 5.1
                     # recomputes
                     target_gram=(model.style_gram.detach().clone() if styled and model.plain_gram else None),
                     dataset=spec.get("dataset"), example_length=spec.get("example_length") or "canonical",
                     kind="cvae" if styled else "vae")
