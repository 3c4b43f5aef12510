"""Subsequence DTW of a motion template against a long document (Müller 2007, the ``Δ_C`` of Krüger §3.2.2).

The template (``m`` frames) is aligned as a whole, the document (``L`` frames) as a free subsequence, with
the step sizes ``(1, 1)``, ``(2, 1)`` and ``(1, 2)`` (template, document) of Müller's motion-template
matching, which bound the local tempo to between half and twice the template's. ``Δ(ℓ)`` is the cost of the
best path ending at document frame ``ℓ``, divided by ``m``; ``start(ℓ)`` is its first document frame.

The one subsequence DTW of the package is :func:`stylemotion.search.dtw.subsequence_dtw`; this module only
fixes its steps, normalization and (free) skipped template frames for annotation.
"""

from __future__ import annotations

import numpy as np

from stylemotion.search.dtw import subsequence_dtw as _general_subsequence_dtw

# (template frames, document frames) per step: Müller's motion-template steps
TEMPLATE_STEPS: tuple[tuple[int, int], ...] = ((1, 1), (2, 1), (1, 2))


def subsequence_dtw(cost: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(Δ, start)`` for a ``(m, L)`` local cost matrix (finite, ≥ 0): ``Δ`` ``(L,)`` float64 (``inf`` where no
    path ends), ``start`` ``(L,)`` int64 (-1 where none).

    A ``(2, 1)`` step skips a template frame at no cost (``skip_cost=0``), ``Δ`` is the path's sum divided
    by ``m`` (``normalize="query"``), and of equal-cost predecessors the first of least sum is taken
    (``ties="predecessor"``), the exact argmin this module has always used."""
    result = _general_subsequence_dtw(cost, steps=TEMPLATE_STEPS, normalize="query", skip_cost=0.0,
                                      ties="predecessor")
    return result.end_costs, result.end_starts
