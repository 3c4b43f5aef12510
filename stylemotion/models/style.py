"""Gram-matrix style of autoencoder features (thesis §5.3.3, eq. 5.9–5.10 and 5.12).

The single source of truth for the style measure: training (:class:`~stylemotion.models.cvae.StyleCVAE`),
evaluation (Table 5.1) and synthesis all call these functions.

Features are the motion autoencoder's ``encode`` output, ``(..., channels, time)`` (256 channels,
half the frame count). The Gram matrix is taken over the temporal axis and **normalized by the
number of time steps**::

    Gram(Y) = (1 / T) · Σ_t y_t y_tᵀ          (channels × channels)

The thesis (eq. 5.9) writes the plain sum. Dividing by ``T`` makes the Gram matrices of clips of
different lengths comparable (a two-step example is not "twice as stylish" as a one-step one), which
the thesis relies on when it says the Gram needs no frame alignment; it only rescales the loss
weight α for clips of one fixed length. Several examples are combined by averaging their Gram
matrices (:func:`mean_gram`), i.e. each example counts equally whatever its length.

The style distance is the Frobenius norm ``‖G₁ − G₂‖_F`` (not squared), as in eq. 5.10.

``normalization="sum"`` (the style CVAE's ``gram_normalization``, preset ``experiment=style_cvae_thesis``) takes
eq. 5.9 as written, ``Σ_t y_t y_tᵀ``: ``T`` times the default; several examples still average their Gram matrices
(§5.4.1: "averaged by the calculation of gram matrix").
"""

from __future__ import annotations

from collections.abc import Sequence

import torch

#: How a Gram matrix is normalized over time: ``mean`` (÷ T, the default) or ``sum`` (eq. 5.9 as written).
GRAM_NORMALIZATIONS = ("mean", "sum")


def gram_divisor(steps: int, normalization: str = "mean") -> int:
    """What a Gram matrix of ``steps`` time steps is divided by: ``steps`` (``mean``) or 1 (``sum``)."""
    if normalization not in GRAM_NORMALIZATIONS:
        raise ValueError(f"Gram normalization must be one of {GRAM_NORMALIZATIONS}, got {normalization!r}")
    return int(steps) if normalization == "mean" else 1


def gram(features: torch.Tensor, normalization: str = "mean") -> torch.Tensor:
    """Gram matrix over time, normalized by the number of time steps (``normalization="sum"``: not normalized).

    Args:
        features: ``(..., channels, time)`` autoencoder features (any leading batch dims), time ≥ 1.
        normalization: ``mean`` or ``sum`` (:data:`GRAM_NORMALIZATIONS`).

    Returns:
        ``(..., channels, channels)``: ``features @ features.T / time`` (``sum``: ``features @ features.T``).
    """
    if features.dim() < 2:
        raise ValueError(f"features must be (..., channels, time), got shape {tuple(features.shape)}")
    steps = features.shape[-1]
    if steps < 1:
        raise ValueError("cannot take the Gram matrix of features with no time step")
    return features @ features.transpose(-1, -2) / gram_divisor(steps, normalization)


def mean_gram(examples: Sequence[torch.Tensor], normalization: str = "mean") -> torch.Tensor:
    """Average of the Gram matrices of several feature sequences of any lengths.

    Args:
        examples: feature tensors ``(channels, time_i)`` (or ``(1, channels, time_i)``).
        normalization: of each Gram matrix (see :func:`gram`).

    Returns:
        ``(channels, channels)``.
    """
    if not examples:
        raise ValueError("mean_gram needs at least one feature sequence")
    grams = [gram(e.reshape(e.shape[-2], e.shape[-1]), normalization) for e in examples]
    shapes = {tuple(g.shape) for g in grams}
    if len(shapes) != 1:
        raise ValueError(f"feature sequences have different channel counts: {sorted(shapes)}")
    return torch.stack(grams).mean(0)


def style_distance(gram_a: torch.Tensor, gram_b: torch.Tensor) -> torch.Tensor:
    """Frobenius norm ``‖G_a − G_b‖_F`` over the last two dims (broadcasting the leading ones).

    Args:
        gram_a, gram_b: ``(..., channels, channels)`` Gram matrices (see :func:`gram`).

    Returns:
        ``(...)`` distances (same units as the Gram entries: squared feature units).
    """
    return torch.linalg.matrix_norm(gram_a - gram_b, ord="fro")


def gram_factor(target_gram: torch.Tensor, rtol: float = 1e-7) -> torch.Tensor:
    """A factor ``W`` ``(channels, rank)`` with ``W Wᵀ = target_gram`` (a Gram matrix is positive
    semi-definite; eigenvalues below ``rtol`` × the largest are dropped). A Gram matrix of ``T``
    time steps has rank ≤ ``T``, so ``W`` is thin."""
    values, vectors = torch.linalg.eigh(target_gram.double())
    keep = values > rtol * values.max().clamp_min(torch.finfo(torch.float64).tiny)
    return (vectors[:, keep] * values[keep].sqrt()).to(target_gram.dtype)


def feature_style_distance(features: torch.Tensor, target_gram: torch.Tensor | None = None,
                           target_factor: torch.Tensor | None = None, normalization: str = "mean") -> torch.Tensor:
    """``style_distance(gram(features), target_gram)``: distance of feature sequences to a style.

    Computed without forming a ``channels × channels`` matrix per sequence (the training loss
    evaluates it for thousands of decoded samples per step), from the identity, with
    ``F = features``, ``S = target_gram = W Wᵀ`` (:func:`gram_factor`) and ``T`` time steps::

        ‖FFᵀ/T − S‖²_F = ‖FᵀF‖²_F / T² − 2 ‖WᵀF‖²_F / T + ‖WᵀW‖²_F

    which costs ``O(channels · T · (T + rank))`` per sequence instead of ``O(channels² · T)``.
    Equal to the direct formula up to float rounding (relative to ``‖S‖²``); distances that
    round below 1e-6 of ``‖S‖_F`` are reported as that floor, with zero gradient.

    Args:
        features: ``(..., channels, time)``.
        target_gram: ``(channels, channels)``; or give its factor ``target_factor`` ``(channels, rank)``
            (e.g. cached by a model) instead. A factor with leading dims ``(..., channels, rank)`` gives one
            target per sequence (broadcast against the features' leading dims), e.g. the features of each
            sequence's own example scaled by ``1/sqrt(time)``.
        normalization: of the features' Gram matrices (:func:`gram`; ``sum``: ``T`` reads 1 above).

    Returns:
        ``(...)``.
    """
    if target_factor is None:
        if target_gram is None:
            raise ValueError("give target_gram or target_factor")
        target_factor = gram_factor(target_gram)
    # float64: the three terms are each ~‖S‖² and cancel near the target; in float32 the rounding of
    # the products alone leaves ~1e-3·‖S‖ of spurious distance (BLAS-dependent). The extra cost is small
    # (channels · T · (T + rank) per sequence).
    dtype = features.dtype
    features = features.double()
    target_factor = target_factor.to(features)
    steps = gram_divisor(features.shape[-1], normalization)
    ff = features.transpose(-1, -2) @ features  # (..., T, T)
    wf = target_factor.transpose(-1, -2) @ features  # (..., rank, T)
    ww = target_factor.transpose(-1, -2) @ target_factor
    target_sq = ww.square().sum((-1, -2))
    squared = ff.square().sum((-1, -2)) / steps**2 - 2 * wf.square().sum((-1, -2)) / steps + target_sq
    return squared.clamp_min(1e-12 * target_sq.clamp_min(1e-30)).sqrt().to(dtype)
