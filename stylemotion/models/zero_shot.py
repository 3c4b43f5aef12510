"""One network for every style: a VAE conditioned on an embedding of one style example (beyond the thesis).

The thesis trains one :class:`~stylemotion.models.cvae.StyleCVAE` per style (§5.3.3): the neutral clips
plus a Gram term towards that style's example. :class:`ZeroShotStyleVAE` is trained **once** on the
clips of many styles and generates a style from one example clip, also a style it never saw, with no
further training.

Feature space: that of :class:`~stylemotion.models.vae.PrimitiveVAE` (its normalization, duration value,
decoding, checkpoint embedding of the autoencoder are inherited): ``y`` = the frozen autoencoder's
features of a clip on the canonical timeline, normalized, plus its standardized log-duration.

Style embedding ``e`` (``embedding_dim`` values, 32) of an example's raw features ``X`` ``(C, T')``::

    d(X) = [mean_t X, std_t X]           each channel's mean and standard deviation over time (2C values)
    e    = P (d(X) − d̄) / s              P: the leading principal axes (E, 2C) of d over the training
                                          clips, d̄ their mean, s one common scale (root mean variance
                                          of the projections)

``P``, ``d̄`` and ``s`` are fitted once, at the first ``setup``, on the train split (every trained style)
and are buffers. Several example clips: the mean of their embeddings.

Why moments and not the Gram matrix: measured on the synthetic data (``walk_leftStance``, autoencoder
of a ``stylemotion-reproduce`` run), the style of a held-out val/test clip recovered as the nearest of
the 7 styles' single example clips, the embedding fitted without the clip's style: moments → PCA 32:
70 % (clips of the left-out style; 73 % of the others); the full Gram's upper triangle → PCA 32: 59 %
(64 %); the raw Gram distance itself, no embedding: 64 %; a trace-normalized Gram or a log-Gram of 16
principal channels: 70 % but C² values per clip. The moments are as discriminative as the best, cost
2C values per clip and leave a 32 × 512 basis in the checkpoint instead of 32 × 32,896.

Network (:class:`ConditionalMLPVAE`): :class:`~stylemotion.models.vae.MLPVAE` with ``e`` concatenated to
the encoder's and the decoder's input: ``q(z | y, e)``, ``p(y | z, e)``, prior ``N(0, I)``. With ``anchor``
(the default) the example itself, ``a`` = its normalized features (duration value 0), is added to the
decoder's output and taken from the encoder's input: ``y = a + decoder(z, e)``,
``q(z | y − a, e)``: the network models a clip as its example plus a variation of the example's style.

Why the anchor: leaving each style of the synthetic data out in turn (6 styles × 2 stance primitives, 30
epochs, 1,000 samples from the style's one example; an earlier session, with the leaky protocol whose
autoencoder saw the left-out style: a design note, not a figure; suite ``zero_shot`` measures without leakage), the
run's style classifier recognizes 17 % of the embedding-only network's samples as the left-out style (0 %
but for ``exhausted``, which lies between trained styles: the decoder maps an unseen embedding onto the
nearest style it knows; for elderly on walk_leftStance a Gram style term of weight 20 did not change that)
and 99 % of the anchored network's. Conditioned on the examples of styles they were trained on, both give
99–100 %.

Training (:class:`~stylemotion.datamodules.multistyle.MultiStyleDataModule`): each clip ``y_i`` with the
example ``X_i``, **another** clip of its style, so one example has to stand for the style::

    loss = recon + kl_weight · KL + style_weight · mean ‖Gram(decoded) − Gram(X_i)‖_F

plus, with ``contact_weight`` > 0, the foot-contact velocity loss of the reconstructions, as
:class:`~stylemotion.models.vae.PrimitiveVAE`'s (:mod:`stylemotion.models.contact_loss`); the style term
(optional, 0 by default: with the anchor, weight 20 collapses the samples onto the example,
their spread across samples falling from 55 % to 18 % of the real elderly clips';
:func:`stylemotion.models.style.feature_style_distance`, each decoded sequence against its own item's
example) over posterior and/or prior codes (``style_latents``, as :class:`~stylemotion.models.cvae.StyleCVAE`);
logged as ``style`` on val/test whatever its weight.

Sampling: :meth:`ZeroShotStyleVAE.sample` ``(n, seed, example=…)``, or :meth:`ZeroShotStyleVAE.bind_example`,
which returns a :class:`BoundExample` with the ``sample(n, seed)`` of every other model.

Several example clips (e.g. ``stylemotion-style example=[…]``) are pooled by ``pooling`` (default the network's
``sample_pooling``: ``mean`` in the class, ``per_sample`` in ``configs/model/zero_shot.yaml``, chosen on validation
clips by suite ``style_examples_pooling``): ``mean`` conditions every sample on their mean embedding and anchor
(:meth:`ZeroShotStyleVAE.condition`); ``per_sample`` conditions each sample on one clip drawn with the sampling seed
(:meth:`ZeroShotStyleVAE.per_sample_condition`), so the samples spread over the examples instead of sitting at their
centre. One clip samples the same either way.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import torch
from torch import nn

from stylemotion.models.cvae import STYLE_LATENTS
from stylemotion.models.sampling import DEFAULT_CHUNK, MotionSamples, decode_features, masked_mpjpe
from stylemotion.models.style import feature_style_distance, mean_gram
from stylemotion.models.vae import MLPVAE, PrimitiveVAE, kl_divergence, prior_draws, reconstruction_loss
from stylemotion.primitives.segmentation import time_normalize

#: How several example clips condition the samples (see the module doc).
POOLINGS = ("mean", "per_sample")


class ConditionalMLPVAE(MLPVAE):
    """:class:`MLPVAE` whose encoder and decoder also take a condition ``e`` (concatenated to their input).

    Args:
        input_dim: ``D``, values per item.
        condition_dim: ``E``, values of the condition.
        latent_dim, hidden: as :class:`MLPVAE`.
    """

    def __init__(self, input_dim: int, condition_dim: int, latent_dim: int = 32,
                 hidden: Sequence[int] = (512, 256, 128)):
        super().__init__(input_dim, latent_dim, hidden)
        if condition_dim < 1:
            raise ValueError(f"condition_dim must be ≥ 1, got {condition_dim}")
        self.condition_dim = int(condition_dim)
        first, last = self.encoder[0], self.decoder[0]
        self.encoder[0] = nn.Linear(first.in_features + self.condition_dim, first.out_features)
        self.decoder[0] = nn.Linear(last.in_features + self.condition_dim, last.out_features)

    def encode(self, y: torch.Tensor, e: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """``(batch, D)`` items and ``(batch, E)`` (or ``(E,)``) conditions → mean and log-variance ``(batch, k)``."""
        return super().encode(torch.cat([y, e.expand(*y.shape[:-1], self.condition_dim)], -1))

    def decode(self, z: torch.Tensor, e: torch.Tensor) -> torch.Tensor:
        """``(..., k)`` codes and conditions broadcasting to ``(..., E)`` → ``(..., D)``."""
        return super().decode(torch.cat([z, e.expand(*z.shape[:-1], self.condition_dim)], -1))

    def forward(self, y: torch.Tensor, e: torch.Tensor, samples: int = 1,
                generator: torch.Generator | None = None):
        """Returns ``(recon (samples, batch, D), mean (batch, k), logvar (batch, k), z (samples, batch, k))``."""
        mean, logvar = self.encode(y, e)
        z = self.reparameterize(mean, logvar, samples, generator)
        return self.decode(z, e), mean, logvar, z


def style_descriptor(features: torch.Tensor) -> torch.Tensor:
    """``(..., C, T')`` raw features → ``(..., 2C)``: each channel's mean, then its (population)
    standard deviation over time."""
    if features.dim() < 2 or features.shape[-1] < 1:
        raise ValueError(f"features must be (..., channels, time ≥ 1), got shape {tuple(features.shape)}")
    return torch.cat([features.mean(-1), features.std(-1, unbiased=False)], -1)


def fit_style_basis(descriptors: torch.Tensor, dim: int) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The embedding's PCA: mean ``(2C,)``, axes ``(dim, 2C)`` (sign: largest entry positive) and one
    scale ``()`` (root mean variance of the projections), from descriptors ``(n, 2C)``.

    Raises:
        ValueError: ``dim`` exceeds ``n − 1`` or the descriptor size (the message names ``embedding_dim``).
    """
    n, width = descriptors.shape
    if not 1 <= dim <= min(n - 1, width):
        raise ValueError(f"model.embedding_dim={dim} needs at least {dim + 1} training clips and at most {width} "
                         f"descriptor values; the data has {n} training clips")
    x = descriptors.double()
    mean = x.mean(0)
    _, _, vt = torch.linalg.svd(x - mean, full_matrices=False)
    axes = vt[:dim]
    flip = axes.gather(1, axes.abs().argmax(1, keepdim=True)).sign()
    axes = axes * torch.where(flip == 0, 1.0, flip)
    scale = ((x - mean) @ axes.T).square().mean().sqrt().clamp_min(1e-12)
    return mean.float(), axes.float(), scale.float()


class ZeroShotStyleVAE(PrimitiveVAE):
    """A primitive's generative model for any style given one example (see the module doc).

    Logged per split: ``loss``, ``recon``, ``kl``, ``style`` (training: only with ``style_weight > 0``);
    on val/test ``mpjpe`` and ``duration_error`` as :class:`PrimitiveVAE` (posterior-mean reconstructions
    conditioned on each clip's example).

    Args:
        embedding_dim: ``E``, values of the style embedding (32).
        anchor: also add the example's normalized features to the decoder's output (and subtract them from the
            encoder's input): the network models a clip as its example plus a variation (see the module doc).
        style_weight: weight of the Gram style term (0: off).
        style_latents: codes the style term decodes: ``posterior``, ``prior`` or ``both``.
        sample_temperature: τ of :meth:`sample`'s codes, ``z ~ N(0, τ² I)`` (1: the prior; smaller keeps the
            samples nearer the decoder's centre: less variation). Sampling only: it changes no training;
            :meth:`set_sample_temperature` changes it on a trained network.
        sample_centred: (anchored networks; false otherwise) decode :meth:`decode_latent`'s codes as the example plus
            the variation minus its mean over the prior (:meth:`variation_centre`), so the samples centre on their
            example instead of on where the decoder puts an unseen style. Sampling only, as ``sample_temperature``
            (:meth:`set_sample_centred`); the path-following synthesis decodes without it.
        sample_pooling: how several example clips condition :meth:`bind_example`'s samples (:data:`POOLINGS`:
            ``mean``, their mean condition; ``per_sample``, one clip drawn per sample). Sampling only
            (:meth:`set_sample_pooling`); one clip is the same either way.
        spec: what the model knows about its data (filled in at the first ``setup``).
        **kwargs: :class:`PrimitiveVAE` arguments (latent_dim, hidden, samples_per_item, kl_weight, …).
    """

    def __init__(self, embedding_dim: int = 32, anchor: bool = True, style_weight: float = 0.0,
                 style_latents: str = "both", sample_temperature: float = 1.0, sample_centred: bool = False,
                 sample_pooling: str = "mean", spec: dict[str, Any] | None = None, **kwargs: Any):
        super().__init__(**kwargs)  # built below, once this class' hyperparameters are known
        if isinstance(embedding_dim, bool) or int(embedding_dim) != embedding_dim or embedding_dim < 1:
            raise ValueError(f"embedding_dim must be a whole number ≥ 1, got {embedding_dim!r}")
        if not style_weight >= 0:
            raise ValueError(f"style_weight must be ≥ 0, got {style_weight}")
        if style_latents not in STYLE_LATENTS:
            raise ValueError(f"style_latents must be one of {STYLE_LATENTS}, got {style_latents!r}")
        if sample_pooling not in POOLINGS:
            raise ValueError(f"sample_pooling must be one of {POOLINGS}, got {sample_pooling!r}")
        self.save_hyperparameters({**dict(self.hparams), "embedding_dim": int(embedding_dim), "anchor": bool(anchor),
                                   "style_weight": float(style_weight), "style_latents": str(style_latents),
                                   "sample_temperature": checked_temperature(sample_temperature),
                                   "sample_centred": bool(sample_centred) and bool(anchor),  # needs the example
                                   "sample_pooling": str(sample_pooling),
                                   "spec": None if spec is None else dict(spec)})
        if spec is not None:
            self._build(spec)

    @property
    def sample_temperature(self) -> float:
        """τ of :meth:`sample` (1 for a checkpoint saved before the setting existed)."""
        return float(self.hparams.get("sample_temperature", 1.0))

    def set_sample_temperature(self, temperature: float) -> None:
        """Sample with ``z ~ N(0, τ² I)`` from now on (also in this network's checkpoints saved later)."""
        self.hparams["sample_temperature"] = checked_temperature(temperature)

    @property
    def sample_centred(self) -> bool:
        """Whether :meth:`decode_latent` centres the variation on the example (False for older checkpoints)."""
        return bool(self.hparams.get("sample_centred", False))

    def set_sample_centred(self, centred: bool) -> None:
        """Centre the samples' variation on their example from now on, or not (see the class doc)."""
        if centred and not self.hparams.anchor:
            raise ValueError("sample_centred needs anchor=true: the samples centre on their example")
        self.hparams["sample_centred"] = bool(centred)

    def set_sampling(self, sampling: Mapping[str, Any]) -> None:
        """Sample as ``sampling`` says from now on: its ``sample_temperature``, ``sample_centred`` (applied only where
        the network has an anchor to centre on) and ``sample_pooling``; a key it lacks leaves that setting as it is
        (e.g. ``configs/model/zero_shot.yaml``'s keys, or a style folder's record of them).

        Raises:
            ValueError: a value that is not a setting of its kind, naming it.
        """
        if "sample_temperature" in sampling:
            self.set_sample_temperature(sampling["sample_temperature"])
        if "sample_centred" in sampling:
            centred = sampling["sample_centred"]
            if not isinstance(centred, bool):
                raise ValueError(f"sample_centred must be true or false, got {centred!r}")
            self.set_sample_centred(centred and bool(self.hparams.anchor))
        if "sample_pooling" in sampling:
            self.set_sample_pooling(sampling["sample_pooling"])

    @property
    def sample_pooling(self) -> str:
        """How several example clips condition the samples of :meth:`bind_example` (``mean`` for older
        checkpoints)."""
        return str(self.hparams.get("sample_pooling", "mean"))

    def set_sample_pooling(self, pooling: str) -> None:
        """Pool several example clips this way from now on (:data:`POOLINGS`)."""
        if pooling not in POOLINGS:
            raise ValueError(f"sample_pooling must be one of {POOLINGS}, got {pooling!r}")
        self.hparams["sample_pooling"] = str(pooling)

    @torch.no_grad()
    def variation_centre(self, condition: StyleCondition) -> torch.Tensor:
        """The decoder's mean variation under ``condition`` over :data:`CENTRE_DRAWS` prior codes (a fixed seed):
        ``(D,)`` for one embedding ``(E,)``, ``(n, D)`` for embeddings ``(n, E)`` (each distinct one once)."""
        z = prior_draws(CENTRE_DRAWS, self.hparams.latent_dim, 0).to(self.device)
        embeddings = condition.embedding.reshape(-1, condition.embedding.shape[-1])
        distinct, inverse = torch.unique(embeddings, dim=0, return_inverse=True)
        centres = torch.stack([self.net.decode(z, e.expand(len(z), -1)).mean(0) for e in distinct])
        return centres[inverse].reshape(*condition.embedding.shape[:-1], -1)

    # -- construction from the data

    def _build(self, spec: dict[str, Any]) -> None:
        super()._build(spec)
        channels, steps = int(spec["feature_channels"]), int(spec["feature_steps"])
        dim = self.hparams.embedding_dim
        self.net = ConditionalMLPVAE(channels * steps + 1, dim, self.hparams.latent_dim, self.hparams.hidden)
        self.register_buffer("style_mean", torch.zeros(2 * channels))
        self.register_buffer("style_axes", torch.zeros(dim, 2 * channels))
        self.register_buffer("style_scale", torch.ones(()))

    def _adapt_spec(self, spec: dict[str, Any]) -> dict[str, Any]:
        if "excluded_styles" not in spec:
            raise ValueError("ZeroShotStyleVAE trains on clips of several styles paired with style examples: use "
                             "stylemotion.datamodules.multistyle.MultiStyleDataModule (experiment=zero_shot)")
        return dict(spec)

    def _install_stats(self, datamodule) -> None:
        super()._install_stats(datamodule)
        mean, axes, scale = fit_style_basis(style_descriptor(datamodule.datasets["train"].features),
                                            self.hparams.embedding_dim)
        self.style_mean.copy_(mean)
        self.style_axes.copy_(axes)
        self.style_scale.copy_(scale)

    # -- what the model knows

    @property
    def styles(self) -> list[str]:
        """The styles it was trained on."""
        return list(self.spec["styles"])

    @property
    def excluded_styles(self) -> list[str]:
        """The data's styles it never saw (left out of training)."""
        return list(self.spec["excluded_styles"])

    # -- the condition: style embedding (and anchor)

    def embed(self, features: torch.Tensor) -> torch.Tensor:
        """Raw autoencoder features ``(..., C, T')`` (any ``T'``) → embeddings ``(..., E)``."""
        d = style_descriptor(features.to(self.style_mean))
        return (d - self.style_mean) @ self.style_axes.T / self.style_scale

    def anchor(self, features: torch.Tensor) -> torch.Tensor:
        """Raw features ``(..., C, T')`` of examples on the canonical timeline → ``(..., D)`` in model space (as
        :meth:`normalize`, the duration value 0: the mean log-duration)."""
        steps = int(self.spec["feature_steps"])
        if features.shape[-1] != steps:
            raise ValueError(f"an anchored model needs examples of {steps} feature steps (encoded at the canonical "
                             f"length of {self.timeline_frames} frames), got {features.shape[-1]}")
        z = (features.to(self.feature_mean) - self.feature_mean[:, None]) / self.feature_std[:, None]
        return torch.cat([z.flatten(-2), z.new_zeros(z.shape[:-2] + (1,))], -1)

    def batch_condition(self, examples: torch.Tensor) -> StyleCondition:
        """The condition of each item of a batch from its example's raw features ``(batch, C, T')``."""
        examples = examples.to(self.style_mean)
        return StyleCondition(self.embed(examples), self.anchor(examples) if self.hparams.anchor else None)

    @torch.no_grad()
    def example_features(self, example: Any) -> list[torch.Tensor]:
        """An example as raw features ``[(C, T'), …]`` on this model's device.

        Args:
            example: features ``(C, T')`` or ``(n, C, T')``, a list of such tensors, or clips (anything
                with ``frames`` ``(frames, 66)``, e.g. :class:`~stylemotion.primitives.segmentation.Clip`), one or a
                list: resampled to the canonical timeline and encoded by the autoencoder, as the
                training clips were.

        Raises:
            ValueError: nothing given, or features of another channel count.
        """
        items = list(example) if isinstance(example, (list, tuple)) else [example]
        if not items or (isinstance(example, torch.Tensor) and example.dim() not in (2, 3)):
            raise ValueError("example must be features (C, T') or (n, C, T'), a list of them, or clip(s) with "
                             f"frames; got {type(example).__name__} {tuple(getattr(example, 'shape', ()))}")
        out: list[torch.Tensor] = []
        for item in items:
            if hasattr(item, "frames") and not isinstance(item, torch.Tensor):
                frames = torch.from_numpy(time_normalize(item.frames, self.timeline_frames)).float()
                out.append(self.autoencoder.encode(frames[None].to(self.device))[0])
            else:
                tensor = torch.as_tensor(item, dtype=torch.float32, device=self.device)
                out += list(tensor) if tensor.dim() == 3 else [tensor]
        channels = int(self.spec["feature_channels"])
        bad = [tuple(f.shape) for f in out if f.dim() != 2 or f.shape[0] != channels]
        if bad:
            raise ValueError(f"example features must be ({channels}, time) each (this model's autoencoder has "
                             f"{channels} channels), got {bad}")
        return out

    @torch.no_grad()
    def condition(self, example: Any) -> StyleCondition:
        """The condition of one example (see :meth:`example_features`; a :class:`StyleCondition` is returned
        as it is): the mean embedding of its clip(s), and with ``anchor`` their mean anchor."""
        if isinstance(example, StyleCondition):
            return example
        if example is None:
            raise ValueError("ZeroShotStyleVAE generates the style of an example: pass example=<features or clip>, "
                             "or use model.bind_example(example).sample(n, seed)")
        features = self.example_features(example)
        embedding = torch.stack([self.embed(f) for f in features]).mean(0)
        anchor = torch.stack([self.anchor(f) for f in features]).mean(0) if self.hparams.anchor else None
        return StyleCondition(embedding, anchor)

    @torch.no_grad()
    def per_sample_condition(self, example: Any, n: int, seed: int | None = None) -> StyleCondition:
        """``pooling=per_sample``: the condition of ``n`` samples, each that of one clip of ``example`` (see
        :meth:`example_features`) drawn uniformly with ``seed`` (a generator of its own, apart from the codes'):
        embeddings ``(n, E)`` and, with ``anchor``, anchors ``(n, D)``."""
        features = self.example_features(example)
        generator = torch.Generator()
        if seed is None:
            generator.seed()
        else:
            generator.manual_seed(int(seed) + 1)
        picks = torch.randint(len(features), (n,), generator=generator)
        embedding = torch.stack([self.embed(f) for f in features])[picks.to(self.device)]
        anchor = torch.stack([self.anchor(f) for f in features])[picks.to(self.device)] if self.hparams.anchor else None
        return StyleCondition(embedding, anchor)

    def bind_example(self, example: Any, style: str | None = None,
                     records: Sequence[dict[str, Any]] | None = None, pooling: str | None = None) -> BoundExample:
        """This model with one style example bound: a sampler with ``sample(n, seed)`` (see :class:`BoundExample`).

        Args:
            example: as :meth:`example_features`.
            style: the style's name (for reports).
            records: plain-value records of the example clip(s) (take, start, stop, …).
            pooling: how several clips condition the samples (:data:`POOLINGS`, see the module doc; None: the
                network's :attr:`sample_pooling`).
        """
        return BoundExample(self, self.example_features(example), style, records, pooling or self.sample_pooling)

    # -- objective

    def _decode(self, z: torch.Tensor, condition: StyleCondition) -> torch.Tensor:
        """``(..., k)`` codes → ``(..., D)`` model space (plus the anchor, when there is one)."""
        out = self.net.decode(z, condition.embedding)
        return out if condition.anchor is None else out + condition.anchor

    def _encode(self, y: torch.Tensor, condition: StyleCondition) -> tuple[torch.Tensor, torch.Tensor]:
        """``(batch, D)`` → posterior mean and log-variance ``(batch, k)`` (of ``y`` − anchor, when anchored)."""
        return self.net.encode(y if condition.anchor is None else y - condition.anchor, condition.embedding)

    def _style_term(self, recon: torch.Tensor, condition: StyleCondition, examples: torch.Tensor,
                    generator: torch.Generator | None) -> torch.Tensor:
        """Mean Gram distance of decoded sequences to their item's example: ``recon`` ``(L, batch, D)``,
        ``examples`` ``(batch, C, T_x)`` raw features."""
        decoded = []
        if self.hparams.style_latents in ("posterior", "both"):
            decoded.append(recon)
        if self.hparams.style_latents in ("prior", "both"):
            z = torch.randn(recon.shape[:-1] + (self.hparams.latent_dim,), generator=generator,
                            device=recon.device, dtype=recon.dtype)
            decoded.append(self._decode(z, condition))
        features, _ = self.denormalize(torch.cat(decoded), clamp=False)  # (L', batch, C, T')
        factor = examples / math.sqrt(examples.shape[-1])  # Gram(X) = (X/√T)(X/√T)ᵀ
        return feature_style_distance(features, target_factor=factor).mean()

    def losses(self, batch: dict[str, torch.Tensor],
               generator: torch.Generator | None = None) -> dict[str, torch.Tensor]:
        """``loss`` and its terms on a batch with ``example_features`` ``(batch, C, T_x)`` (see the module doc)."""
        y = self.normalize(batch["features"], batch["duration_s"])
        examples = batch["example_features"].to(y)
        condition = self.batch_condition(examples)
        mean, logvar = self._encode(y, condition)
        z = self.net.reparameterize(mean, logvar, self.hparams.samples_per_item, generator)
        recon = self._decode(z, condition)
        weights = torch.ones(y.shape[-1], device=y.device, dtype=y.dtype)
        weights[-1] = self.hparams.duration_weight
        out = {"recon": reconstruction_loss(recon, y, weights), "kl": kl_divergence(mean, logvar)}
        total = out["recon"] + self.hparams.kl_weight * out["kl"]
        if self.hparams.style_weight > 0 or not self.training:
            out["style"] = self._style_term(recon, condition, examples, generator)
            total = total + self.hparams.style_weight * out["style"]
        out["loss"] = self._add_contact_term(out, total, recon, batch)
        return out

    def _eval_step(self, batch: dict[str, torch.Tensor], batch_idx: int, split: str) -> None:
        generator = torch.Generator(device=self.device).manual_seed(batch_idx)  # the same noise every epoch
        terms = self.losses(batch, generator)
        with torch.no_grad():
            condition = self.batch_condition(batch["example_features"])
            recon = self.reconstruct(batch["features"], batch["duration_s"], condition)
            terms["mpjpe"] = masked_mpjpe(recon.positions, batch["positions"].cpu(), batch["num_frames"].cpu())
            _, decoded = self.denormalize(self._decode(recon.latent.to(self.device), condition))
            terms["duration_error"] = (decoded - batch["duration_s"]).abs().mean()
        size = batch["features"].shape[0]
        for name, value in terms.items():
            self.log(f"{split}/{name}", value, batch_size=size, sync_dist=True, prog_bar=name in ("loss", "mpjpe"))

    # -- inference

    @torch.no_grad()
    def reconstruct(self, features: torch.Tensor, duration_s: torch.Tensor, example: Any = None) -> MotionSamples:
        """Posterior-mean reconstructions of clips ``(n, C, T')`` at their durations ``(n,)`` seconds, given one
        example for all (see :meth:`condition`) or a :class:`StyleCondition` per clip."""
        features, duration_s = features.to(self.device), duration_s.to(self.device)
        condition = self.condition(example)
        mean, _ = self._encode(self.normalize(features, duration_s), condition)
        decoded, _ = self.denormalize(self._decode(mean, condition))
        out = decode_features(self.autoencoder, decoded, duration_s, self.timeline_frames, self.fps)
        out.latent = mean.cpu()
        return out

    @torch.no_grad()
    def decode_latent(self, z: torch.Tensor, chunk_size: int = DEFAULT_CHUNK, *, example: Any = None) -> MotionSamples:
        """Motions of latent codes ``(n, k)`` in the style of ``example`` (see :meth:`condition`; with
        :attr:`sample_centred` the variation centred on the example)."""
        condition = self.condition(example)
        z = torch.as_tensor(z, dtype=torch.float32)
        decoded = self._decode(z.to(self.device), condition)
        if self.sample_centred:
            decoded = decoded - self.variation_centre(condition)
        features, duration = self.denormalize(decoded)
        out = decode_features(self.autoencoder, features, duration, self.timeline_frames, self.fps, chunk_size)
        out.latent = z.cpu()
        return out

    @torch.no_grad()
    def sample(self, n: int, seed: int | None = None, chunk_size: int = DEFAULT_CHUNK, *,
               example: Any = None) -> MotionSamples:
        """``n`` motions in the style of ``example``: ``z ~ N(0, τ² I)`` (τ: :attr:`sample_temperature`) decoded
        under its condition. An example given as clips (see :meth:`example_features`) is bound first
        (:meth:`bind_example`), so several clips condition the samples as :attr:`sample_pooling` says, as
        ``stylemotion-style`` samples them; a :class:`StyleCondition` is used as it is. ``seed`` seeds a private
        generator (None: a fresh seed); returns :class:`MotionSamples` as :meth:`PrimitiveVAE.sample`."""
        if example is not None and not isinstance(example, StyleCondition):
            return self.bind_example(example).sample(n, seed, chunk_size)
        z = prior_draws(n, self.hparams.latent_dim, seed) * self.sample_temperature
        return self.decode_latent(z, chunk_size, example=self.condition(example))


#: Prior codes :meth:`ZeroShotStyleVAE.variation_centre` averages the decoder's variation over.
CENTRE_DRAWS = 1024


def checked_temperature(value: Any) -> float:
    """A sampling temperature τ as a float; refused unless a finite number ≥ 0 (ValueError naming it)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value < 0:
        raise ValueError(f"sample_temperature must be a finite number ≥ 0, got {value!r}")
    return float(value)


@dataclass
class StyleCondition:
    """What the network is conditioned on: the example's embedding ``(..., E)`` and, for an anchored model,
    its anchor ``(..., D)`` (its normalized features; None otherwise)."""

    embedding: torch.Tensor
    anchor: torch.Tensor | None = None


class BoundDecoder:
    """The network's decoder with one condition bound: :meth:`decode` maps codes to model space as a
    :class:`~stylemotion.models.vae.PrimitiveVAE`'s ``net.decode`` does (the anchor included)."""

    def __init__(self, model: ZeroShotStyleVAE, condition: StyleCondition):
        self.model, self.condition = model, condition

    def decode(self, z: torch.Tensor) -> torch.Tensor:
        """``(..., k)`` codes → ``(..., D)`` model space (differentiable in ``z``)."""
        return self.model._decode(z, self.condition)


class BoundExample:
    """A :class:`ZeroShotStyleVAE` with one style example bound: a sample source like any style model, and
    what the path-following synthesis uses of a primitive model (``net.decode``, ``denormalize``,
    ``hparams.latent_dim``, ``autoencoder``, ``timeline_frames``, ``fps``, ``decode_latent``, ``sample``,
    ``eval``, ``requires_grad_``).

    Attributes:
        model: the network.
        example_features: ``[(C, T'), …]`` the example clip(s), raw features.
        condition: their :class:`StyleCondition` (computed at binding: bind again after further training).
        style: the style's name, or None.
        style_examples: plain-value records of the example clip(s) (take, start, stop, …).
        pooling: how several clips condition :meth:`sample` (``mean``: :attr:`condition`; ``per_sample``: one clip
            drawn per sample); the path-following synthesis decodes under :attr:`condition`.
    """

    def __init__(self, model: ZeroShotStyleVAE, example_features: list[torch.Tensor], style: str | None = None,
                 records: Sequence[dict[str, Any]] | None = None, pooling: str = "mean"):
        if pooling not in POOLINGS:
            raise ValueError(f"pooling must be one of {POOLINGS}, got {pooling!r}")
        self.pooling = pooling
        self.model = model
        self.example_features = list(example_features)
        self.condition = model.condition(self.example_features)
        self.style = style
        self.style_examples = [dict(r) for r in records or []]

    @property
    def spec(self) -> dict[str, Any]:
        return self.model.spec

    @property
    def primitive(self) -> str:
        return self.model.primitive

    @property
    def timeline_frames(self) -> int:
        return self.model.timeline_frames

    @property
    def fps(self) -> float:
        return self.model.fps

    @property
    def latent_dim(self) -> int:
        return int(self.model.hparams.latent_dim)

    @property
    def autoencoder(self):
        return self.model.autoencoder

    @property
    def hparams(self):
        """The network's hyperparameters (``latent_dim``, …)."""
        return self.model.hparams

    @property
    def net(self) -> BoundDecoder:
        """The decoder under the bound condition (``net.decode(z)``, as a PrimitiveVAE's ``net``)."""
        return BoundDecoder(self.model, self.condition)

    def denormalize(self, y: torch.Tensor, clamp: bool = True) -> tuple[torch.Tensor, torch.Tensor]:
        """See :meth:`PrimitiveVAE.denormalize`."""
        return self.model.denormalize(y, clamp)

    def eval(self) -> BoundExample:
        """The network in eval mode; returns this sampler."""
        self.model.eval()
        return self

    def requires_grad_(self, requires_grad: bool = True) -> BoundExample:
        """The network's parameters (not) requiring gradients; returns this sampler."""
        self.model.requires_grad_(requires_grad)
        return self

    @property
    def checkpoint_file(self) -> str | None:
        return self.model.checkpoint_file

    def attach_autoencoder(self, autoencoder) -> None:
        """See :meth:`PrimitiveVAE.attach_autoencoder`."""
        self.model.attach_autoencoder(autoencoder)

    @property
    def target_gram(self) -> torch.Tensor:
        """``(C, C)`` the mean Gram of the example clip(s) (what Table 5.1's column of this example is)."""
        return mean_gram([f.cpu() for f in self.example_features])

    def sample(self, n: int, seed: int | None = None, chunk_size: int = DEFAULT_CHUNK) -> MotionSamples:
        """``n`` motions in the bound example's style (see :meth:`ZeroShotStyleVAE.sample`; ``pooling=per_sample``:
        each conditioned on one clip drawn with ``seed``, :meth:`ZeroShotStyleVAE.per_sample_condition`)."""
        if self.pooling == "per_sample" and len(self.example_features) > 1:  # one clip: the mean's condition
            condition = self.model.per_sample_condition(self.example_features, n, seed)
            return self.model.sample(n, seed, chunk_size, example=condition)
        return self.model.sample(n, seed, chunk_size, example=self.condition)

    def decode_latent(self, z: torch.Tensor, chunk_size: int = DEFAULT_CHUNK) -> MotionSamples:
        """Motions of latent codes ``(n, k)`` in the bound example's style."""
        return self.model.decode_latent(z, chunk_size, example=self.condition)
