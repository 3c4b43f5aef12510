"""Subsequence DTW of a motion template against a long document (Müller 2007, the ``Δ_C`` of Krüger §3.2.2).

The template (``m`` frames) is aligned as a whole, the document (``L`` frames) as a free subsequence, with
the step sizes ``(1, 1)``, ``(2, 1)`` and ``(1, 2)`` (template, document) of Müller's motion-template
matching, which bound the local tempo to between half and twice the template's. ``Δ(ℓ)`` is the cost of the
best path ending at document frame ``ℓ``, divided by ``m``; ``start(ℓ)`` is its first document frame. Without
vertical or horizontal steps every row depends only on the two rows before it at shifted columns, so the
recursion is vectorized over the document (time ``O(m L)``, memory two rows of starts and costs).
"""

from __future__ import annotations

import numpy as np


def subsequence_dtw(cost: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(Δ, start)`` for a ``(m, L)`` local cost matrix: ``Δ`` ``(L,)`` float64 (``inf`` where no path ends),
    ``start`` ``(L,)`` int64 (-1 where none)."""
    c = np.asarray(cost, dtype=np.float64)
    if c.ndim != 2 or c.shape[0] < 1 or c.shape[1] < 1:
        raise ValueError(f"cost must be a non-empty (template frames, document frames) matrix, got {c.shape}")
    m, n = c.shape
    inf = np.inf
    prev2 = np.full(n, inf)
    prev2_start = np.full(n, -1, dtype=np.int64)
    prev = c[0].copy()                                         # free start anywhere in the document
    prev_start = np.arange(n, dtype=np.int64)
    for i in range(1, m):
        # candidates for cell (i, j): (i-1, j-1), (i-2, j-1), (i-1, j-2)
        cand = np.full((3, n), inf)
        starts = np.full((3, n), -1, dtype=np.int64)
        cand[0, 1:], starts[0, 1:] = prev[:-1], prev_start[:-1]
        cand[1, 1:], starts[1, 1:] = prev2[:-1], prev2_start[:-1]
        cand[2, 2:], starts[2, 2:] = prev[:-2], prev_start[:-2]
        best = np.argmin(cand, axis=0)
        cols = np.arange(n)
        row = c[i] + cand[best, cols]
        row_start = np.where(np.isfinite(row), starts[best, cols], -1)
        prev2, prev2_start, prev, prev_start = prev, prev_start, row, row_start
    return prev / m, prev_start
