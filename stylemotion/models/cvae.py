"""Style CVAE: the primitive VAE deformed towards one style example (thesis §5.3.3, eq. 5.9–5.11).

The network and the content data are those of :class:`~stylemotion.models.vae.PrimitiveVAE` (the
neutral clips of the primitive); the loss gains a style term::

    loss = recon + kl_weight · KL + α · mean_z ‖Gram(decoder(z)) − Gram(Φ(x_s))‖_F

where ``decoder(z)`` is turned back into raw autoencoder features (de-normalized, duration value
dropped), ``Gram`` is :func:`stylemotion.models.style.gram` (over time, normalized by the number of
time steps) and ``Gram(Φ(x_s))`` is the mean Gram of the encoded style example clip(s) — any
length, any primitive (see :mod:`stylemotion.datamodules.features`).

Which ``z`` (``style_latents``): the thesis writes ``decoder(z)`` next to the reconstruction's
``z_il = μ(y_i) + σ(y_i) ε_l``. Styling only those (``posterior``) leaves the samples a user draws,
``z ~ N(0, I)``, unstyled wherever the encoder's posteriors do not cover the prior; ``prior``
(default) styles as many fresh prior draws instead, the draws a user samples; ``both`` styles both, so
reconstructions and samples agree. ``prior`` was chosen on Bandai validation clips by suite ``style_term``
(benchmarks/evaluation.md): its samples lie nearer the example's Gram, with less spread.

α (``style_weight``) is 5 by default, chosen on Bandai validation clips (suite ``style_alpha``,
benchmarks/evaluation.md): the thesis' 200 is far too strong in our units (the Gram is divided by the
number of time steps) and collapses the samples onto the example; see ``docs/style.md``.

Two departures from the thesis, off by default (measured in issue 12; history in
``git show 1c0f1b8:benchmarks/evaluation.md``, "Issue 12: the style term"): ``style_term=margin`` replaces
α·d by ``α · mean (max(0, d − τ)/τ)²`` with τ = ``style_margin`` × the median Gram distance of the content
training clips to their mean Gram, a
dimensionless term that leaves samples free inside a ball the size of the neutral data's own spread;
``style_centred`` takes the Gram of features centred over time (a covariance), so each channel's mean
over the clip — where speed and turning live, and, as measured, most of what makes a style
recognizable — is not pinned to the example's. On Bandai neither keeps both the style and the
variation: the margin keeps the style only where it is as strong as the default, the centred term
keeps the variation and loses the style.

Options for the strict replication arm (preset ``experiment=style_cvae_thesis``, suite ``style_thesis``; defaults
leave the model as above): ``gram_normalization=sum`` takes eq. 5.9 as written (``Σ_t y_t y_tᵀ``, ``T`` times ours,
so the same α pulls ``T`` times harder); ``style_channels=pose`` compares Gram matrices of pose-only features
(:func:`pose_features`: the features decoded by the frozen autoencoder, root ground velocity and yaw rate set to
their data mean, encoded again), which frees speed and turning from the example; it costs a decode and an encode
per style decode, so ``style_subset`` = k > 0 takes the style term's mean over a random k of the decodes of each
step (an unbiased estimate of the same mean; 0 = all).

Planted feet in the draws (issue 27 item 1; off by default): ``sample_contact_weight`` = β > 0 adds β · the foot-
contact velocity loss of the style term's decodes (the same draws, decoded by the frozen autoencoder on the
primitive's timeline at each draw's own duration), with the contacts the detector finds on each draw itself
(:func:`~stylemotion.models.contact_loss.own_contacts`): the feet a styled draw plants must stay still, wherever it
plants them. A draw whose stance foot slides so fast that the detector never finds it planted has no contact, so
that term cannot reach it; ``sample_contacts=content`` takes instead the primitive's contact template: the timeline
frames where most content (neutral) training clips have that foot in contact (:func:`content_contact_template`,
computed once from the clips' recorded contacts), the same frames for every draw, and adds the speed of heel and
ball over the middle half of each of the template's contact runs
(:func:`~stylemotion.models.contact_loss.midstance_loss`: the per-frame term alone lets heel and ball take turns to
stay still while the foot walks backwards under the root). Primitives are cut at contacts, so the stance foot is
planted on the whole timeline in clips of every style. The PrimitiveVAE's ``contact_weight`` instead holds the
reconstructions of the neutral content clips to the content clips' contacts, which pulls the draws' steps towards
neutral ones (suite ``contact_loss``).

A styled duration (``StyleCVAE``'s default off; ``configs/model/style_cvae.yaml`` sets γ = 50, chosen on Bandai
validation clips by suite ``style_duration``): the reconstruction term holds the draws' durations to the content
(neutral) clips', and the style term reads features on the canonical timeline only, so without it every style's
draws last about as long as neutral steps, however long the style's steps are (Bandai validation clips: masculine
real steps 0.62 s, its draws 0.48 s). ``style_duration_weight`` = γ > 0 adds γ · (mean standardized log-duration of
the style term's decodes − the examples' mean, standardized alike)²: the draws' mean duration moves to the examples',
their spread around it stays the model's. Against the reconstruction's per-item duration weight w
(``duration_weight``), the mean moves about γ / (γ + w/2) of the way.

One model per (primitive, style). The style, the example clip(s) (take, frame range, primitive,
duration) and how they were encoded are recorded in ``hparams.spec``; the target Gram matrix is a
buffer, so the checkpoint is self-contained.
"""

from __future__ import annotations

from typing import Any

import torch

from stylemotion.models.autoencoder import IncompatibleModelError
from stylemotion.models.contact_loss import (
    contact_runs,
    contact_velocity_loss,
    midstance_loss,
    own_contacts,
    timeline_contacts,
)
from stylemotion.models.style import GRAM_NORMALIZATIONS, feature_style_distance, gram_factor, mean_gram
from stylemotion.models.vae import PrimitiveVAE
from stylemotion.representation import VELOCITY_DIMS, YAW_RATE_DIM

#: Which latent codes the style term decodes (see :class:`StyleCVAE`).
STYLE_LATENTS = ("posterior", "prior", "both")
#: How the style distance enters the loss (see :class:`StyleCVAE`).
STYLE_TERMS = ("distance", "margin")
#: Which motion channels the style term's Gram sees (see :class:`StyleCVAE`).
STYLE_CHANNELS = ("all", "pose")
#: Where the draws' contact term holds the feet (see :class:`StyleCVAE`).
SAMPLE_CONTACTS = ("own", "content")
#: Share of content clips in contact above which a timeline frame is in the contact template (a majority).
CONTENT_CONTACT_MAJORITY = 0.5


class StyleCVAE(PrimitiveVAE):
    """:class:`PrimitiveVAE` plus α·(Gram-matrix distance to a style example); logs ``style``
    (the mean distance, before α) per split.

    Args:
        style_weight: α (5; the thesis uses 200, see the module doc).
        style_latents: ``posterior``, ``prior`` or ``both`` (see the module doc).
        style_term, style_margin, style_centred: see the module doc.
        gram_normalization: ``mean`` (÷ T) or ``sum`` (eq. 5.9 as written).
        style_channels: ``all`` or ``pose`` (root velocity and yaw rate left out, :func:`pose_features`).
        style_subset: the style term's mean over a random this many decodes per step (0 = all).
        sample_contact_weight: β of the draws' foot-contact velocity loss (m²/s²; 0 = off; see the module doc).
        sample_contacts: where that loss holds the draws' feet: ``own`` (the contacts each draw plants) or
            ``content`` (the primitive's contact template from the content clips).
        style_duration_weight: γ of the styled duration term (dimensionless; 0 = off; see the module doc).
        **kwargs: :class:`PrimitiveVAE` arguments.
    """

    def __init__(self, style_weight: float = 5.0, style_latents: str = "prior", style_term: str = "distance",
                 style_margin: float = 1.0, style_centred: bool = False, gram_normalization: str = "mean",
                 style_channels: str = "all", style_subset: int = 0, sample_contact_weight: float = 0.0,
                 sample_contacts: str = "own", style_duration_weight: float = 0.0, **kwargs: Any):
        super().__init__(**kwargs)
        if not style_weight >= 0:
            raise ValueError(f"style_weight must be ≥ 0, got {style_weight}")
        if style_latents not in STYLE_LATENTS:
            raise ValueError(f"style_latents must be one of {STYLE_LATENTS}, got {style_latents!r}")
        if style_term not in STYLE_TERMS:
            raise ValueError(f"style_term must be one of {STYLE_TERMS}, got {style_term!r}")
        if not style_margin > 0:
            raise ValueError(f"style_margin must be > 0, got {style_margin}")
        if gram_normalization not in GRAM_NORMALIZATIONS:
            raise ValueError(f"gram_normalization must be one of {GRAM_NORMALIZATIONS}, got {gram_normalization!r}")
        if style_channels not in STYLE_CHANNELS:
            raise ValueError(f"style_channels must be one of {STYLE_CHANNELS}, got {style_channels!r}")
        if isinstance(style_subset, bool) or int(style_subset) != style_subset or style_subset < 0:
            raise ValueError(f"style_subset must be an integer ≥ 0 (0 = every decode), got {style_subset!r}")
        if not sample_contact_weight >= 0:
            raise ValueError(f"sample_contact_weight must be ≥ 0, got {sample_contact_weight}")
        if sample_contacts not in SAMPLE_CONTACTS:
            raise ValueError(f"sample_contacts must be one of {SAMPLE_CONTACTS}, got {sample_contacts!r}")
        if not style_duration_weight >= 0:
            raise ValueError(f"style_duration_weight must be ≥ 0, got {style_duration_weight}")
        self.save_hyperparameters({**dict(self.hparams), "style_weight": float(style_weight),
                                   "style_latents": str(style_latents), "style_term": str(style_term),
                                   "style_margin": float(style_margin), "style_centred": bool(style_centred),
                                   "gram_normalization": str(gram_normalization),
                                   "style_channels": str(style_channels), "style_subset": int(style_subset),
                                   "sample_contact_weight": float(sample_contact_weight),
                                   "sample_contacts": str(sample_contacts),
                                   "style_duration_weight": float(style_duration_weight)})

    def _build(self, spec: dict[str, Any]) -> None:
        super()._build(spec)
        channels = int(spec["feature_channels"])
        self.register_buffer("style_gram", torch.zeros(channels, channels))
        #: median Gram distance of the content (neutral) training clips to their mean Gram
        self.register_buffer("content_spread", torch.tensor(float("nan")))
        #: ``(L, 2)`` share of the content training clips with each foot in contact at each timeline frame
        self.register_buffer("content_contacts", torch.zeros(int(spec["timeline_frames"]), 2))
        #: mean log-duration of the style example clips (log seconds; NaN: not known)
        self.register_buffer("style_log_duration", torch.tensor(float("nan")))

    def _adapt_spec(self, spec: dict[str, Any]) -> dict[str, Any]:
        if not spec.get("style"):
            raise ValueError("StyleCVAE needs a style: set style=<name> (the datamodule's style), e.g. "
                             "'stylemotion-train experiment=style_cvae style=elderly'")
        return dict(spec)

    def _check_spec(self, spec: dict[str, Any]) -> None:
        super()._check_spec(spec)
        if spec.get("style") != self.spec.get("style"):
            raise IncompatibleModelError(f"this StyleCVAE models style {self.spec.get('style')!r}, the data "
                                         f"selects style {spec.get('style')!r}")

    def _install_stats(self, datamodule) -> None:
        super()._install_stats(datamodule)
        if not datamodule.style_features:
            raise ValueError(f"the datamodule has no style example for style {datamodule.style!r}")
        if self.style_channels == "pose":  # the pose-only features need the autoencoder now
            self.attach_autoencoder(datamodule.autoencoder)
        with torch.no_grad():
            self.style_gram.copy_(mean_gram([self._style_features(f) for f in datamodule.style_features],
                                            self.gram_normalization))
            durations = torch.tensor([float(e["duration_s"]) for e in datamodule.style_examples], dtype=torch.float64)
            self.style_log_duration.fill_(float(durations.log().mean()))
            train = datamodule.datasets["train"]
            self.content_spread.fill_(content_spread(self._style_features(train.features), self.gram_normalization))
            if self.hparams.get("sample_contacts", "own") == "content":
                self.content_contacts.copy_(timeline_contacts(train.positions, train.num_frames, self.fps,
                                                              self.timeline_frames).float().mean(0))

    @property
    def gram_normalization(self) -> str:
        return str(self.hparams.get("gram_normalization", "mean"))

    @property
    def style_channels(self) -> str:
        return str(self.hparams.get("style_channels", "all"))

    @property
    def plain_gram(self) -> bool:
        """Whether :attr:`style_gram` is the plain Gram of eq. 5.12 (÷ T, every channel, not centred), the one
        Table 5.1 recomputes from the example."""
        return (not self.hparams.get("style_centred", False) and self.gram_normalization == "mean"
                and self.style_channels == "all")

    def _style_features(self, features: torch.Tensor) -> torch.Tensor:
        """The features ``(..., C, T')`` the style term's Gram is taken of: as they are (the thesis), pose-only
        (``style_channels=pose``, :func:`pose_features`), and/or centred over time (``style_centred``: a
        covariance, blind to each channel's mean over the clip)."""
        if self.style_channels == "pose":
            features = pose_features(self.autoencoder, features)
        if self.hparams.get("style_centred", False):
            return features - features.mean(-1, keepdim=True)
        return features

    def on_load_checkpoint(self, checkpoint: dict[str, Any]) -> None:
        super().on_load_checkpoint(checkpoint)
        # checkpoints from before the margin term have no content_spread (their loss never used it)
        state = checkpoint.get("state_dict", {})
        state.setdefault("content_spread", torch.tensor(float("nan")))
        # checkpoints from before the contact template have none (their loss never used it)
        if "content_contacts" not in state:
            state["content_contacts"] = torch.zeros(int(checkpoint["hyper_parameters"]["spec"]["timeline_frames"]), 2)
        # checkpoints from before the styled duration have no example duration (their loss never used it)
        state.setdefault("style_log_duration", torch.tensor(float("nan")))

    @property
    def style_radius(self) -> float:
        """τ = ``style_margin`` × :attr:`content_spread`: the distance to the example under which the
        margin term is zero (Gram units)."""
        return float(self.hparams.style_margin * self.content_spread)

    @property
    def style(self) -> str:
        return self.spec["style"]

    @property
    def style_examples(self) -> list[dict[str, Any]]:
        """The example clips the style came from (take, start, stop, primitive, duration, …)."""
        return list(self.spec["style_examples"])

    def style_distance(self, features: torch.Tensor) -> torch.Tensor:
        """``‖Gram(features) − Gram(style example)‖_F`` for raw features ``(..., C, T')`` → ``(...)``."""
        version = (self.style_gram._version, self.style_gram.device, self.style_gram.data_ptr())
        if getattr(self, "_factor_key", None) != version:  # the factor of the (fixed) target, cached
            object.__setattr__(self, "_factor", gram_factor(self.style_gram))
            object.__setattr__(self, "_factor_key", version)
        return feature_style_distance(self._style_features(features), target_factor=self._factor,
                                      normalization=self.gram_normalization)

    def _extra_losses(self, recon: torch.Tensor, generator: torch.Generator | None = None
                      ) -> dict[str, tuple[torch.Tensor, float]]:
        outputs = []
        if self.hparams.style_latents in ("posterior", "both"):
            outputs.append(recon.flatten(0, 1))
        if self.hparams.style_latents in ("prior", "both"):
            count = recon.shape[0] * recon.shape[1]
            z = torch.randn(count, self.hparams.latent_dim, generator=generator, device=recon.device, dtype=recon.dtype)
            outputs.append(self.net.decode(z))
        decoded = torch.cat(outputs)
        subset = int(self.hparams.get("style_subset", 0))
        if 0 < subset < decoded.shape[0]:  # a random subset of the decodes (module doc)
            decoded = decoded[torch.randperm(decoded.shape[0], generator=generator, device=decoded.device)[:subset]]
        features, duration = self.denormalize(decoded)  # the clamp acts on the duration only
        distance = self.style_distance(features)
        if self.hparams.style_term == "margin":  # the distance is logged, the excess optimized
            terms = {"style": (distance.mean(), 0.0),
                     "style_excess": (margin_excess(distance, self.style_radius), self.hparams.style_weight)}
        else:
            terms = {"style": (distance.mean(), self.hparams.style_weight)}
        weight = float(self.hparams.get("sample_contact_weight", 0.0))
        if weight > 0:
            terms["sample_contact"] = (self.sample_contact_term(features, duration), weight)
        gamma = float(self.hparams.get("style_duration_weight", 0.0))
        if gamma > 0:
            terms["style_duration"] = (self.style_duration_term(decoded[..., -1]), gamma)
        return terms

    def style_duration_term(self, standardized_log_duration: torch.Tensor) -> torch.Tensor:
        """``(mean of the draws' standardized log-durations (n,) − the examples' mean, standardized alike)²``
        (dimensionless; the module doc's styled duration)."""
        target = (self.style_log_duration - self.duration_stats[0]) / self.duration_stats[1]
        return (standardized_log_duration.mean() - target.to(standardized_log_duration)).square()

    def sample_contact_term(self, features: torch.Tensor, duration_s: torch.Tensor) -> torch.Tensor:
        """The foot-contact velocity loss of draws on their own contacts or the content template (module doc).

        Args:
            features: ``(n, C, T')`` raw features of decoded draws (differentiable).
            duration_s: ``(n,)`` their decoded durations, seconds (not differentiated).

        Returns:
            Scalar, m²/s² (:func:`~stylemotion.models.contact_loss.contact_velocity_loss`).
        """
        length = self.timeline_frames
        frames = self.autoencoder.decode(features, length).float()  # (n, L, 66)
        rate = (length - 1) / duration_s.detach().to(frames)  # playback fps of the timeline
        if self.hparams.get("sample_contacts", "own") == "content":
            template = content_contact_template(self.content_contacts)
            return (contact_velocity_loss(frames, template.expand(frames.shape[0], -1, -1), rate)
                    + midstance_loss(frames, contact_runs(template), rate))
        return contact_velocity_loss(frames, own_contacts(frames, rate), rate)


def content_contact_template(shares: torch.Tensor) -> torch.Tensor:
    """The contact template ``(L, 2)`` bool of contact shares ``(L, 2)``: frames where more than
    :data:`CONTENT_CONTACT_MAJORITY` of the content clips have the foot in contact."""
    return shares > CONTENT_CONTACT_MAJORITY


def content_spread(features: torch.Tensor, normalization: str = "mean") -> float:
    """Median Gram distance of feature sequences ``(n, C, T')`` to their mean Gram: how far the clips of
    one style (the content data) typically sit from its centre, in Gram units (``normalization``: see
    :func:`stylemotion.models.style.gram`)."""
    centre = mean_gram(list(features), normalization)
    return float(feature_style_distance(features, centre, normalization=normalization).median())


def pose_features(autoencoder, features: torch.Tensor) -> torch.Tensor:
    """Pose-only features ``(..., C, T')`` of raw features ``(..., C, T')``: decoded by the autoencoder to its
    z-scored frames, the root ground velocity and yaw rate set to 0 (their data mean), encoded again — as if the
    encoder had no weights for those channels. Differentiable in ``features`` (the autoencoder stays frozen)."""
    net = autoencoder.net
    frames = net.decode_normalized(features)  # (..., 2T', 66) z-scores
    keep = torch.ones(frames.shape[-1], dtype=frames.dtype, device=frames.device)
    keep[VELOCITY_DIMS] = 0
    keep[YAW_RATE_DIM] = 0
    return net.encode_normalized(frames * keep)


def margin_excess(distance: torch.Tensor, radius: float) -> torch.Tensor:
    """``mean (max(0, d − τ) / τ)²``: the squared relative excess of style distances ``(n,)`` over the
    radius τ — zero inside the ball, dimensionless (the same for any Gram scale)."""
    return ((distance - radius).clamp_min(0) / radius).square().mean()
