"""Time warping of a class's example motions onto a reference (Krüger §4.1.3).

Two warpings bring an example onto the reference timeline; both return the warping function ``w`` ``(f,)``: the
example's fractional frame shown at reference frame ``i`` (the mean example frame the DTW path matches to ``i``,
made monotone by :func:`stylemotion.morphable.warping.monotone`, from 0 to the example's last frame):

* ``"pose"``: plain DTW on root-local joint coordinates (:func:`stylemotion.morphable.warping.dtw_warp`,
  dtaidistance), the warping the annotation tensors and the Morphable Graph use;
* ``"physics"``: the thesis' multiscale DTW on physics-based features (:mod:`.physics`) with the cost
  ``c(v, w) = 1 − ⟨v, w⟩ / (‖v‖ ‖w‖)`` (eq. 4.3; 0 where a vector is zero). The features are averaged over
  windows of 2 frames per level (``levels`` resolutions: at 30 fps, 4 levels reach 3.75 Hz; the thesis used 6
  from 120 Hz to 4 Hz); the coarsest level is warped in full, and each finer level only inside the cells the
  coarser path covers, widened by ``radius`` cells (Zhang & Müller's iterative multiscale DTW, [ZM06]).

The DTW itself (:func:`banded_dtw`) is global (both ends matched), with the steps (1, 0), (0, 1), (1, 1) of
weight 1, evaluated row by row inside a band ``[lo_i, hi_i)``: with ``A_j = min(D[i−1, j−1], D[i−1, j])`` a row
is ``D[i, j] = C_j + min_{k ≤ j} (A_k − C_{k−1})``, ``C`` the row's cumulative cost (a running minimum: one
numpy pass per row). The project's subsequence DTW (:mod:`stylemotion.search.dtw`) frees the path's start and
end in the database, so it does not serve a global alignment.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np

from stylemotion.morphable.warping import dtw_warp, monotone, resample
from stylemotion.multilinear.physics import LOCOMOTION_SEGMENTS, balanced, physics_features
from stylemotion.representation import positions_to_frames
from stylemotion.skeleton import NUM_JOINTS

Method = Literal["physics", "pose"]
METHODS: tuple[str, ...] = ("physics", "pose")


@dataclass(frozen=True)
class Alignment:
    """A global DTW result: ``path`` ``(k, 2)`` index pairs (reference frame, example frame) from ``(0, 0)`` to
    ``(n − 1, m − 1)``; ``cost`` the summed local cost along it; ``cells`` the cost cells evaluated (all levels)."""

    path: np.ndarray
    cost: float
    cells: int


def cosine_cost(v: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Eq. 4.3: ``(n, m)`` costs ``1 − cos∠(v_i, w_j)`` in ``[0, 2]`` of features ``(n, d)`` and ``(m, d)``; 0 where
    either vector is zero."""
    v, w = np.asarray(v, dtype=np.float64), np.asarray(w, dtype=np.float64)
    nv, nw = np.linalg.norm(v, axis=1), np.linalg.norm(w, axis=1)
    cos = (v @ w.T) / np.maximum(np.outer(nv, nw), 1e-300)
    return np.where(np.outer(nv > 0, nw > 0), 1.0 - cos, 0.0)


def banded_dtw(row_cost: Callable[[int, int, int], np.ndarray], n: int, m: int,
               lo: np.ndarray | None = None, hi: np.ndarray | None = None) -> Alignment:
    """Global DTW of an ``n × m`` cost matrix given row by row: ``row_cost(i, a, b)`` returns the costs of row
    ``i``, columns ``a ≤ j < b`` (≥ 0). Only cells with ``lo[i] ≤ j < hi[i]`` are evaluated (default: all);
    the band must hold ``(0, 0)`` and ``(n − 1, m − 1)`` and let every row reach the next. Ties prefer the
    diagonal, then the step from the row above."""
    lo = np.zeros(n, dtype=int) if lo is None else np.asarray(lo, dtype=int)
    hi = np.full(n, m, dtype=int) if hi is None else np.asarray(hi, dtype=int)
    if lo[0] != 0 or hi[-1] != m or np.any(hi <= lo):
        raise ValueError("the band must start at (0, 0), end at (n − 1, m − 1) and hold a cell in every row")
    acc = np.full((n, m), np.inf)
    cells = 0
    for i in range(n):
        a, b = int(lo[i]), int(hi[i])
        c = np.asarray(row_cost(i, a, b), dtype=np.float64)
        cells += b - a
        if i == 0:
            entry = np.full(b - a, np.inf)
            entry[0] = 0.0
        else:
            above = acc[i - 1, a:b]
            diagonal = acc[i - 1, a - 1:b - 1] if a > 0 else np.concatenate([[np.inf], acc[i - 1, :b - 1]])
            entry = np.minimum(above, diagonal)
        csum = np.cumsum(c)
        acc[i, a:b] = csum + np.minimum.accumulate(entry - (csum - c))
    if not np.isfinite(acc[-1, -1]):
        raise ValueError("the band leaves no path from (0, 0) to (n − 1, m − 1)")
    return Alignment(_backtrack(acc), float(acc[-1, -1]), cells)


def _backtrack(acc: np.ndarray) -> np.ndarray:
    i, j = acc.shape[0] - 1, acc.shape[1] - 1
    path = [(i, j)]
    while i > 0 or j > 0:
        if i == 0:
            j -= 1
        elif j == 0:
            i -= 1
        else:
            options = (acc[i - 1, j - 1], acc[i - 1, j], acc[i, j - 1])
            k = int(np.argmin(options))
            i, j = (i - 1, j - 1) if k == 0 else (i - 1, j) if k == 1 else (i, j - 1)
        path.append((i, j))
    return np.asarray(path[::-1], dtype=int)


def full_dtw(v: np.ndarray, w: np.ndarray) -> Alignment:
    """Plain (one-scale) DTW of features ``(n, d)`` and ``(m, d)`` under the cosine cost (eq. 4.3)."""
    return banded_dtw(lambda i, a, b: cosine_cost(v[i:i + 1], w[a:b])[0], len(v), len(w))


def coarsen(x: np.ndarray) -> np.ndarray:
    """``(ceil(n / 2), d)``: the means of windows of 2 frames (the last one alone when ``n`` is odd)."""
    n = x.shape[0]
    pad = np.concatenate([x, x[-1:]]) if n % 2 else x
    return 0.5 * (pad[0::2] + pad[1::2])


def project_band(path: np.ndarray, n: int, m: int, radius: int) -> tuple[np.ndarray, np.ndarray]:
    """The band ``(lo, hi)`` ``(n,)`` at the finer level of a coarse ``path``: each coarse cell covers its 2 × 2
    fine cells; every fine row's span is widened to the rows within ``radius`` and by ``radius`` columns."""
    lo, hi = np.full(n, m, dtype=int), np.zeros(n, dtype=int)
    for ci, cj in path:
        for i in (2 * ci, 2 * ci + 1):
            if i < n:
                lo[i] = min(lo[i], 2 * cj)
                hi[i] = max(hi[i], min(2 * cj + 2, m))
    wide_lo, wide_hi = lo.copy(), hi.copy()
    for i in range(n):
        a, b = max(0, i - radius), min(n, i + radius + 1)
        wide_lo[i] = max(0, lo[a:b].min() - radius)
        wide_hi[i] = min(m, hi[a:b].max() + radius)
    return wide_lo, wide_hi


def multiscale_dtw(v: np.ndarray, w: np.ndarray, levels: int = 4, radius: int = 2) -> Alignment:
    """Iterative multiscale DTW of features ``(n, d)`` and ``(m, d)`` (cosine cost): ``levels`` resolutions
    (1: plain DTW, :func:`full_dtw`), each coarser one half the frames; coarsening stops early below 4 frames.
    ``cells`` counts every level's evaluated cells."""
    if levels < 1 or radius < 0:
        raise ValueError(f"levels must be ≥ 1 and radius ≥ 0, got {levels}, {radius}")
    pyramid = [(np.asarray(v, dtype=np.float64), np.asarray(w, dtype=np.float64))]
    while len(pyramid) < levels and min(len(pyramid[-1][0]), len(pyramid[-1][1])) >= 8:
        pyramid.append((coarsen(pyramid[-1][0]), coarsen(pyramid[-1][1])))
    a, b = pyramid[-1]
    result = full_dtw(a, b)
    cells = result.cells
    for a, b in reversed(pyramid[:-1]):
        lo, hi = project_band(result.path, len(a), len(b), radius)
        result = banded_dtw(lambda i, s, e, a=a, b=b: cosine_cost(a[i:i + 1], b[s:e])[0], len(a), len(b), lo, hi)
        cells += result.cells
    return Alignment(result.path, result.cost, cells)


def path_to_warp(path: np.ndarray, n: int, m: int) -> np.ndarray:
    """``(n,)`` warping function from a global path: each reference frame's mean matched example frame, monotone,
    from 0 to ``m − 1``."""
    sums = np.bincount(path[:, 0], weights=path[:, 1], minlength=n)
    counts = np.bincount(path[:, 0], minlength=n)
    return monotone(sums / np.maximum(counts, 1), last=m - 1)


def warp_function(reference: np.ndarray, example: np.ndarray, fps: float, method: Method = "physics",
                  levels: int = 4, radius: int = 2) -> tuple[np.ndarray, int]:
    """``(w, cells)``: the warping function ``(f,)`` of ``example`` ``(m, 21, 3)`` onto ``reference``
    ``(f, 21, 3)`` (metres, at ``fps``) by ``method``, and the DTW cost cells evaluated."""
    if method not in METHODS:
        raise ValueError(f"warping method must be one of {METHODS}, got {method!r}")
    f, m = len(reference), len(example)
    if method == "pose":
        pose = [positions_to_frames(p, fps)[0][:, :NUM_JOINTS * 3] for p in (reference, example)]
        return dtw_warp(pose[0], pose[1]), f * m
    feats = [balanced(physics_features(p, fps, LOCOMOTION_SEGMENTS)) for p in (reference, example)]
    alignment = multiscale_dtw(feats[0], feats[1], levels, radius)
    return path_to_warp(alignment.path, f, m), alignment.cells


def warp_positions(positions: np.ndarray, warp: np.ndarray) -> np.ndarray:
    """``(len(warp), 21, 3)``: ``positions`` ``(m, 21, 3)`` linearly interpolated at the fractional frames
    ``warp``."""
    p = np.asarray(positions, dtype=np.float64)
    return resample(p.reshape(len(p), -1), warp).reshape(len(warp), *p.shape[1:])
