"""Clips a Morphable Graph primitive was not fitted to, encoded like its training clips: the held-out coefficient
vectors and the joint-space error of their reconstructions (used by SFPCA's validation choice in
:func:`~stylemotion.morphable.model.fit_primitive` and by :mod:`stylemotion.morphable.heldout`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from stylemotion.morphable.bspline import SplineBasis
from stylemotion.morphable.warping import dtw_warp, resample
from stylemotion.representation import JOINT_DIMS

if TYPE_CHECKING:
    from stylemotion.primitives.segmentation import Clip

#: A :class:`~stylemotion.morphable.model.FunctionalData` (``channels``, ``length``, ``fps``); not imported, since the
#: model module imports this one.
FunctionalData = Any

__all__ = ["HeldOutVectors", "encode_heldout", "heldout_error_function"]


@dataclass
class HeldOutVectors:
    """Coefficient vectors of clips not used to fit, on the training data's canonical timeline.

    Attributes:
        vectors: ``(n, (C + 1) K)`` spline coefficients (spatial channels, then the warp), as
            :func:`~stylemotion.morphable.model.coefficient_vectors`.
        playback_fps: ``(n,)`` rate at which the canonical timeline lasts each clip's duration.
    """

    vectors: np.ndarray
    playback_fps: np.ndarray


def encode_heldout(data: FunctionalData, reference: Clip, basis: SplineBasis, clips: Sequence[Clip]) -> HeldOutVectors:
    """``clips`` aligned by DTW to ``reference`` (the training reference clip, ``train[data.reference]``) and
    encoded with the training channels and ``basis``."""
    if not clips:
        raise ValueError("no held-out clip to encode")
    ref = reference.frames[:, JOINT_DIMS]
    vectors, rates = [], []
    for clip in clips:
        warp = dtw_warp(ref, clip.frames[:, JOINT_DIMS])
        aligned = resample(data.channels.encode(clip.positions, clip.frames), warp)
        vectors.append(np.concatenate([basis.fit(aligned), basis.fit(warp[:, None])], axis=0).ravel())
        rates.append((data.length - 1) * data.fps / warp[-1])
    return HeldOutVectors(np.stack(vectors), np.asarray(rates, dtype=np.float64))


def heldout_error_function(data: FunctionalData, basis: SplineBasis, held: HeldOutVectors):
    """Reconstructed held-out vectors ``(n, D)`` → mean squared joint distance (m²) to FK of their own spline
    fit (eq. 3.8's error on clips the reduction never saw); with ``per_clip=True`` the ``(n,)`` means per clip."""
    size = data.channels.size + 1

    def positions(vecs: np.ndarray) -> np.ndarray:
        spatial = vecs.reshape(len(vecs), size, basis.num_coefficients)[:, :-1]
        return data.channels.positions(basis.evaluate(spatial, data.length), held.playback_fps)

    target = positions(held.vectors)

    def error(reconstructed: np.ndarray, per_clip: bool = False) -> float | np.ndarray:
        squared = ((positions(reconstructed) - target) ** 2).sum(-1)
        return squared.reshape(len(squared), -1).mean(1) if per_clip else float(squared.mean())

    return error
