"""Exact re-ranking of the lazy neighbourhood graph's candidates by subsequence DTW in windows around them.

The LNG (:mod:`stylemotion.search.lng`) sees only each query frame's k nearest database frames, so its best
segment can lie in the right place with the wrong cost, or a segment whose path leaves the neighbour lists can
be missing from its ranking. :func:`refine_matches` takes the LNG's ``N`` best candidates, widens each by the
query's length on both sides (within its take; overlapping windows of one take merged), and runs exact
subsequence DTW (:func:`stylemotion.search.dtw.subsequence_dtw`, every cell evaluated) over all windows at once:
the result is the exact DTW ranking restricted to those windows. It equals the exact search over the whole
database whenever the exact best segment lies inside a window; the windows cost ``O(N · m · 3m)`` cells, not
``O(m · n)``.

:func:`verify_best` goes one step further: with the best candidate's cost as an upper bound it sweeps every take
whose lower bound does not exceed it (:func:`stylemotion.search.dtw.best_subsequence_match`), so the first match
is exact DTW's best segment over the whole database, whatever the neighbour lists held.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stylemotion.search.dtw import best_subsequence_match, feature_distances, subsequence_dtw
from stylemotion.search.lng import THESIS_STEPS, Match, Normalization, Step, TakeBounds


def candidate_windows(candidates: Sequence[Match], takes: TakeBounds, widen: int) -> list[tuple[int, int]]:
    """``[(first, last)]`` global frames (inclusive) of the windows around ``candidates``: each match widened by
    ``widen`` frames on both sides, clipped to its take, overlapping or touching windows of one take merged;
    sorted by first frame."""
    if isinstance(widen, bool) or not isinstance(widen, (int, np.integer)) or widen < 0:
        raise ValueError(f"widen must be a whole number ≥ 0, got {widen!r}")
    firsts, ends = takes.spans()
    spans = []
    for match in candidates:
        t = int(np.searchsorted(ends, match.start))
        spans.append((t, max(int(firsts[t]), match.start - int(widen)), min(int(ends[t]), match.end + int(widen))))
    merged: list[list[int]] = []
    for t, first, last in sorted(spans, key=lambda s: s[1]):
        if merged and merged[-1][0] == t and first <= merged[-1][2] + 1:
            merged[-1][2] = max(merged[-1][2], last)
        else:
            merged.append([t, first, last])
    return [(first, last) for _, first, last in merged]


def refine_matches(query: np.ndarray, database: np.ndarray, takes: TakeBounds, candidates: Sequence[Match], *,
                   top: int = 1, widen: int | None = None, steps: tuple[Step, ...] = THESIS_STEPS,
                   normalize: Normalization = "none", skip_cost: float | None = None) -> list[Match]:
    """The exact subsequence-DTW matches of query features ``(m, d)`` inside the windows around ``candidates``
    (global database frames), best first, non-overlapping, at most ``top``; empty without candidates or a path.

    ``database``: ``(n, d)`` features of every database frame (the index's); ``takes``: its take layout;
    ``widen``: frames added on both sides of each candidate (default ``m``, enough for the thesis steps, which
    stretch a query to at most twice its length); ``steps``/``normalize``/``skip_cost``: as the LNG's
    (:func:`~stylemotion.search.dtw.subsequence_dtw`; ``skip_cost`` None: a skipped query frame costs its row's
    largest distance over the windows).
    """
    q = np.asarray(query, dtype=np.float64)
    if not candidates:
        return []
    windows = candidate_windows(candidates, takes, len(q) if widen is None else widen)
    frames = np.concatenate([np.arange(a, b + 1) for a, b in windows])
    local = TakeBounds.from_lengths([b - a + 1 for a, b in windows])
    found = subsequence_dtw(feature_distances(q, database[frames]), local, steps=steps, normalize=normalize,
                            top=top, skip_cost=skip_cost).matches  # ranked and non-overlapping (windows are disjoint)
    out = []
    for match in found:
        path = match.path.copy()
        path[:, 1] = frames[path[:, 1]]
        start, end = int(frames[match.start]), int(frames[match.end])
        out.append(Match(start, end, match.cost, path, int(takes.take_id[start])))
    return out


#: Relative slack on an upper bound taken from a match's cost: the float32 engines' distances may sum to a cost a
#: hair below the exact one, and a bound too low could prune the best take (a looser bound only sweeps more).
BOUND_SLACK = 1e-5


def neighbour_floor(indices: np.ndarray, distances: np.ndarray, takes: TakeBounds) -> np.ndarray:
    """``(takes,)`` a lower bound of ``LB(T) = Σ_i min_{g ∈ T} C[i, g]`` from the query frames' exact k nearest
    frames alone (``indices``, ``distances`` ``(m, k)``, ascending per row, all finite): where frame i has
    neighbours in T the nearest of them is T's nearest frame (a nearer one would be among the k); where it has none,
    every frame of T is at least its k-th distance away. No database frame is read."""
    starts, _ = takes.spans()
    m, count = len(starts), len(distances)
    kth = distances[:, -1]
    keys = (np.arange(count)[:, None] * m + (np.searchsorted(starts, indices, side="right") - 1)).ravel()
    pairs, first = np.unique(keys, return_index=True)  # rows ascending: the first of a (row, take) is its nearest
    gain = distances.ravel()[first] - kth[pairs // m]  # ≤ 0: how much nearer than the k-th the take comes
    return float(np.sum(kth)) + np.bincount(pairs % m, weights=gain, minlength=m)


def verify_best(query: np.ndarray, database: np.ndarray, takes: TakeBounds, matches: Sequence[Match], *,
                excluded_takes: Sequence[int] = (),
                neighbours: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[list[Match], int]:
    """``matches`` (best first) with exact subsequence DTW's best segment (thesis steps, no normalization) first.

    The first match's cost (× ``1 +`` :data:`BOUND_SLACK`) bounds DTW's best from above, so only the takes whose
    lower bound does not exceed it are swept; without matches every take is. ``neighbours``: the query frames'
    **exact** k nearest frames outside the excluded takes (``(indices, distances)`` ``(m, k)``, ascending, finite)
    — their :func:`neighbour_floor` (× ``1 −`` :data:`BOUND_SLACK`) prunes takes before any of their frames is
    read. When DTW's best differs from the first match it is put first and the matches overlapping it are dropped.
    ``excluded_takes``: take positions never searched. Returns the matches and the number of takes swept.
    """
    upper = matches[0].cost * (1.0 + BOUND_SLACK) + 1e-12 if matches else None
    candidates = None
    if upper is not None and neighbours is not None:
        floor = neighbour_floor(*neighbours, takes) * (1.0 - BOUND_SLACK)
        candidates = np.flatnonzero(floor <= upper)
    best, swept = best_subsequence_match(query, database, takes, upper_bound=upper, excluded_takes=excluded_takes,
                                         candidate_takes=candidates)
    if best is None or (matches and (matches[0].start, matches[0].end) == (best.start, best.end)):
        return list(matches), swept
    rest = [m for m in matches if m.take != best.take or m.end < best.start or m.start > best.end]
    return [best, *rest], swept
