"""What the evaluation evaluates: anything that samples motions of a primitive, plus what it targets.

A :class:`SampleSource` has ``sample(n, seed) -> MotionSamples`` (:mod:`stylemotion.models.sampling`):
the trained :class:`~stylemotion.models.vae.PrimitiveVAE` and
:class:`~stylemotion.models.cvae.StyleCVAE` are sources, and so is :class:`RealClipSource`
(real clips drawn with replacement: an "oracle model" for tests and reference rows).
:class:`EvalModel` wraps a source with the primitive it models, the style it targets and the style
example it was conditioned on; :func:`load_model` makes one from a checkpoint. Those three and
:data:`NEUTRAL` live with the models (:mod:`stylemotion.models.loading`, the one loading path) and are
named here too, as the evaluation's inputs.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence

import numpy as np
import torch

from stylemotion.io.errors import UserInputError
from stylemotion.models.autoencoder import IncompatibleModelError
from stylemotion.models.loading import EvalModel
from stylemotion.models.sampling import MotionSamples, pad_motions
from stylemotion.primitives.segmentation import Clip, time_normalize


class MixedAutoencodersError(IncompatibleModelError):
    """Models of one evaluation were trained on features of different autoencoders."""


class MissingExampleError(UserInputError, ValueError):
    """A style model's example clip cannot be found (or does not match) in the evaluation data."""


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
