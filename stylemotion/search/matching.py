"""Global motion matching of a query motion against a :class:`~stylemotion.search.index.FrameIndex` (Krüger §2.4.1).

One call does the thesis' steps 2–4 on an index built once (step 1): the query's features in the index's
feature set (:meth:`FrameIndex.features_of`), one batched k-NN query for all its frames, the lazy
neighbourhood graph over the database's takes (:func:`stylemotion.search.lng.lng_match`), and the matches
mapped back to takes and labels::

    index = FrameIndex.build(load_dataset("synthetic"), "E15")
    result = search_motion(query_positions, index, k=16, top=10)     # (m, 21, 3) metres at index fps
    for match in result.matches:                                      # best first, non-overlapping
        match.take, match.content, match.style, match.start, match.end, match.cost
        match.path                                                    # (L, 2) (query frame, frame in take)
    result.implicit_distances(lo, hi)                                 # (m, hi - lo) k-NN distances, NaN elsewhere

Frames of a match are frames of its take at the dataset's fps; ``end`` is **exclusive** (one past the last
matched frame), so ``take[start:end]`` is the matched segment and ``query=<take>:<start>-<end>`` of
``stylemotion-search`` cuts it again. ``cost`` is the LNG's accumulated feature distance along the path (the
thesis' global distance; the feature set's units, see :mod:`stylemotion.search.features`).

Excluding takes (e.g. the one a query was cut from): their frames are dropped from every query frame's
neighbour list. So that each frame still has its ``k`` nearest frames *outside* them, the search asks for
``k`` plus the excluded frame count (capped at the database) and keeps the ``k`` nearest that remain: the
result is exactly the k-NN over the database without those takes.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stylemotion.search.index import EXACT_ENGINES, FrameIndex
from stylemotion.search.lng import THESIS_STEPS, Match, Normalization, Step, check_skip_cost, lng_match
from stylemotion.search.refine import refine_matches, verify_best
from stylemotion.search.settings import SearchSettings

#: Neighbours per query frame by default: ``stylemotion-search``'s ``k`` (:class:`SearchSettings`, where it is
#: set and why).
DEFAULT_K: int = SearchSettings.k
#: Largest neighbours per query frame a growing search reaches by default (:class:`SearchSettings`'s ``k_max``).
DEFAULT_K_MAX: int = SearchSettings.k_max
#: Doublings in a row over which ``grow="stable"`` needs the same best segment (:class:`SearchSettings`'s
#: ``stable_for``).
DEFAULT_STABLE_FOR: int = SearchSettings.stable_for
#: How the search grows ``k`` (:func:`grow_k`): not at all, until a path exists, until the best segment is stable.
GROWTH: tuple[str, ...] = ("none", "path", "stable")
#: Keys of a match's record in ``matches.json``, in order.
MATCH_KEYS = ("take", "content", "style", "start", "end", "cost")


@dataclass(frozen=True, eq=False)
class SegmentMatch:
    """One ranked database segment.

    Attributes:
        rank: 1 for the best match.
        take, content, style: the take's name and labels.
        start, end: frames of the take at the dataset's fps, ``end`` exclusive.
        cost: accumulated feature distance along the warping path (feature-set units).
        path: ``(L, 2)`` int64 pairs (query frame, frame of the take), in path order.
        global_start, global_end: the same frames as global database indices (``global_end`` exclusive).
    """

    rank: int
    take: str
    content: str
    style: str
    start: int
    end: int
    cost: float
    path: np.ndarray = field(repr=False)
    global_start: int = 0
    global_end: int = 0

    @property
    def frames(self) -> int:
        """Length of the matched segment in database frames."""
        return self.end - self.start

    def record(self) -> dict[str, Any]:
        """The match as ``matches.json`` holds it: exactly :data:`MATCH_KEYS`."""
        return {"take": self.take, "content": self.content, "style": self.style, "start": int(self.start),
                "end": int(self.end), "cost": float(self.cost)}


@dataclass(frozen=True, eq=False)
class SearchResult:
    """What :func:`search_features` found, and what it looked at.

    Attributes:
        matches: ranked, non-overlapping, best first.
        indices, distances: ``(m, k)`` each query frame's neighbours (global frames, ascending distance;
            ``-1``/``inf`` padding where a radius search found fewer) and their feature distances.
        k: neighbours per query frame of the graph that gave the matches (the k used; ``indices`` has
            ``k`` columns).  k_tried: every k whose graph was searched, in order (one entry without growth).
        excluded_takes: names of takes left out of the search.
        timings: seconds of ``features``, ``knn`` and ``lng`` (summed over the k tried), ``refine`` and ``verify``
            when run.  takes_verified: takes the exact verification swept (None without ``verify``).
    """

    matches: list[SegmentMatch]
    indices: np.ndarray = field(repr=False)
    distances: np.ndarray = field(repr=False)
    k: int = DEFAULT_K
    excluded_takes: tuple[str, ...] = ()
    timings: dict[str, float] = field(default_factory=dict)
    k_tried: tuple[int, ...] = ()
    takes_verified: int | None = None

    @property
    def query_frames(self) -> int:
        return int(self.indices.shape[0])

    def implicit_distances(self, lo: int, hi: int) -> np.ndarray:
        """``(m, hi - lo)`` the distance matrix the LNG computed implicitly over global frames ``lo:hi``:
        each query frame's k-NN distances where a neighbour lies in the range, NaN where none was computed."""
        if not 0 <= lo < hi:
            raise ValueError(f"the frame range must satisfy 0 <= lo < hi, got {lo}, {hi}")
        out = np.full((self.query_frames, hi - lo), np.nan)
        inside = (self.indices >= lo) & (self.indices < hi)
        rows, cols = np.nonzero(inside)
        out[rows, self.indices[rows, cols] - lo] = self.distances[rows, cols]
        return out


def _excluded_frames(index: FrameIndex, exclude_takes: Iterable[str]) -> tuple[tuple[str, ...], np.ndarray]:
    names = tuple(dict.fromkeys(str(t) for t in exclude_takes))
    ids = np.array([index.database.take_index(name) for name in names], dtype=np.int64)
    return names, ids


def nearest_outside(index: FrameIndex, features: np.ndarray, k: int, excluded_ids: np.ndarray, *,
                    eps: float = 0.0, radius: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``(distances, indices)`` ``(m, k)``: the ``k`` nearest frames of each query feature ``(m, d)`` among the
    frames outside the takes ``excluded_ids`` (see the module docstring); ``-1``/``inf`` padding."""
    database = index.database
    blocked = int(sum(database.take_start[i + 1] - database.take_start[i] for i in excluded_ids))
    available = database.num_frames - blocked
    if k > available:
        raise ValueError(f"k={k} exceeds the {available} frames of the database outside the excluded takes")
    if blocked == 0:
        return index.query(features, k, eps=eps, radius=radius)
    distances, indices = index.query(features, min(k + blocked, database.num_frames), eps=eps, radius=radius)
    keep = indices >= 0
    keep[keep] = ~np.isin(database.take_id[indices[keep]], excluded_ids)
    order = np.argsort(~keep, axis=1, kind="stable")[:, :k]  # kept first, in ascending distance
    kept = np.take_along_axis(keep, order, axis=1)
    distances = np.where(kept, np.take_along_axis(distances, order, axis=1), np.inf)
    indices = np.where(kept, np.take_along_axis(indices, order, axis=1), -1)
    return distances, indices


def _segment(index: FrameIndex, match: Match, rank: int) -> SegmentMatch:
    database = index.database
    take = int(database.take_id[match.start])
    first = int(database.take_start[take])
    path = match.path.copy()
    path[:, 1] -= first
    return SegmentMatch(rank, database.take_names[take], database.contents[take], database.styles[take],
                        match.start - first, match.end - first + 1, float(match.cost), path, match.start,
                        match.end + 1)


def grow_k(neighbours: Callable[[int], tuple[np.ndarray, np.ndarray]],
           match: Callable[[np.ndarray, np.ndarray], list[Match]], k: int, k_max: int,
           grow: str = "stable", stable_for: int = DEFAULT_STABLE_FOR
           ) -> tuple[list[Match], np.ndarray, np.ndarray, tuple[int, ...]]:
    """The LNG's matches with ``k`` doubled (capped at ``k_max``) until the answer holds.

    ``neighbours(k)`` → ``(distances, indices)`` ``(m, k)``, ascending per row (the first ``j`` columns are the
    ``j`` nearest, so one query serves every smaller k); ``match(indices, distances)`` → ranked matches.
    ``grow``: ``"none"`` searches ``k`` only; ``"path"`` doubles until a path exists; ``"stable"`` doubles until
    a path exists and the best segment (start and end frame) has held over ``stable_for`` doublings in a row
    (1: the same at k and 2k; 2: at k, 2k and 4k), and returns the last answer (with every frame a neighbour the
    LNG is exact DTW, so the doubling converges to it). With exact neighbours the graph at 2k holds the graph
    at k, so the best cost never rises as k grows: a larger ``stable_for`` or ``k_max`` only searches further and
    never answers worse. Returns ``(matches at the k used, its distances, its indices, every k searched)``; the
    last k searched is the k used. At ``k_max`` the answer stands as it is (possibly no path).
    """
    if grow not in GROWTH:
        raise ValueError(f"grow must be one of {GROWTH}, got {grow!r}")
    if k_max < k:
        raise ValueError(f"k_max={k_max} is below k={k}: the growth bound must be at least the starting k")
    if isinstance(stable_for, bool) or not isinstance(stable_for, (int, np.integer)) or stable_for < 1:
        raise ValueError(f"stable_for must be a whole number ≥ 1, got {stable_for!r}")
    if grow == "none" or k == k_max:
        dist, ind = neighbours(k)
        return match(ind, dist), dist, ind, (k,)
    if grow == "path":
        tried = []
        while True:
            dist, ind = neighbours(k)
            found = match(ind, dist)
            tried.append(k)
            if found or k >= k_max:
                return found, dist, ind, tuple(tried)
            k = min(2 * k, k_max)
    dist, ind = neighbours(min(2 * k, k_max))
    found = match(ind[:, :k], dist[:, :k])
    tried = [k]
    held = 0  # doublings in a row over which the best segment stayed the same
    while k < k_max:
        nxt = min(2 * k, k_max)
        if dist.shape[1] < nxt:
            dist, ind = neighbours(nxt)
        better = match(ind[:, :nxt], dist[:, :nxt])
        tried.append(nxt)
        same = found and better and (found[0].start, found[0].end) == (better[0].start, better[0].end)
        held = held + 1 if same else 0
        found, k = better, nxt
        if held >= stable_for:
            break
    return found, dist[:, :k], ind[:, :k], tuple(tried)


def search_features(features: np.ndarray, index: FrameIndex, k: int = DEFAULT_K, top: int = 10, *,
                    exclude_takes: Iterable[str] = (), eps: float = 0.0, radius: float | None = None,
                    steps: tuple[Step, ...] = THESIS_STEPS, normalize: Normalization = "none",
                    k_max: int | None = None, grow: str = "none", stable_for: int = DEFAULT_STABLE_FOR,
                    skip_cost: float | None = None, refine: int = 0, verify: bool = False) -> SearchResult:
    """Ranked database segments matching query features ``(m, d)`` (the index's feature set) as a whole.

    ``k``: neighbours per query frame (1 ≤ k ≤ database frames outside ``exclude_takes``), the first k a
    growing search tries; ``k_max``, ``grow``, ``stable_for``: :func:`grow_k` (``k_max`` None: no growth; capped at the
    frames outside ``exclude_takes``); ``top``: at most this many matches; ``exclude_takes``: take names left
    out; ``eps``/``radius``: the k-NN search's approximation and fixed radius (:meth:`FrameIndex.query`);
    ``steps``/``normalize``/``skip_cost``: the LNG's (:func:`lng_match`; ``skip_cost`` None: the radius when one
    is given, else each frame's k-th distance); ``refine``: re-rank the LNG's ``max(refine, top)`` best candidates
    by exact subsequence DTW in windows around them (:func:`~stylemotion.search.refine.refine_matches`; 0: the
    LNG's ranking as it is), which makes the matches' costs exact DTW costs (every candidate's window is searched,
    so as many matches come back as the LNG found, up to ``top``); ``verify``: make the first match exact
    subsequence DTW's best segment over every take not excluded, sweeping the takes whose lower bound does not
    exceed the first match's cost (:func:`~stylemotion.search.refine.verify_best`; thesis steps and
    ``normalize="none"`` only).

    Raises:
        ValueError: bad ``k``/``k_max``/``top``/``grow``/``stable_for``/``refine``/features, ``verify`` with other
            steps or a normalization, an unknown take name (KeyError).
    """
    for value, key in ((k, "k"), (top, "top"), (k if k_max is None else k_max, "k_max")):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise ValueError(f"{key} must be a whole number ≥ 1, got {value!r}")
    if isinstance(refine, bool) or not isinstance(refine, (int, np.integer)) or refine < 0:
        raise ValueError(f"refine must be a whole number ≥ 0, got {refine!r}")
    if verify and (tuple(steps) != THESIS_STEPS or normalize != "none"):
        raise ValueError("verify needs the thesis' steps and normalize='none' (the exact search it runs)")
    skip_cost = radius if skip_cost is None else check_skip_cost(skip_cost)
    names, ids = _excluded_frames(index, exclude_takes)
    database = index.database
    available = database.num_frames - int(sum(database.take_start[i + 1] - database.take_start[i] for i in ids))
    bound = int(k) if k_max is None else min(int(k_max), max(available, int(k)))
    spent = {"knn": 0.0, "lng": 0.0}
    candidates = max(int(top), int(refine))

    def neighbours(j: int) -> tuple[np.ndarray, np.ndarray]:
        t0 = time.perf_counter()
        out = nearest_outside(index, features, j, ids, eps=eps, radius=radius)
        spent["knn"] += time.perf_counter() - t0
        return out

    def match(ind: np.ndarray, dist: np.ndarray) -> list[Match]:
        t0 = time.perf_counter()
        out = lng_match(ind, dist, database.take_bounds, steps=steps, normalize=normalize, top=candidates,
                        skip_cost=skip_cost)
        spent["lng"] += time.perf_counter() - t0
        return out

    found, distances, indices, tried = grow_k(neighbours, match, int(k), bound, grow, stable_for)
    if refine:
        t0 = time.perf_counter()
        found = refine_matches(features, index.features, database.take_bounds, found[:candidates], top=int(top),
                               steps=steps, normalize=normalize, skip_cost=skip_cost)
        spent["refine"] = time.perf_counter() - t0
    swept = None
    if verify:
        t0 = time.perf_counter()
        exact = eps == 0 and radius is None and index.engine in EXACT_ENGINES and bool(np.isfinite(distances).all())
        found, swept = verify_best(features, index.features, database.take_bounds, found, excluded_takes=ids,
                                   neighbours=(indices, distances) if exact else None)
        spent["verify"] = time.perf_counter() - t0
    matches = [_segment(index, m, rank) for rank, m in enumerate(found[:top], start=1)]
    return SearchResult(matches, indices, distances, tried[-1], names, spent, tried, swept)


def search_motion(positions: np.ndarray, index: FrameIndex, k: int = DEFAULT_K, top: int = 10,
                  **options: Any) -> SearchResult:
    """:func:`search_features` for a query motion ``(m, 21, 3)`` (metres, Y up, at the index's fps): its
    features are made as the database's (:meth:`FrameIndex.features_of`; ValueError for a query shorter than
    the feature set's window, naming both frame counts)."""
    t0 = time.perf_counter()
    features = index.features_of(positions)
    elapsed = time.perf_counter() - t0
    result = search_features(features, index, k, top, **options)
    result.timings["features"] = elapsed
    return result
