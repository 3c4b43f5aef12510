"""Per-primitive variational autoencoder over autoencoder features (thesis §5.3.2, eq. 5.3–5.8, Fig. 5.3).

:class:`MLPVAE` is the plain network: encoder ``D → 512 → 256 → 128`` (tanh) with two linear heads
giving the mean and log-variance of a 32-dim latent, decoder ``32 → 128 → 256 → 512`` (tanh)
``→ D`` (linear). :class:`PrimitiveVAE` trains it on one primitive's neutral clips:

    loss = recon + kl_weight · KL
    recon = 1/(2NL) Σ_i Σ_l ‖decoder(z_il) − y_i‖²_w,   z_il = μ(y_i) + σ(y_i) ε_l     (eq. 5.7)
    KL    = 1/N Σ_i ½ (μᵀμ + tr Σ − k − log det Σ)                                   (eq. 5.8)

with ``L = samples_per_item`` reparameterized samples per item (10 in the thesis). With ``contact_weight`` > 0
the loss gains ``contact_weight · contact``, the foot-contact velocity loss
(:mod:`stylemotion.models.contact_loss`, m²/s²) of the first of each item's ``L`` reconstructions, decoded
through the frozen autoencoder at the item's real duration, on the recorded clip's contact foot-frames;
the CVAE and the zero-shot network inherit it.

What the VAE models, ``y`` (``D = channels · steps + 1`` values): the clip's autoencoder features
``(channels, steps)`` z-scored per channel (statistics of the train split), flattened, plus its
standardized log-duration. ``‖·‖²_w`` weighs the duration value by ``duration_weight`` and every
feature value by 1. Samples thus carry their own durations, correlated with the motion.

Sampling (:meth:`PrimitiveVAE.sample`) decodes ``z ~ N(0, I)`` to features and a duration, and
:func:`stylemotion.models.sampling.decode_features` turns them into motions (autoencoder decoder, duration
restored, root integrated). The autoencoder is not part of this module's state (not a submodule,
not in ``state_dict``), but every checkpoint embeds it beside the state dict (its hyperparameters
and weights, :func:`stylemotion.models.checkpoints.autoencoder_record`), so a checkpoint samples
wherever it is copied. Its path and a fingerprint of its weights are hyperparameters
(``spec["autoencoder"]``); on first use it is taken from the checkpoint (or, for checkpoints written
before the embedding, from that path; see :func:`stylemotion.models.checkpoints.resolve_autoencoder`),
or it is given with :meth:`PrimitiveVAE.attach_autoencoder`.

Everything the model learned about its data (feature shape, canonical length, fps, autoencoder,
which clips and examples) is filled in from the :class:`~stylemotion.datamodules.features.FeatureDataModule`
at the first ``setup`` into the plain-valued hyperparameter ``spec``; normalization statistics are
buffers. So ``PrimitiveVAE.load_from_checkpoint(path)`` works in a fresh process under
``torch.load(weights_only=True)``.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import lightning.pytorch as pl
import torch
from torch import nn

from stylemotion.models.autoencoder import IncompatibleModelError, MotionAutoencoder, NonFiniteLossError
from stylemotion.models.checkpoints import (
    EMBEDDED_AUTOENCODER,
    autoencoder_record,
    fingerprint,
    load_autoencoder,
    resolve_autoencoder,
)
from stylemotion.models.contact_loss import contact_velocity_loss, timeline_contacts
from stylemotion.models.sampling import DEFAULT_CHUNK, MotionSamples, decode_features, masked_mpjpe

log = logging.getLogger(__name__)

#: Spec keys that must agree between a model and the data it is trained or evaluated on.
STRUCTURAL_KEYS = ("primitive", "feature_channels", "feature_steps", "timeline_frames", "fps")


class MLPVAE(nn.Module):
    """Fully connected VAE with tanh hidden layers (thesis Fig. 5.3).

    Args:
        input_dim: ``D``, values per item.
        latent_dim: ``k``, latent dimensions (32).
        hidden: encoder hidden widths (512, 256, 128); the decoder mirrors them.
    """

    def __init__(self, input_dim: int, latent_dim: int = 32, hidden: Sequence[int] = (512, 256, 128)):
        super().__init__()
        if input_dim < 1 or latent_dim < 1 or not hidden or min(hidden) < 1:
            raise ValueError(f"need positive sizes, got input_dim={input_dim}, latent_dim={latent_dim}, "
                             f"hidden={list(hidden)}")
        self.input_dim, self.latent_dim = int(input_dim), int(latent_dim)
        layers, width = [], self.input_dim
        for h in hidden:
            layers += [nn.Linear(width, h), nn.Tanh()]
            width = h
        self.encoder = nn.Sequential(*layers)
        self.mean = nn.Linear(width, self.latent_dim)
        self.logvar = nn.Linear(width, self.latent_dim)
        layers, width = [], self.latent_dim
        for h in reversed(list(hidden)):
            layers += [nn.Linear(width, h), nn.Tanh()]
            width = h
        layers.append(nn.Linear(width, self.input_dim))
        self.decoder = nn.Sequential(*layers)

    def encode(self, y: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        """``(batch, D)`` → mean and log-variance, each ``(batch, k)``."""
        h = self.encoder(y)
        return self.mean(h), self.logvar(h)

    def decode(self, z: torch.Tensor) -> torch.Tensor:
        """``(..., k)`` latent codes → ``(..., D)``."""
        return self.decoder(z)

    @staticmethod
    def reparameterize(mean: torch.Tensor, logvar: torch.Tensor, samples: int = 1,
                       generator: torch.Generator | None = None) -> torch.Tensor:
        """``(samples, batch, k)`` draws ``μ + exp(½ log σ²) ε`` with ``ε ~ N(0, I)`` (eq. 5.5)."""
        eps = torch.randn((samples,) + tuple(mean.shape), generator=generator, device=mean.device, dtype=mean.dtype)
        return mean + torch.exp(0.5 * logvar) * eps

    def forward(self, y: torch.Tensor, samples: int = 1, generator: torch.Generator | None = None):
        """Returns ``(recon (samples, batch, D), mean (batch, k), logvar (batch, k), z (samples, batch, k))``."""
        mean, logvar = self.encode(y)
        z = self.reparameterize(mean, logvar, samples, generator)
        return self.decode(z), mean, logvar, z


def prior_draws(n: int, latent_dim: int, seed: int | None = None) -> torch.Tensor:
    """``(n, latent_dim)`` draws of ``N(0, I)`` from a private generator seeded with ``seed`` (None: a fresh
    seed; the global RNG is untouched)."""
    if n < 1:
        raise ValueError(f"n must be ≥ 1, got {n}")
    generator = torch.Generator()
    if seed is None:
        generator.seed()
    else:
        generator.manual_seed(int(seed))
    return torch.randn(n, latent_dim, generator=generator)


def reconstruction_loss(recon: torch.Tensor, target: torch.Tensor, weights: torch.Tensor | None = None) -> torch.Tensor:
    """Eq. 5.7: ``½ · mean over samples and items of Σ_d w_d (recon − target)²``.

    Args:
        recon: ``(samples, batch, D)`` decoder outputs.
        target: ``(batch, D)``.
        weights: ``(D,)`` per-value weights (None = 1).
    """
    sq = (recon - target).square()
    if weights is not None:
        sq = sq * weights
    return 0.5 * sq.sum(-1).mean()


def kl_divergence(mean: torch.Tensor, logvar: torch.Tensor) -> torch.Tensor:
    """Eq. 5.8, ``KL(N(μ, diag σ²) ‖ N(0, I))`` summed over latent dims, averaged over ``(batch,)`` items."""
    return 0.5 * (mean.square() + logvar.exp() - 1.0 - logvar).sum(-1).mean()


class PrimitiveVAE(pl.LightningModule):
    """Generative model of one motion primitive (a VAE on its clips' autoencoder features).

    Batches come from :class:`~stylemotion.datamodules.features.FeatureDataModule`. Logged per split:
    ``loss``, ``recon``, ``kl`` (and ``contact`` when ``contact_weight`` > 0); on val/test also ``contact`` (m²/s²,
    see :meth:`contact_term`), ``mpjpe`` (metres: posterior-mean reconstruction
    decoded through the autoencoder at the clip's real duration, against the recorded clip, both
    integrated from the origin at the data's fps) and ``duration_error`` (seconds, mean absolute).

    Args:
        latent_dim: latent dimensions (32).
        hidden: encoder hidden widths (decoder mirrors them).
        samples_per_item: ``L``, reparameterized samples per item per step (10).
        kl_weight: weight of the KL term (1).
        duration_weight: weight of the standardized log-duration in the reconstruction term.
        contact_weight: weight of the foot-contact velocity loss (m²/s², :meth:`contact_term`; 0 = off).
        lr, weight_decay: Adam settings.
        duration_range: sampled durations are clamped to ``[lo · shortest, hi · longest]`` training
            duration.
        spec: what the model knows about its data (filled in at the first ``setup``; see module doc).
    """

    def __init__(
        self,
        latent_dim: int = 32,
        hidden: Sequence[int] = (512, 256, 128),
        samples_per_item: int = 10,
        kl_weight: float = 1.0,
        duration_weight: float = 100.0,
        contact_weight: float = 0.0,
        lr: float = 1e-3,
        weight_decay: float = 0.0,
        duration_range: Sequence[float] = (0.75, 1.5),
        spec: dict[str, Any] | None = None,
    ):
        super().__init__()
        if samples_per_item < 1 or not kl_weight >= 0 or not duration_weight >= 0 or not lr > 0:
            raise ValueError(f"need samples_per_item ≥ 1, kl_weight ≥ 0, duration_weight ≥ 0, lr > 0; got "
                             f"{samples_per_item}, {kl_weight}, {duration_weight}, {lr}")
        if not contact_weight >= 0:
            raise ValueError(f"contact_weight must be ≥ 0, got {contact_weight}")
        lo, hi = (float(v) for v in duration_range)
        if not 0 < lo <= 1 <= hi:
            raise ValueError(f"duration_range must be (lo, hi) with 0 < lo ≤ 1 ≤ hi, got {list(duration_range)}")
        self.save_hyperparameters({
            "latent_dim": int(latent_dim), "hidden": [int(h) for h in hidden],
            "samples_per_item": int(samples_per_item), "kl_weight": float(kl_weight),
            "duration_weight": float(duration_weight), "contact_weight": float(contact_weight),
            "lr": float(lr), "weight_decay": float(weight_decay),
            "duration_range": [lo, hi], "spec": None if spec is None else dict(spec),
        })
        self.net: MLPVAE | None = None
        object.__setattr__(self, "_autoencoder", None)  # not a submodule: not in state_dict
        object.__setattr__(self, "_autoencoder_record", None)  # the one embedded in a loaded checkpoint
        #: the checkpoint file this model was loaded from, when known (finds an old checkpoint's autoencoder)
        self.checkpoint_file: str | None = None
        #: the file the autoencoder was loaded from (a model checkpoint when embedded there), when known
        self.autoencoder_path: str | None = None
        if spec is not None:
            self._build(spec)

    # -- construction from the data

    def _build(self, spec: dict[str, Any]) -> None:
        channels, steps = int(spec["feature_channels"]), int(spec["feature_steps"])
        self.net = MLPVAE(channels * steps + 1, self.hparams.latent_dim, self.hparams.hidden)
        self.register_buffer("feature_mean", torch.zeros(channels))
        self.register_buffer("feature_std", torch.ones(channels))
        #: log-duration mean and std, shortest and longest training duration (seconds)
        self.register_buffer("duration_stats", torch.tensor([0.0, 1.0, 0.0, float("inf")]))
        self.register_buffer("stats_initialized", torch.zeros((), dtype=torch.bool))

    def _adapt_spec(self, spec: dict[str, Any]) -> dict[str, Any]:
        """The data spec as this model records it (a plain VAE ignores style examples)."""
        return {**spec, "style": None, "style_examples": [], "example_length": None}

    def _install_stats(self, datamodule) -> None:
        self.feature_mean.copy_(datamodule.feature_mean)
        self.feature_std.copy_(datamodule.feature_std)
        self.duration_stats.copy_(datamodule.duration_stats)
        self.stats_initialized.fill_(True)

    def _check_spec(self, spec: dict[str, Any]) -> None:
        mine = self.spec
        bad = [f"{k}: model {mine.get(k)!r}, data {spec.get(k)!r}"
               for k in STRUCTURAL_KEYS if mine.get(k) != spec.get(k)]
        if mine["autoencoder"]["fingerprint"] != spec["autoencoder"]["fingerprint"]:
            bad.append(f"autoencoder weights: model {mine['autoencoder']['fingerprint']} "
                       f"({mine['autoencoder']['path']}), data {spec['autoencoder']['fingerprint']} "
                       f"({spec['autoencoder']['path']})")
        if bad:
            raise IncompatibleModelError(f"{type(self).__name__} and its data do not match — " + "; ".join(bad))

    def setup(self, stage: str) -> None:
        datamodule = getattr(self.trainer, "datamodule", None) if self._trainer is not None else None
        if datamodule is None or not hasattr(datamodule, "model_spec"):
            raise RuntimeError(f"{type(self).__name__} is trained on a FeatureDataModule "
                               "(stylemotion.datamodules.features), which provides the features and their statistics")
        spec = self._adapt_spec(datamodule.model_spec())
        if self.net is None:
            self._build(spec)
            self.hparams["spec"] = spec
        else:
            self._check_spec(spec)
        if not bool(self.stats_initialized):
            self._install_stats(datamodule)
        self.attach_autoencoder(datamodule.autoencoder)

    def configure_optimizers(self):
        return torch.optim.Adam(self.parameters(), lr=self.hparams.lr, weight_decay=self.hparams.weight_decay)

    # -- what the model knows

    @property
    def spec(self) -> dict[str, Any]:
        if self.hparams.spec is None:
            raise RuntimeError(f"this {type(self).__name__} has not seen its data yet: fit it on a FeatureDataModule")
        return self.hparams.spec

    @property
    def primitive(self) -> str:
        return self.spec["primitive"]

    @property
    def timeline_frames(self) -> int:
        return int(self.spec["timeline_frames"])

    @property
    def fps(self) -> float:
        return float(self.spec["fps"])

    @property
    def autoencoder(self) -> MotionAutoencoder:
        """The frozen autoencoder that decodes features: the attached one, else the one embedded in
        the checkpoint, else the recorded file (see :func:`~stylemotion.models.checkpoints.resolve_autoencoder`)."""
        if self._autoencoder is None:
            autoencoder, path = resolve_autoencoder(self.spec["autoencoder"], self._autoencoder_record,
                                                    self.checkpoint_file)
            self.attach_autoencoder(autoencoder)
            self.autoencoder_path = path
        if self._autoencoder.net.encoder.weight.device != self.device:
            self._autoencoder.to(self.device)
        return self._autoencoder

    def attach_autoencoder(self, autoencoder: MotionAutoencoder | str | Path) -> None:
        """Use ``autoencoder`` (a module or a checkpoint path) to decode; it must be the one the
        features came from (same weight fingerprint), e.g. after the checkpoint file moved."""
        info = self.spec["autoencoder"]
        if isinstance(autoencoder, (str, Path)):
            path, autoencoder = str(autoencoder), load_autoencoder(autoencoder, expected=info)
            self.autoencoder_path = path
        else:
            got = fingerprint(autoencoder)
            if got != info["fingerprint"]:
                raise IncompatibleModelError(f"this autoencoder (weights {got}) is not the one the model "
                                             f"was trained with (weights {info['fingerprint']}, {info['path']})")
            self.autoencoder_path = None
        autoencoder.eval().requires_grad_(False)
        object.__setattr__(self, "_autoencoder", autoencoder.to(self.device))

    def on_save_checkpoint(self, checkpoint: dict[str, Any]) -> None:
        """Embed the autoencoder (hyperparameters and weights, plain values; see the module doc)."""
        if self.hparams.spec is None:
            return
        if self._autoencoder is not None:
            checkpoint[EMBEDDED_AUTOENCODER] = autoencoder_record(self._autoencoder)
        elif self._autoencoder_record is not None:
            checkpoint[EMBEDDED_AUTOENCODER] = self._autoencoder_record
        else:
            try:
                checkpoint[EMBEDDED_AUTOENCODER] = autoencoder_record(self.autoencoder)
            except (FileNotFoundError, IncompatibleModelError) as err:
                log.warning("checkpoint saved without its autoencoder (%s)", err)

    def on_load_checkpoint(self, checkpoint: dict[str, Any]) -> None:
        """Keep the embedded autoencoder (built on first use; absent in older checkpoints)."""
        object.__setattr__(self, "_autoencoder_record", checkpoint.get(EMBEDDED_AUTOENCODER))

    # -- feature space ⇄ model space

    def normalize(self, features: torch.Tensor, duration_s: torch.Tensor) -> torch.Tensor:
        """Raw features ``(batch, C, T')`` and durations ``(batch,)`` seconds → ``(batch, C·T' + 1)``."""
        z = (features - self.feature_mean[:, None]) / self.feature_std[:, None]
        d = (duration_s.log() - self.duration_stats[0]) / self.duration_stats[1]
        return torch.cat([z.flatten(-2), d.unsqueeze(-1)], dim=-1)

    def denormalize(self, y: torch.Tensor, clamp: bool = True) -> tuple[torch.Tensor, torch.Tensor]:
        """``(..., C·T' + 1)`` → raw features ``(..., C, T')`` and durations ``(...)`` seconds
        (clamped to ``duration_range`` unless ``clamp`` is False)."""
        channels = self.feature_mean.numel()
        features = y[..., :-1].unflatten(-1, (channels, -1)) * self.feature_std[:, None] + self.feature_mean[:, None]
        duration = torch.exp(y[..., -1] * self.duration_stats[1] + self.duration_stats[0])
        if clamp:
            lo, hi = self.hparams.duration_range
            duration = duration.clamp(float(self.duration_stats[2]) * lo, float(self.duration_stats[3]) * hi)
        return features, duration

    # -- objective

    def _extra_losses(self, recon: torch.Tensor, generator: torch.Generator | None = None
                      ) -> dict[str, tuple[torch.Tensor, float]]:
        """Additional terms ``name → (value, weight)`` given the decoder outputs ``(L, batch, D)`` of
        the posterior samples (``generator`` draws any further noise)."""
        return {}

    def losses(self, batch: dict[str, torch.Tensor],
               generator: torch.Generator | None = None) -> dict[str, torch.Tensor]:
        """``loss`` and its terms (``recon``, ``kl``, …) on a batch (eq. 5.6, 5.11)."""
        y = self.normalize(batch["features"], batch["duration_s"])
        recon, mean, logvar, _ = self.net(y, self.hparams.samples_per_item, generator)
        weights = torch.ones(y.shape[-1], device=y.device, dtype=y.dtype)
        weights[-1] = self.hparams.duration_weight
        out = {"recon": reconstruction_loss(recon, y, weights), "kl": kl_divergence(mean, logvar)}
        total = out["recon"] + self.hparams.kl_weight * out["kl"]
        for name, (value, weight) in self._extra_losses(recon, generator).items():
            out[name] = value
            total = total + weight * value
        out["loss"] = self._add_contact_term(out, total, recon, batch)
        return out

    # -- the foot-contact velocity loss (stylemotion.models.contact_loss)

    def _add_contact_term(self, out: dict[str, torch.Tensor], total: torch.Tensor, recon: torch.Tensor,
                          batch: dict[str, torch.Tensor]) -> torch.Tensor:
        """``total`` plus ``contact_weight · contact`` (recorded in ``out``): computed when the weight is > 0,
        and in evaluation whenever the batch holds the recorded clips (``positions``, ``num_frames``)."""
        weight = float(self.hparams.get("contact_weight", 0.0))
        if weight > 0 or (not self.training and "positions" in batch and "num_frames" in batch):
            out["contact"] = self.contact_term(recon[0], batch)
            if weight > 0:
                total = total + weight * out["contact"]
        return total

    def contact_term(self, y: torch.Tensor, batch: dict[str, torch.Tensor]) -> torch.Tensor:
        """The foot-contact velocity loss of model-space reconstructions of a batch's clips.

        Args:
            y: ``(batch, D)`` model-space values (e.g. one reparameterized reconstruction per item), decoded
                through the frozen autoencoder (gradient to ``y``, not to the autoencoder) on the canonical
                timeline at each clip's real duration ``batch["duration_s"]``.
            batch: with ``positions`` ``(batch, frames, 21, 3)`` and ``num_frames`` ``(batch,)``: the recorded
                clips, whose contacts (:func:`~stylemotion.models.contact_loss.timeline_contacts`) say where
                the decoded feet must stay still.

        Returns:
            Scalar, m²/s² (:func:`~stylemotion.models.contact_loss.contact_velocity_loss`).
        """
        if "positions" not in batch or "num_frames" not in batch:
            raise ValueError("the contact term needs the recorded clips in the batch (positions, num_frames): "
                             "train on a FeatureDataModule or MultiStyleDataModule")
        length = self.timeline_frames
        features, _ = self.denormalize(y, clamp=False)
        frames = self.autoencoder.decode(features, length).float()  # (batch, L, 66)
        contacts = timeline_contacts(batch["positions"], batch["num_frames"], self.fps, length).to(frames.device)
        rate = (length - 1) / batch["duration_s"].to(frames)  # playback fps of the canonical timeline
        return contact_velocity_loss(frames, contacts, rate)

    def training_step(self, batch: dict[str, torch.Tensor], batch_idx: int) -> torch.Tensor:
        terms = self.losses(batch)
        if not torch.isfinite(terms["loss"]):
            raise NonFiniteLossError(
                f"training loss is {terms['loss'].item()} at epoch {self.current_epoch}, batch {batch_idx} "
                f"({ {k: float(v) for k, v in terms.items()} }); lower the learning rate (lr={self.hparams.lr})")
        size = batch["features"].shape[0]
        for name, value in terms.items():
            self.log(f"train/{name}", value, batch_size=size, prog_bar=name == "loss", sync_dist=True)
        return terms["loss"]

    def _eval_step(self, batch: dict[str, torch.Tensor], batch_idx: int, split: str) -> None:
        generator = torch.Generator(device=self.device).manual_seed(batch_idx)  # the same noise every epoch
        terms = self.losses(batch, generator)
        with torch.no_grad():
            recon = self.reconstruct(batch["features"], batch["duration_s"])
            terms["mpjpe"] = masked_mpjpe(recon.positions, batch["positions"].cpu(), batch["num_frames"].cpu())
            _, decoded = self.denormalize(self.net.decode(recon.latent.to(self.device)))
            terms["duration_error"] = (decoded - batch["duration_s"]).abs().mean()
        size = batch["features"].shape[0]
        for name, value in terms.items():
            self.log(f"{split}/{name}", value, batch_size=size, sync_dist=True, prog_bar=name in ("loss", "mpjpe"))

    def validation_step(self, batch: dict[str, torch.Tensor], batch_idx: int) -> None:
        self._eval_step(batch, batch_idx, "val")

    def test_step(self, batch: dict[str, torch.Tensor], batch_idx: int) -> None:
        self._eval_step(batch, batch_idx, "test")

    # -- inference

    @torch.no_grad()
    def reconstruct(self, features: torch.Tensor, duration_s: torch.Tensor) -> MotionSamples:
        """Posterior-mean reconstructions of clips, as motions at their given durations.

        Args:
            features: ``(n, C, T')`` raw autoencoder features of time-normalized clips.
            duration_s: ``(n,)`` their durations, seconds (applied to the reconstructions).

        Returns:
            :class:`MotionSamples` with ``latent`` = posterior means ``(n, k)``.
        """
        features, duration_s = features.to(self.device), duration_s.to(self.device)
        mean, _ = self.net.encode(self.normalize(features, duration_s))
        decoded, _ = self.denormalize(self.net.decode(mean))
        out = decode_features(self.autoencoder, decoded, duration_s, self.timeline_frames, self.fps)
        out.latent = mean.cpu()
        return out

    @torch.no_grad()
    def decode_latent(self, z: torch.Tensor, chunk_size: int = DEFAULT_CHUNK) -> MotionSamples:
        """Motions of latent codes ``(n, k)``, each with its decoded duration."""
        z = torch.as_tensor(z, dtype=torch.float32)
        y = self.net.decode(z.to(self.device))
        features, duration = self.denormalize(y)
        out = decode_features(self.autoencoder, features, duration, self.timeline_frames, self.fps, chunk_size)
        out.latent = z.cpu()
        return out

    @torch.no_grad()
    def sample(self, n: int, seed: int | None = None, chunk_size: int = DEFAULT_CHUNK) -> MotionSamples:
        """``n`` random motions of the primitive: ``z ~ N(0, I)`` decoded (see :meth:`decode_latent`).

        Args:
            n: number of samples.
            seed: seeds a private generator (the global RNG is untouched); None draws a fresh seed.
            chunk_size: samples per autoencoder call.

        Returns:
            :class:`MotionSamples`: ``positions (n, frames, 21, 3)`` metres at ``fps`` (30) with each
            sample's duration applied (padded, see ``num_frames``), ``frames (n, frames, 66)``,
            ``latent (n, 32)``, ``duration_s``, ``features``.
        """
        return self.decode_latent(prior_draws(n, self.hparams.latent_dim, seed), chunk_size)
