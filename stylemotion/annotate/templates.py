"""Class motion templates (Müller & Röder 2006; Krüger §3.2.1): the average of a class's feature matrices.

A template is a ``(frames, features)`` array of values in ``[0, 1]``: the fraction of a class's training
motions, after time warping, that have a relational feature on at that moment. It is learned by iterative
warping and averaging: start from the example closest to the average length, resampled to that length; then,
``iterations`` times, align every example to the current template by DTW (``dtaidistance``) and replace
each template frame by the mean of the example frames aligned to it (per example first, so every example
weighs the same). Entries at most ``delta`` from 0 or 1 are *consistent*: the quantized template keeps them
as 0/1 and leaves the rest as wildcards, ignored by the distance (:func:`local_cost`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from dtaidistance import dtw_ndim

from stylemotion.annotate.feature_sets import DEFAULT_FEATURE_SET
from stylemotion.io.errors import UserInputError
from stylemotion.morphable.warping import resample

#: Quantization threshold δ of the thesis (entries ≤ δ become 0, ≥ 1 − δ become 1, the rest wildcards).
DELTA = 0.05


class TemplateInputError(UserInputError, ValueError):
    """Examples a template cannot be learned from; the message names the class and the count or shape."""


@dataclass(frozen=True)
class MotionTemplate:
    """A class motion template.

    Attributes:
        label: the class (content) name.
        values: ``(frames, features)`` float in ``[0, 1]``.
        examples: number of training motions averaged.
        delta: quantization threshold.
        feature_set: the relational feature set of the columns (:mod:`.feature_sets`).
    """

    label: str
    values: np.ndarray
    examples: int
    delta: float = DELTA
    feature_set: str = DEFAULT_FEATURE_SET

    @property
    def num_frames(self) -> int:
        return int(self.values.shape[0])

    @property
    def mask(self) -> np.ndarray:
        """``(frames, features)`` bool: the consistent entries."""
        return (self.values <= self.delta) | (self.values >= 1.0 - self.delta)

    @property
    def quantized(self) -> np.ndarray:
        """``(frames, features)`` float: 0/1 at consistent entries, 0.5 at wildcards."""
        q = np.full_like(self.values, 0.5)
        q[self.values <= self.delta] = 0.0
        q[self.values >= 1.0 - self.delta] = 1.0
        return q


def resample_length(x: np.ndarray, length: int) -> np.ndarray:
    """Linear resampling of ``(frames, d)`` to ``(length, d)``."""
    return resample(x, np.linspace(0.0, x.shape[0] - 1.0, length))


def warp_to(reference: np.ndarray, example: np.ndarray) -> np.ndarray:
    """``example`` ``(n, d)`` warped onto the timeline of ``reference`` ``(m, d)`` by DTW (dtaidistance's C
    implementation): frame ``i`` of the result is the mean of the example frames aligned to reference frame
    ``i`` (for boolean features: the fraction that is on). Returns ``(m, d)`` float64."""
    reference = np.ascontiguousarray(reference, dtype=np.float64)
    example = np.ascontiguousarray(example, dtype=np.float64)
    path = np.asarray(dtw_ndim.warping_path(reference, example, use_c=True))
    sums = np.zeros((reference.shape[0], example.shape[1]))
    np.add.at(sums, path[:, 0], example[path[:, 1]])
    return sums / np.bincount(path[:, 0], minlength=reference.shape[0])[:, None]


def learn_template(label: str, examples: Sequence[np.ndarray], iterations: int = 4,
                   delta: float = DELTA, feature_set: str = DEFAULT_FEATURE_SET) -> MotionTemplate:
    """Learn the template of class ``label`` from its examples' feature matrices.

    Args:
        examples: ``γ ≥ 2`` arrays ``(frames_k, features)`` (bool or float in ``[0, 1]``).
        iterations: warping-and-averaging rounds.
        feature_set: the set the examples' features come from (recorded in the template).

    Raises:
        TemplateInputError: fewer than two examples, or examples of different feature counts.
    """
    if len(examples) < 2:
        raise TemplateInputError(f"class {label!r} has {len(examples)} example motion(s); a template needs at "
                                 f"least 2")
    xs = [np.asarray(x, dtype=np.float64) for x in examples]
    widths = {x.shape[1] if x.ndim == 2 else None for x in xs}
    if len(widths) != 1 or None in widths or any(x.shape[0] < 2 for x in xs):
        raise TemplateInputError(f"class {label!r}: examples must be (frames ≥ 2, features) with one feature "
                                 f"count, got shapes {[x.shape for x in xs][:5]}")
    length = int(round(np.mean([x.shape[0] for x in xs])))
    start = int(np.argmin([abs(x.shape[0] - length) for x in xs]))
    template = resample_length(xs[start], length)
    for _ in range(iterations):
        template = np.mean([warp_to(template, x) for x in xs], axis=0)
    return MotionTemplate(label, np.clip(template, 0.0, 1.0), len(xs), delta, feature_set)


def sub_templates(template: MotionTemplate, frames: int) -> list[MotionTemplate]:
    """Windows of ``frames`` template frames cut from ``template`` (§3.3's sub-templates ``M_p``), each a template
    of the same class: one every ``frames // 2`` frames from the first, and the last ending at the template's last
    frame. ``frames`` ≤ 0 or at least the template's length: the template itself."""
    n = template.num_frames
    if frames <= 0 or frames >= n:
        return [template]
    starts = list(range(0, n - frames + 1, max(frames // 2, 1)))
    if starts[-1] != n - frames:
        starts.append(n - frames)
    return [MotionTemplate(template.label, template.values[a:a + frames], template.examples, template.delta,
                           template.feature_set) for a in starts]


def local_cost(template: MotionTemplate, document: np.ndarray) -> np.ndarray:
    """Masked distance ``c(i, j)`` between template frame ``i`` and document frame ``j``: the fraction of the
    consistent entries of column ``i`` that the document's features contradict (0 where none is consistent).

    Args:
        document: ``(frames, features)`` bool features.

    Returns:
        ``(template frames, document frames)`` float64 in ``[0, 1]``.
    """
    d = np.asarray(document, dtype=np.float64)
    mask = template.mask.astype(np.float64)
    ones = mask * (template.quantized == 1.0)                  # consistent entries that must be on
    # |q − d| summed over consistent entries: Σ ones·(1 − d) + Σ (mask − ones)·d
    mismatches = ones.sum(1)[:, None] - ones @ d.T + (mask - ones) @ d.T
    count = mask.sum(1)[:, None]
    return np.where(count > 0, mismatches / np.maximum(count, 1.0), 0.0)
