"""How well the search does, with its failures counted: the LNG against exact subsequence DTW, retrieval
precision by content, and the helpers the benchmark suite ``search`` (scripts/suites/search.py) and the tests
share.

Conventions (docs/search.md, "How the search is measured"):

* A query for which the LNG finds **no path** is a miss, never dropped: it shares the same best segment with
  DTW "no", and in Spearman's ρ its LNG cost is ``+inf`` — the worst rank, ties among misses sharing their
  average rank (:func:`spearman_with_misses`).
* **Precision@n** counts a missing match as a wrong one: the number of the first ``n`` matches with the
  wanted label, divided by ``n`` however many were found (:func:`precision_at`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.stats import rankdata

from stylemotion.search.dtw import best_subsequence_match
from stylemotion.search.index import FrameIndex
from stylemotion.search.lng import THESIS_STEPS, Match, TakeBounds, lng_match

#: A query whose mean joint speed (all 21 joints, world frame) is below this is a "still pose" query, m/s.
#: Bandai's takes begin and end standing; standing sway stays below it, a waving hand alone lifts the mean
#: above it. A label for reporting, not a tuned setting.
STILL_SPEED_M_S = 0.1


def spearman_with_misses(lng_costs: Sequence[float | None], dtw_costs: Sequence[float]) -> float | None:
    """Spearman's ρ between the LNG's and DTW's best costs over all queries; a query without an LNG path
    (``None`` or ``inf``) takes the worst LNG rank (misses tie). ``None`` for fewer than 3 queries or when
    one side is constant."""
    lng = np.array([np.inf if c is None else float(c) for c in lng_costs])
    dtw = np.asarray(dtw_costs, dtype=float)
    if lng.shape != dtw.shape:
        raise ValueError(f"{lng.size} LNG costs but {dtw.size} DTW costs")
    if lng.size < 3:
        return None
    a, b = rankdata(lng), rankdata(dtw)
    if np.ptp(a) == 0 or np.ptp(b) == 0:
        return None
    return float(np.corrcoef(a, b)[0, 1])


def precision_at(labels: Sequence[str], wanted: str, n: int) -> float:
    """Share of the first ``n`` found ``labels`` equal to ``wanted``, missing ones (fewer than ``n`` found)
    counted wrong."""
    if n < 1:
        raise ValueError(f"n must be ≥ 1, got {n}")
    return sum(label == wanted for label in list(labels)[:n]) / n


def mean_joint_speed(positions: np.ndarray, fps: float) -> float:
    """Mean speed of all joints over ``positions (frames, J, 3)`` metres, m/s (0 for one frame)."""
    p = np.asarray(positions, dtype=np.float64)
    if len(p) < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(p, axis=0), axis=-1).mean() * fps)


def random_segments(lengths: Sequence[int], frames: int, count: int, rng: np.random.Generator
                    ) -> list[tuple[int, int]]:
    """``count`` random ``(take, start)`` pairs (takes numbered as in ``lengths``) of segments of ``frames``
    frames: a take drawn uniformly among those long enough, then a start uniformly inside it."""
    usable = [t for t, n in enumerate(lengths) if n >= frames]
    if not usable:
        return []
    picks = rng.integers(0, len(usable), count)
    return [(usable[p], int(rng.integers(0, lengths[usable[p]] - frames + 1))) for p in picks]


class NeighbourCache:
    """The k nearest database frames of one query's frames, queried once per larger ``k`` and sliced for a
    smaller one (the first ``j`` columns of an exact k-NN answer are the ``j`` nearest), with each k's LNG
    answer kept: every k-rule (a fixed k, :func:`~stylemotion.search.matching.grow_k` with any start and bound)
    is then evaluated on the same neighbours without a second search.

    ``features``: ``(m, d)`` the query's; ``eps``/``radius``: :meth:`FrameIndex.query`'s; ``steps``: the LNG's;
    ``top``: candidates the LNG ranks per k (the most a :meth:`grown` refinement re-ranks).
    """

    def __init__(self, index: FrameIndex, features: np.ndarray, takes: TakeBounds, *, eps: float = 0.0,
                 radius: float | None = None, steps: tuple[tuple[int, int], ...] = THESIS_STEPS,
                 top: int = 1) -> None:
        self.index, self.features, self.takes = index, features, takes
        self.eps, self.radius, self.steps, self.top = eps, radius, steps, int(top)
        self._refined: dict[tuple[int, int], list[Match]] = {}
        self._dist = np.zeros((len(features), 0))
        self._ind = np.zeros((len(features), 0), dtype=np.int64)
        self._found: dict[int, list[Match]] = {}

    @property
    def largest(self) -> int:
        """The largest k queried so far."""
        return int(self._ind.shape[1])

    def __call__(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """``(distances, indices)`` ``(m, k)``."""
        if k > self.largest:
            dist, ind = self.index.query(self.features, k, eps=self.eps, radius=self.radius)
            self._dist, self._ind = np.atleast_2d(dist), np.atleast_2d(ind)
        return self._dist[:, :k], self._ind[:, :k]

    def match(self, ind: np.ndarray, dist: np.ndarray) -> list[Match]:
        """The LNG's best match on these neighbours (kept per k)."""
        k = int(ind.shape[1])
        if k not in self._found:
            self._found[k] = lng_match(ind, dist, self.takes, steps=self.steps, top=self.top,
                                       skip_cost=self.radius)
        return self._found[k]

    def best(self, k: int) -> tuple[int, int, float, int] | None:
        """``(start, end, cost, take)`` of the LNG's best match at ``k``, None without a path."""
        found = self.match(*self(k)[::-1])
        return (found[0].start, found[0].end, found[0].cost, found[0].take) if found else None

    def grown(self, k: int, k_max: int, grow: str, stable_for: int = 1, refine: int = 0
              ) -> tuple[tuple[int, int, float, int] | None, int]:
        """The best match of :func:`~stylemotion.search.matching.grow_k` from ``k`` up to ``k_max`` (``grow``,
        ``stable_for``: its rule) and the k it used; ``refine`` > 0: the best after re-ranking the LNG's ``refine``
        best candidates at that k by exact DTW in windows (:func:`~stylemotion.search.refine.refine_matches`; at
        most :attr:`top` candidates)."""
        from stylemotion.search.matching import grow_k
        from stylemotion.search.refine import refine_matches

        found, _, ind, _ = grow_k(self, self.match, k, min(k_max, self.index.size), grow, stable_for)
        used = int(ind.shape[1])
        if refine and found:
            if (used, refine) not in self._refined:
                self._refined[(used, refine)] = refine_matches(self.features, self.index.features, self.takes,
                                                               found[:refine], steps=self.steps)
            found = self._refined[(used, refine)]
        best = (found[0].start, found[0].end, found[0].cost, found[0].take) if found else None
        return best, used


@dataclass(frozen=True)
class LNGvsDTW:
    """One query: the DTW best match (``dtw_*``, global frames, always found for queries no longer than a
    take) and per ``k`` the LNG's best (``lng[k]``: ``(start, end, cost)`` or ``None`` for no path)."""

    dtw_start: int
    dtw_end: int
    dtw_cost: float
    dtw_take: int
    lng: dict[int | str, tuple[int, int, float, int] | None]
    takes_swept: int

    def record(self, k: int | str) -> dict[str, Any]:
        """The comparison at ``k`` (or a named variant of ``lng``): ``no_path``, ``same_segment``, ``overlap``,
        ``cost_ratio`` (LNG / DTW, ``None`` without a path), ``lng_cost``, ``dtw_cost``."""
        found = self.lng[k]
        if found is None:
            return {"no_path": True, "same_segment": False, "overlap": False, "cost_ratio": None,
                    "lng_cost": None, "dtw_cost": self.dtw_cost}
        start, end, cost, take = found
        return {"no_path": False, "same_segment": (start, end) == (self.dtw_start, self.dtw_end),
                "overlap": take == self.dtw_take and start <= self.dtw_end and self.dtw_start <= end,
                "cost_ratio": cost / self.dtw_cost if self.dtw_cost > 0 else (1.0 if cost == 0 else None),
                "lng_cost": cost, "dtw_cost": self.dtw_cost}


def compare_lng_dtw(features: np.ndarray, index: FrameIndex, takes: TakeBounds, ks: Sequence[int],
                    variants: dict[str, tuple[int, int, float, int] | None] | None = None,
                    cache: NeighbourCache | None = None, bounding: Sequence[str] = ()) -> LNGvsDTW:
    """The LNG's best match of query ``features (m, d)`` at each of ``ks`` neighbours per frame (one k-NN
    query for the largest; the first ``k`` columns are the ``k`` nearest) against exact subsequence DTW over
    every database frame with the thesis' steps (:func:`~stylemotion.search.dtw.best_subsequence_match`).
    ``variants``: further named best matches ``(start, end, cost, take)`` or None (e.g. a growing k, another
    step set) compared with the same DTW answer; ``bounding``: the variants found with the thesis' steps, whose
    costs (like the fixed k's) bound DTW's from above and prune its sweep; ``cache``: the query's
    :class:`NeighbourCache` (thesis steps) to reuse."""
    ks = sorted(set(int(k) for k in ks))
    cache = cache if cache is not None else NeighbourCache(index, features, takes)
    lng: dict[int | str, tuple[int, int, float, int] | None] = {k: cache.best(k) for k in ks}
    lng.update(variants or {})
    upper = min((v[2] for key, v in lng.items() if v is not None and (isinstance(key, int) or key in bounding)),
                default=None)
    best, swept = best_subsequence_match(features, index.features, takes, upper_bound=upper)
    if best is None:
        raise ValueError("no DTW path: the query is longer than every take of the database")
    return LNGvsDTW(best.start, best.end, best.cost, best.take, lng, swept)


def summarize_lng(records: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Figures over queries' :meth:`LNGvsDTW.record` s: counts, no-path count, same/overlapping best segment
    shares and Spearman ρ over **all** queries (no path = miss), cost ratio mean/p95/max over the queries
    with a path (their count beside)."""
    n = len(records)
    ratios = np.array([r["cost_ratio"] for r in records if r["cost_ratio"] is not None], dtype=float)
    return {"queries": n, "no_path": sum(r["no_path"] for r in records),
            "same_segment": float(np.mean([r["same_segment"] for r in records])) if n else None,
            "overlap": float(np.mean([r["overlap"] for r in records])) if n else None,
            "spearman_rho": spearman_with_misses([r["lng_cost"] for r in records], [r["dtw_cost"] for r in records]),
            "cost_ratio_n": int(ratios.size),
            "cost_ratio_mean": float(ratios.mean()) if ratios.size else None,
            "cost_ratio_p95": float(np.percentile(ratios, 95)) if ratios.size else None,
            "cost_ratio_max": float(ratios.max()) if ratios.size else None,
            "lng_never_below_dtw": bool(np.all(ratios >= 1 - 1e-9)) if ratios.size else None}


def rank_agreement(indexes: dict[str, FrameIndex], frames: np.ndarray, k: int) -> dict[str, dict[str, float]]:
    """Fig. 2.5/2.7 of the thesis: for each frame of ``frames`` (global indices), its ``k`` nearest frames under
    feature set A; Spearman's ρ between those frames' distances under A and under B, averaged over the frames.
    ``indexes``: feature set → index over the same database. Returns ``{A: {B: mean ρ}}`` (ties share ranks)."""
    out: dict[str, dict[str, float]] = {}
    for a, ia in indexes.items():
        _, near = ia.query(ia.features[frames], k)
        near = np.atleast_2d(near)
        ranks = {}
        for b, ib in indexes.items():
            dist = np.linalg.norm(ib.features[near] - ib.features[frames][:, None, :], axis=-1)
            ranks[b] = rankdata(dist, axis=1)
        ra = ranks[a] - ranks[a].mean(axis=1, keepdims=True)
        out[a] = {}
        for b, rb in ranks.items():
            rb = rb - rb.mean(axis=1, keepdims=True)
            denom = np.sqrt((ra ** 2).sum(axis=1) * (rb ** 2).sum(axis=1))
            rho = np.where(denom > 0, (ra * rb).sum(axis=1) / np.where(denom > 0, denom, 1), np.nan)
            out[a][b] = float(np.nanmean(rho))
    return out
