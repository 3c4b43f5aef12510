"""Subsequence dynamic time warping (Müller 2007, [Mül07] in Krüger's thesis §2.4): the reference the lazy
neighbourhood graph (:mod:`stylemotion.search.lng`) is validated against.

The query (``m`` frames) is aligned as a whole, the database (``n`` frames, takes stored one after
another) as a free subsequence inside one take. Cell ``(i, g)`` costs ``C[i, g]``, a feature distance; its
accumulated cost is ``C[i, g] + min`` over the source (row 0 only, cost 0) and the steps ``(dq, dg)`` from
``(i - dq, g - dg)`` that stay in one take (plus the skip penalties of the query frames a ``dq >= 2`` step
skips). Step sets, tie order (source, then the steps as given), skip penalties and cost normalizations are
those of :func:`stylemotion.search.lng.lng_match`, and every cell is evaluated with
the same floating-point expression, so the two agree exactly when every frame is a neighbour.

The sweep is row-wise and vectorized over the database: a row depends on earlier rows by shifts, and
the vertical steps ``(0, dg)`` inside a row are relaxed to their fixed point (as many passes as the
longest vertical run used, plus one). Time O(m n (steps + passes)); memory one ``(m, n)`` int8 choice
matrix for the paths plus a few rows (the full ``(m, n)`` float matrix only on request).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import reduce
from typing import Literal

import numpy as np
from scipy.spatial.distance import cdist

from stylemotion.search.lng import (
    THESIS_STEPS,
    Match,
    Normalization,
    Step,
    TakeBounds,
    check_normalization,
    check_skip_cost,
    check_steps,
    frame_skip_costs,
    normalized,
    select_matches,
    skip_penalty,
)

Ties = Literal["total", "predecessor"]
TIES: tuple[str, ...] = ("total", "predecessor")


@dataclass(frozen=True, eq=False)
class DTWResult:
    """Subsequence DTW output.

    ``matches``: ranked, non-overlapping matches, best first (as :func:`~stylemotion.search.lng.lng_match`);
    ``end_costs``: ``(n,)`` the (normalized) cost of the best path ending at each database frame, ``inf``
    where none; ``end_starts``: ``(n,)`` its first database frame, -1 where none; ``accumulated``: ``(m, n)``
    accumulated sums when asked for, else ``None``.
    """

    matches: list[Match]
    end_costs: np.ndarray
    end_starts: np.ndarray
    accumulated: np.ndarray | None

    @property
    def best(self) -> Match | None:
        """The best match, ``None`` when no path exists."""
        return self.matches[0] if self.matches else None


def feature_distances(query: np.ndarray, database: np.ndarray) -> np.ndarray:
    """``(m, n)`` Euclidean distances between query features ``(m, d)`` and database features ``(n, d)``,
    the distance a k-NN index over the same features reports."""
    q, x = np.asarray(query, dtype=np.float64), np.asarray(database, dtype=np.float64)
    if q.ndim != 2 or x.ndim != 2 or q.shape[1] != x.shape[1] or q.size == 0 or x.size == 0:
        raise ValueError(f"features must be non-empty (m, d) and (n, d) arrays, got {q.shape} and {x.shape}")
    if not (np.isfinite(q).all() and np.isfinite(x).all()):
        raise ValueError("features contain non-finite values")
    return cdist(q, x)


def _shift(row: np.ndarray, dg: int, fill: float | int) -> np.ndarray:
    """``row[g - dg]`` at ``g`` (``fill`` where ``g < dg``)."""
    if dg == 0:
        return row
    out = np.full_like(row, fill)
    out[dg:] = row[:-dg]
    return out


def _check_cost(cost: np.ndarray) -> np.ndarray:
    c = np.asarray(cost)
    if c.ndim != 2 or c.size == 0:
        raise ValueError(f"cost matrix must be a non-empty (m, n) array, got shape {c.shape}")
    c = c.astype(np.float64)
    bad = ~np.isfinite(c) | (c < 0)
    if bad.any():
        i, g = (int(v) for v in np.argwhere(bad)[0])
        raise ValueError(f"cost matrix entry {c[i, g]} at (query frame {i}, database frame {g}) must be finite, >= 0")
    return c


def subsequence_dtw(cost: np.ndarray, takes: TakeBounds | np.ndarray | None = None, *,
                    steps: tuple[Step, ...] = THESIS_STEPS, normalize: Normalization = "none", top: int = 1,
                    skip_cost: float | None = None, keep_matrix: bool = False, ties: Ties = "total") -> DTWResult:
    """Subsequence DTW over a precomputed ``(m, n)`` feature distance matrix.

    ``takes``: :class:`TakeBounds` or ``next_in_take (n,)`` (default: one take); ``steps``/``normalize``/``top``/
    ``skip_cost`` as in :func:`~stylemotion.search.lng.lng_match` (by default a skipped query frame costs its
    row's largest distance, what the LNG charges when every frame is a neighbour); ``keep_matrix``: also
    return the accumulated sums. ``ties``: which predecessor a cell's path takes, the first (source, then the
    steps as given) whose ``C[i, g] + predecessor`` equals the cell's total (``"total"``, the LNG's rule, so
    the two agree exactly), or the first of least predecessor sum (``"predecessor"``, the exact argmin;
    annotation's motion-template matching). The two differ only where two predecessor sums differ by less
    than the rounding of adding ``C[i, g]``: the totals are the same, a start frame may differ.
    """
    if ties not in TIES:
        raise ValueError(f"ties must be one of {TIES}, got {ties!r}")
    c = _check_cost(cost)
    m, n = c.shape
    tb = TakeBounds.from_lengths([n]) if takes is None else TakeBounds.coerce(takes)
    if tb.n != n:
        raise ValueError(f"takes describe {tb.n} database frames, the cost matrix has {n}")
    steps = check_steps(steps)
    check_normalization(normalize)
    skips = frame_skip_costs(c, check_skip_cost(skip_cost))
    frames = np.arange(n)
    allowed = {dg: tb.allows(frames - dg, dg) for _, dg in steps}
    choice = np.full((m, n), -1, dtype=np.int8)
    acc = np.empty((m, n)) if keep_matrix else None
    rows: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    depth = max(dq for dq, _ in steps)
    for i in range(m):
        d = c[i]
        rows[i] = _row(i, d, steps, allowed, rows, choice[i], frames, skips, ties)
        rows.pop(i - depth, None)
        if acc is not None:
            acc[i] = rows[i][0]
    total, start, length = rows[m - 1]
    end_costs = normalized(total, length, m, normalize)
    matches = []
    for g in select_matches(end_costs, start, frames, top):
        path = _backtrack(choice, m - 1, g, steps)
        matches.append(Match(int(start[g]), g, float(end_costs[g]), path, int(tb.take_id[start[g]])))
    return DTWResult(matches, end_costs, np.where(np.isfinite(total), start, -1), acc)


def subsequence_dtw_features(query: np.ndarray, database: np.ndarray, takes: TakeBounds | np.ndarray | None = None,
                             **kwargs) -> DTWResult:
    """:func:`subsequence_dtw` on Euclidean distances of query ``(m, d)`` and database ``(n, d)`` features."""
    return subsequence_dtw(feature_distances(query, database), takes, **kwargs)


def _row(i: int, d: np.ndarray, steps: tuple[Step, ...], allowed: dict[int, np.ndarray],
         rows: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]], choice: np.ndarray,
         frames: np.ndarray, skips: np.ndarray, ties: Ties) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Row ``i``: ``(accumulated sums, start frames, path lengths)``, each ``(n,)``; fills ``choice (n,)``."""
    cands: list[np.ndarray | None] = [np.zeros_like(d) if i == 0 else None]
    for dq, dg in steps:
        cand = None
        if dq >= 1 and i - dq >= 0:
            pred = _shift(rows[i - dq][0], dg, np.inf)
            if dq >= 2:
                pred = pred + skip_penalty(skips[i - dq + 1:i])
            cand = np.where(allowed[dg], pred, np.inf)
        cands.append(cand)
    present = [x for x in cands if x is not None]
    total = d + (reduce(np.minimum, present) if present else np.full_like(d, np.inf))
    vertical = [(c, dg) for c, (dq, dg) in enumerate(steps) if dq == 0]
    while vertical:
        new = total
        for _, dg in vertical:
            new = np.minimum(new, np.where(allowed[dg], d + _shift(new, dg, np.inf), np.inf))
        if np.array_equal(new, total):
            break
        total = new
    for c, dg in vertical:
        cands[c + 1] = np.where(allowed[dg], _shift(total, dg, np.inf), np.inf)
    reached = np.isfinite(total)
    if ties == "predecessor":  # total == d + least exactly (rounding is monotonic)
        least = reduce(np.minimum, [x for x in cands if x is not None], np.full_like(d, np.inf))
    for c, cand in enumerate(cands):
        if cand is not None:
            same = (cand == least) if ties == "predecessor" else (d + cand == total)
            choice[reached & (choice < 0) & same] = c
    return (total, *_bookkeep(i, choice, steps, rows, frames))


def _bookkeep(i: int, choice: np.ndarray, steps: tuple[Step, ...],
              rows: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]],
              frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(n,)`` first database frame and length (nodes + skipped query frames) of each cell's best path."""
    start = np.where(choice == 0, frames, -1)
    length = (choice == 0).astype(np.int64)
    for c, (dq, dg) in enumerate(steps):
        if dq >= 1 and i - dq >= 0:
            hit = choice == c + 1
            _, prev_start, prev_length = rows[i - dq]
            start = np.where(hit, _shift(prev_start, dg, -1), start)
            length = np.where(hit, _shift(prev_length, dg, 0) + dq, length)
    vertical = [(c, dg) for c, (dq, dg) in enumerate(steps) if dq == 0]
    while vertical:
        new_start, new_length = start, length
        for c, dg in vertical:
            hit = choice == c + 1
            new_start = np.where(hit, _shift(new_start, dg, -1), new_start)
            new_length = np.where(hit, _shift(new_length, dg, 0) + 1, new_length)
        if np.array_equal(new_start, start) and np.array_equal(new_length, length):
            break
        start, length = new_start, new_length
    return start, length


def _backtrack(choice: np.ndarray, i: int, g: int, steps: tuple[Step, ...]) -> np.ndarray:
    """``(L, 2)`` path ``(query frame, database frame)`` ending at cell ``(i, g)``."""
    out = []
    while True:
        c = int(choice[i, g])
        out.append((i, g))
        if c <= 0:
            break
        dq, dg = steps[c - 1]
        i, g = i - dq, g - dg
    return np.array(out[::-1], dtype=np.int64)


#: Query × database cells per chunk of :func:`take_lower_bounds` (16 M float64 cells, 128 MB), so that the bounds of
#: a long query over millions of frames never hold the whole ``(m, n)`` distance matrix.
BOUND_CHUNK_CELLS = 1 << 24


def take_lower_bounds(query: np.ndarray, database: np.ndarray, takes: TakeBounds,
                      only: np.ndarray | None = None) -> np.ndarray:
    """``(takes,)`` ``LB(T) = Σ_i min_{g ∈ T} C[i, g]`` of query ``(m, d)`` against database ``(n, d)`` features:
    no thesis-step path inside take ``T`` costs less (each step visits every query frame at least once).
    Computed over chunks of :data:`BOUND_CHUNK_CELLS` cells; memory ``O(chunk + m)`` (a take cut by a chunk's
    end carries its ``(m,)`` minima into the next chunk). ``only``: take positions to bound (the others ``inf``),
    reading only their frames."""
    q = np.asarray(query, dtype=np.float64)
    starts, ends = takes.spans()
    if only is not None:
        chosen = np.unique(np.asarray(only, dtype=np.int64))
        out = np.full(len(starts), np.inf)
        if chosen.size:
            frames, layout = takes.subset(chosen)
            out[chosen] = take_lower_bounds(q, database[frames], layout)
        return out
    bound = np.empty(len(starts))
    open_mins: np.ndarray | None = None  # minima of the take the previous chunk ended inside
    step = max(1, BOUND_CHUNK_CELLS // max(len(q), 1))
    for lo in range(0, takes.n, step):
        hi = min(takes.n, lo + step)
        cuts = np.concatenate([[lo], starts[(starts > lo) & (starts < hi)]])  # one segment per take in the chunk
        ids = np.searchsorted(starts, cuts, side="right") - 1  # the takes' positions
        segment = np.minimum.reduceat(feature_distances(q, database[lo:hi]), cuts - lo, axis=1)
        if open_mins is not None:  # the first segment continues the open take
            segment[:, 0] = np.minimum(segment[:, 0], open_mins)
        done = ends[ids] < hi
        bound[ids[done]] = segment[:, done].sum(axis=0)
        open_mins = None if done[-1] else segment[:, -1].copy()
    return bound


def best_subsequence_match(query: np.ndarray, database: np.ndarray, takes: TakeBounds | np.ndarray, *,
                           upper_bound: float | None = None, first_takes: int = 8,
                           excluded_takes: Sequence[int] = (),
                           candidate_takes: np.ndarray | None = None) -> tuple[Match | None, int]:
    """The best :func:`subsequence_dtw_features` match (thesis steps, no normalization) of query ``(m, d)``
    features in database ``(n, d)`` features, exactly, without sweeping takes that cannot hold it.

    Every thesis step visits each query frame at least once, so a path inside take ``T`` costs at least
    ``LB(T)`` (:func:`take_lower_bounds`). The sweep runs on the ``first_takes`` takes of lowest bound (or
    uses ``upper_bound``, e.g. the LNG's best cost, which can only be higher than DTW's), then on every
    take whose bound does not exceed the best cost so far (a relative margin of 1e-9 covers rounding),
    kept in database order so ties break as in the full sweep; ``excluded_takes`` (takes' positions in database
    order, a :class:`~stylemotion.search.MotionDatabase`'s take indices) are never swept; ``candidate_takes``
    (positions; None: every take): the only takes bounded and swept, for a caller that has pruned the others with
    a bound of its own below ``upper_bound``.
    Memory: the bounds' chunks and the swept takes' columns, never the whole ``(m, n)`` matrix. Returns the match
    in the database's global frames (``None`` without any path) and the number of takes swept. Tests: equal to
    the full sweep.
    """
    q = np.asarray(query, dtype=np.float64)
    tb = TakeBounds.coerce(takes)
    if tb.n != len(database):
        raise ValueError(f"takes describe {tb.n} database frames, the features have {len(database)}")
    bound = take_lower_bounds(q, database, tb, only=candidate_takes)
    bound[np.asarray(list(excluded_takes), dtype=np.int64)] = np.inf
    order = np.argsort(bound, kind="stable")
    order = order[np.isfinite(bound[order])]

    def sweep(chosen: np.ndarray) -> Match | None:
        if chosen.size == 0:
            return None
        frames, layout = tb.subset(np.sort(chosen))
        found = subsequence_dtw(feature_distances(q, database[frames]), layout).best
        if found is None:
            return None
        path = found.path.copy()
        path[:, 1] = frames[path[:, 1]]
        return Match(int(frames[found.start]), int(frames[found.end]), found.cost, path,
                     int(tb.take_id[frames[found.start]]))

    limit = np.inf if upper_bound is None else float(upper_bound)
    if not np.isfinite(limit):
        first = sweep(order[:first_takes])
        limit = np.inf if first is None else first.cost
    chosen = np.flatnonzero(bound <= limit * (1 + 1e-9) + 1e-12) if np.isfinite(limit) else np.sort(order)
    return sweep(chosen), int(len(chosen))
