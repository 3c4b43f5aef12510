"""Global motion matching with the lazy neighbourhood graph (LNG), Krüger's thesis §2.4.1, and its
online variant (OLNG, §2.7, after Tautges et al. 2011).

Input per query frame ``i`` (``m`` frames): its ``k`` nearest database frames as *global* frame indices
``(m, k)`` and their feature distances ``(m, k)`` (the units of the feature set). Radius searches may pad
with index ``-1`` or distance ``+inf`` (scipy's ``cKDTree`` pads with index ``n`` and ``inf``); such
entries are not nodes. Nothing here searches for neighbours: the arrays come from any k-NN engine.

**Graph.** Every reported neighbour is a node ``(i, g)``. A *step* ``(dq, dg)`` joins ``(i - dq, g - dg)``
to ``(i, g)`` when both are nodes and frames ``g - dg .. g`` lie in one take (:class:`TakeBounds`), so a
path never jumps between takes. The thesis' steps (§2.4.1) are the DTW basics, in its order: diagonal
``(1, 1)``, vertical ``(0, 1)`` (two consecutive database frames for one query frame, both neighbours of
it) and horizontal ``(1, 0)`` — :data:`THESIS_STEPS`, the default. A virtual source joins every node of
the first query frame; a path ends at any node of the last one, so the query is matched as a whole and
the database as a subsequence.

**Cost.** An edge costs the distance of the node it points at, so a path costs the sum of its nodes'
distances — the thesis' "global accumulated costs along the path" (§2.4.1), ``normalize="none"``, the
default. The thesis does not normalize; ``"length"`` (divide by the path's length: its nodes plus the
query frames it skips) and ``"query"`` (divide by ``m``) are offered for comparing queries of different
lengths. The shortest path is always chosen by the *sum*; normalization only rescales the reported cost
and the ranking. Steps with ``dq >= 2`` skip query frames (only the online step set has them); a skipped
frame costs ``skip_cost``, by default the largest distance reported for it (its k-th neighbour's, a lower
bound of its distance to any frame not reported), so skipping is never cheaper than passing a listed node
and pays off only where a frame's neighbours missed the path. Pass the search radius as ``skip_cost`` for
radius searches, where a frame may have no neighbour at all (such a frame cannot be skipped otherwise).

**Path search.** The graph is a DAG ordered by query frame, so one sweep over the query frames solves
the single-source shortest path problem (the thesis cites CLRS §24.2): per frame and step one
``searchsorted`` of the predecessors in the sorted neighbour list of frame ``i - dq``, O(k log k) per
frame, O(m k log k) in all. Vertical steps stay inside a frame; they are relaxed to their fixed point.

**Exactness.** A node's cost is ``d + min(predecessor costs)``, the same floating-point expression the
reference :func:`stylemotion.search.dtw.subsequence_dtw` evaluates in every cell, and ties go to the
first candidate in the order (source, then the steps as given). With every database frame a neighbour
both return identical costs, starts, ends and paths; with fewer neighbours the LNG's costs can only be
higher, and are equal whenever the DTW path's nodes are all neighbours (for step sets that skip query
frames this needs one fixed ``skip_cost`` on both sides: the default penalty depends on the neighbours).

**Ranking.** Every node of the last frame ends a candidate match. Candidates are sorted by cost (ties:
lower end frame) and taken greedily; a candidate whose database interval ``[start, end]`` overlaps an
already accepted one is suppressed — at most one match per region of the database.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from functools import reduce
from typing import Literal

import numpy as np

Step = tuple[int, int]
Normalization = Literal["none", "length", "query"]

#: §2.4.1's valid continuations, in its order: diagonal, vertical, horizontal, as (query frames, database frames).
THESIS_STEPS: tuple[Step, ...] = ((1, 1), (0, 1), (1, 0))
#: The OLNG's modified step sizes (§2.7, "modified step size conditions allow to skip single frames"; the
#: thesis gives no list, this is our reading): ``(1, 1)``; ``(1, 2)`` skips one database frame, ``(2, 1)``
#: one query frame (Müller's slope-bounded set [Mül07]); ``(2, 2)`` skips one query frame at unchanged
#: speed, bridging a frame whose neighbours missed the path. Skipped query frames cost ``skip_cost``.
ONLINE_STEPS: tuple[Step, ...] = ((1, 1), (1, 2), (2, 1), (2, 2))
#: The gap-tolerant set: the thesis' steps (so a path may stay on one database frame, ``(1, 0)``, or linger on a
#: query frame, ``(0, 1)``: still poses) and the online skips ``(1, 2)``, ``(2, 1)``, ``(2, 2)`` (so a path survives a
#: query frame whose neighbours all missed it, at the penalty ``skip_cost``).
GAP_STEPS: tuple[Step, ...] = (*THESIS_STEPS, (1, 2), (2, 1), (2, 2))
#: Step sets by the name ``stylemotion-search``'s ``steps`` takes.
STEP_SETS: dict[str, tuple[Step, ...]] = {"thesis": THESIS_STEPS, "online": ONLINE_STEPS, "gaps": GAP_STEPS}
NORMALIZATIONS: tuple[str, ...] = ("none", "length", "query")

#: Sort key of padding entries: above every database frame, far from int64 overflow under ``- dg``.
_PAD = np.iinfo(np.int64).max // 4
#: A node's path bookkeeping is one int64 "trace": ``start frame << _LEN_BITS | node count`` (one array op
#: per step instead of two); -1 when unreached.
_LEN_BITS = 24


@dataclass(frozen=True, eq=False)
class Match:
    """One matched database segment.

    ``start``/``end``: first and last global database frame; ``cost``: accumulated (and normalized) cost
    in feature-distance units; ``path``: ``(L, 2)`` int pairs ``(query frame, database frame)`` in path
    order, ``L >= m`` with vertical steps, fewer query frames than ``m`` with query-frame skips;
    ``take``: the take id of the segment.
    """

    start: int
    end: int
    cost: float
    path: np.ndarray
    take: int

    def frames_per_query(self) -> np.ndarray:
        """``(q_last - q_first + 1,)`` the last database frame aligned to each query frame of the path; a
        skipped query frame takes its predecessor's."""
        q = self.path[:, 0]
        wanted = np.arange(q[0], q[-1] + 1)
        return self.path[np.searchsorted(q, wanted, side="right") - 1, 1]


@dataclass(frozen=True, eq=False)
class TakeBounds:
    """Take layout of a database of ``n`` frames stored take after take.

    ``remaining``: ``(n,)`` frames after ``g`` in ``g``'s take (a step of ``dg`` frames from ``g`` is allowed
    iff ``remaining[g] >= dg``); ``take_id``: ``(n,)`` the take of each frame, for reporting. Build once per
    database and reuse it for every query (O(n)).
    """

    remaining: np.ndarray
    take_id: np.ndarray

    @property
    def n(self) -> int:
        """Number of database frames."""
        return int(self.remaining.shape[0])

    @classmethod
    def from_next_in_take(cls, next_in_take: np.ndarray, take_ids: np.ndarray | None = None) -> TakeBounds:
        """From ``next_in_take (n,)`` bool (frame ``g + 1`` is in ``g``'s take; the last entry is ignored) and
        optional ``take_ids (n,)`` (default: takes numbered 0, 1, ... in order)."""
        nxt = np.asarray(next_in_take)
        if nxt.ndim != 1 or nxt.shape[0] == 0:
            raise ValueError(f"next_in_take must be a non-empty 1-D array, got shape {nxt.shape}")
        if nxt.dtype != bool:
            raise ValueError(f"next_in_take must be boolean, got dtype {nxt.dtype}")
        n = nxt.shape[0]
        nxt = nxt.copy()
        nxt[-1] = False
        ends = np.flatnonzero(~nxt)
        remaining = ends[np.searchsorted(ends, np.arange(n))] - np.arange(n)
        first = np.concatenate([[True], ~nxt[:-1]])
        if take_ids is None:
            ids = np.cumsum(first) - 1
        else:
            ids = np.asarray(take_ids)
            if ids.shape != (n,) or not np.issubdtype(ids.dtype, np.integer):
                raise ValueError(f"take_ids must be integers of shape ({n},), got {ids.dtype} {ids.shape}")
            split = np.flatnonzero(nxt[:-1] & (ids[1:] != ids[:-1]))
            if split.size:
                g = int(split[0])
                raise ValueError(f"take_ids change between frames {g} and {g + 1} although next_in_take[{g}] is True")
        return cls(remaining.astype(np.int64), ids.astype(np.int64))

    @classmethod
    def from_lengths(cls, lengths: np.ndarray | list[int]) -> TakeBounds:
        """From the frame counts of the takes in database order; take ids are their positions."""
        lens = np.asarray(lengths)
        if lens.ndim != 1 or lens.size == 0 or not np.issubdtype(lens.dtype, np.integer) or (lens < 1).any():
            raise ValueError(f"take lengths must be a non-empty list of positive integers, got {lengths!r}")
        nxt = np.ones(int(lens.sum()), dtype=bool)
        nxt[np.cumsum(lens) - 1] = False
        return cls.from_next_in_take(nxt)

    @classmethod
    def coerce(cls, takes: TakeBounds | np.ndarray) -> TakeBounds:
        """Accept a :class:`TakeBounds` or a ``next_in_take`` array."""
        return takes if isinstance(takes, TakeBounds) else cls.from_next_in_take(takes)

    def spans(self) -> tuple[np.ndarray, np.ndarray]:
        """``(firsts, lasts)`` ``(takes,)`` each: the first and last frame of every take, ascending."""
        lasts = np.flatnonzero(self.remaining == 0)
        return np.concatenate([[0], lasts[:-1] + 1]), lasts

    def subset(self, positions: np.ndarray) -> tuple[np.ndarray, TakeBounds]:
        """The global frames ``(f,)`` of the takes at ``positions`` (ascending, non-empty), stored one after
        another, and their own layout (take ids: their order in ``positions``)."""
        firsts, lasts = self.spans()
        lengths = lasts[positions] - firsts[positions] + 1
        return np.concatenate([np.arange(firsts[t], lasts[t] + 1) for t in positions]), TakeBounds.from_lengths(lengths)

    def allows(self, p: np.ndarray, dg: int) -> np.ndarray:
        """``(...)`` bool: a step of ``dg`` database frames from frames ``p`` stays inside the database and
        the take."""
        inside = (p >= 0) & (p < self.n)
        return inside & (self.remaining[np.clip(p, 0, self.n - 1)] >= dg)


def check_steps(steps: tuple[Step, ...] | list[Step]) -> tuple[Step, ...]:
    """Validate a step set: pairs ``(dq, dg)`` of non-negative ints, not ``(0, 0)``, no repeats, at least one
    advancing the query (``dq >= 1``); at most 126 steps."""
    try:
        out = tuple((int(dq), int(dg)) for dq, dg in steps)
    except (TypeError, ValueError) as err:
        raise ValueError(f"steps must be (query, database) integer pairs, got {steps!r}") from err
    if not out or len(out) > 126:
        raise ValueError(f"steps must hold 1 to 126 pairs, got {steps!r}")
    for dq, dg in out:
        if dq < 0 or dg < 0 or (dq, dg) == (0, 0):
            raise ValueError(f"step {(dq, dg)} invalid: both sizes must be >= 0 and not both 0")
    if len(set(out)) != len(out):
        raise ValueError(f"steps repeat a pair: {steps!r}")
    if all(dq == 0 for dq, _ in out):
        raise ValueError(f"steps {steps!r} never advance the query: add one with dq >= 1")
    return out


def check_normalization(normalize: str) -> str:
    """Validate a cost normalization name."""
    if normalize not in NORMALIZATIONS:
        raise ValueError(f"normalize must be one of {NORMALIZATIONS}, got {normalize!r}")
    return normalize


def normalized(cost: np.ndarray, length: np.ndarray, m: int, normalize: str) -> np.ndarray:
    """Accumulated ``cost`` rescaled: as is, by the path ``length`` (nodes + skipped query frames), or by the
    query length ``m``."""
    if normalize == "length":
        return cost / np.maximum(length, 1)
    if normalize == "query":
        return cost / m
    return cost


def check_skip_cost(skip_cost: float | None) -> float | None:
    """Validate a penalty per skipped query frame (``None``: the frame's largest reported distance)."""
    if skip_cost is None:
        return None
    try:
        value = float(skip_cost)
    except (TypeError, ValueError) as err:
        raise ValueError(f"skip_cost must be a number or None, got {skip_cost!r}") from err
    if not np.isfinite(value) or value < 0:
        raise ValueError(f"skip_cost must be finite and >= 0, got {skip_cost!r}")
    return value


def frame_skip_costs(d: np.ndarray, skip_cost: float | None) -> np.ndarray:
    """``(m,)`` penalty for skipping each query frame, from its ``(m, k)`` distances (``inf`` padding): the
    fixed ``skip_cost``, or the largest finite distance of the frame (``inf`` if it has none)."""
    if skip_cost is not None:
        return np.full(d.shape[0], skip_cost)
    finite = np.where(np.isfinite(d), d, -np.inf).max(axis=1)
    return np.where(finite == -np.inf, np.inf, finite)


def skip_penalty(skipped: list[float] | np.ndarray) -> float:
    """Cost of skipping these query frames, summed left to right (one expression for LNG, OLNG and DTW)."""
    total = 0.0
    for value in skipped:
        total += float(value)
    return total


def select_matches(costs: np.ndarray, starts: np.ndarray, ends: np.ndarray, top: int) -> list[int]:
    """Indices of at most ``top`` candidates, best first: sorted by cost then end frame, greedily accepted,
    a candidate overlapping an accepted ``[start, end]`` interval suppressed. Infinite costs never count."""
    if not isinstance(top, int | np.integer) or top < 1:
        raise ValueError(f"top must be a positive integer, got {top!r}")
    finite = np.flatnonzero(np.isfinite(costs))
    order = finite[np.lexsort((ends[finite], costs[finite]))]
    s, e = starts[order], ends[order]
    alive = np.ones(order.shape[0], dtype=bool)
    chosen: list[int] = []
    while len(chosen) < top and alive.any():
        j = int(np.argmax(alive))
        chosen.append(int(order[j]))
        alive &= (s > e[j]) | (e < s[j])
    return chosen


def _first_bad(mask: np.ndarray) -> tuple[int, ...]:
    return tuple(int(v) for v in np.argwhere(mask)[0])


def _prepare(indices: np.ndarray, distances: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Validate ``(m, k)`` neighbour arrays; return them sorted by database frame per row, padding last
    (frame :data:`_PAD`, distance ``inf``)."""
    ind = np.asarray(indices)
    dist = np.asarray(distances)
    if ind.ndim != 2:
        raise ValueError(f"neighbour indices must have shape (m, k), got {ind.shape}")
    if dist.shape != ind.shape:
        raise ValueError(f"neighbour distances have shape {dist.shape}, indices {ind.shape}: they must match")
    if ind.size == 0:
        raise ValueError(f"neighbour arrays are empty: shape {ind.shape}")
    if not np.issubdtype(ind.dtype, np.integer):
        raise ValueError(f"neighbour indices must be integers, got dtype {ind.dtype}")
    if not np.issubdtype(dist.dtype, np.floating) and not np.issubdtype(dist.dtype, np.integer):
        raise ValueError(f"neighbour distances must be numbers, got dtype {dist.dtype}")
    dist = dist.astype(np.float64)
    bad = np.isnan(dist) | (dist == -np.inf)
    if bad.any():
        at = _first_bad(bad)
        raise ValueError(f"neighbour distance {dist[at]} at (frame, neighbour) {at} is not a distance")
    pad = (dist == np.inf) | (ind == -1)
    bad = ~pad & ((ind < 0) | (ind >= n))
    if bad.any():
        at = _first_bad(bad)
        raise ValueError(f"neighbour index {ind[at]} at {at} is outside the database of {n} frames")
    bad = ~pad & (dist < 0)
    if bad.any():
        at = _first_bad(bad)
        raise ValueError(f"neighbour distance {dist[at]} at {at} is negative")
    key = np.where(pad, _PAD, ind.astype(np.int64))
    order = np.argsort(key, axis=1, kind="stable")
    g = np.take_along_axis(key, order, axis=1)
    d = np.take_along_axis(np.where(pad, np.inf, dist), order, axis=1)
    dup = (g[:, 1:] == g[:, :-1]) & (g[:, 1:] != _PAD)
    if dup.any():
        i, j = _first_bad(dup)
        raise ValueError(f"query frame {i} lists database frame {g[i, j]} twice")
    return g, d


@dataclass(eq=False)
class _Column:
    """One query frame of the graph: ``k`` nodes sorted by database frame, for ``S`` start slots.

    ``t``: query frame (absolute in a stream); ``g, d``: ``(k,)`` frames and distances; ``cost``: ``(k, S)``
    accumulated sums; ``choice``: ``(k, S)`` int8 winning candidate (0 source, ``c + 1`` step ``c``, -1
    unreached); ``trace``: ``(k, S)`` first database frame and node count of the best path, packed;
    ``pos``: ``(steps, k)`` position of each step's predecessor in its column, -1 when none; ``skip``: the
    penalty for skipping this query frame.
    """

    t: int
    g: np.ndarray
    d: np.ndarray
    skip: float
    cost: np.ndarray
    choice: np.ndarray
    trace: np.ndarray
    pos: np.ndarray = field(repr=False)


def _lookup(sorted_g: np.ndarray, p: np.ndarray, valid: np.ndarray, dg: int,
            takes: TakeBounds) -> tuple[np.ndarray, np.ndarray]:
    """``(found (k,), position (k,))`` of predecessor frames ``p`` in a sorted column, in the same take."""
    idx = np.minimum(np.searchsorted(sorted_g, p), sorted_g.shape[0] - 1)
    found = valid & (sorted_g[idx] == p)  # implies 0 <= p < n: columns hold database frames and padding
    if dg > 0:
        found &= takes.remaining[np.where(found, p, 0)] >= dg
    return found, idx


def _build_column(t: int, g: np.ndarray, d: np.ndarray, skip: float, steps: tuple[Step, ...], takes: TakeBounds,
                  source: np.ndarray, preds: dict[int, tuple[_Column, np.ndarray | None, float]]) -> _Column:
    """Costs, choices and path bookkeeping of column ``t``.

    ``skip``: this frame's skip penalty; ``source``: ``(S,)`` cost of starting here per slot (0 or inf);
    ``preds``: ``dq -> (column t - dq, (S,) bool usable slots or None for all, penalty of the dq - 1 frames
    skipped)`` for every cross step that has a predecessor column.
    """
    k = g.shape[0]
    valid = g != _PAD
    dd = d[:, None]
    pos = np.full((len(steps), k), -1, dtype=np.int64)
    cands: list[np.ndarray | None] = [source[None, :]]
    vertical: list[tuple[int, np.ndarray, np.ndarray]] = []
    for c, (dq, dg) in enumerate(steps):
        cands.append(None)
        if dq == 0:
            found, idx = _lookup(g, g - dg, valid, dg, takes)
            if found.any():
                vertical.append((c, found, idx))
                pos[c] = np.where(found, idx, -1)
        elif dq in preds:
            col, usable, penalty = preds[dq]
            found, idx = _lookup(col.g, g - dg, valid, dg, takes)
            pos[c] = np.where(found, idx, -1)
            pred = col.cost[idx] + penalty if dq >= 2 else col.cost[idx]
            mask = found[:, None] if usable is None else found[:, None] & usable[None, :]
            cands[c + 1] = np.where(mask, pred, np.inf)
    cost = dd + reduce(np.minimum, [x for x in cands if x is not None])  # (k, S) by broadcasting
    cost = _relax_vertical(cost, dd, vertical)
    for c, found, idx in vertical:
        cands[c + 1] = np.where(found[:, None], cost[idx], np.inf)
    choice = _choose(cost, dd, cands)
    trace = _trace(np.where(valid, g, 0), choice, steps, pos, preds, vertical)
    return _Column(t, g, d, skip, cost, choice, trace, pos)


def _relax_vertical(cost: np.ndarray, dd: np.ndarray, vertical: list[tuple[int, np.ndarray, np.ndarray]]) -> np.ndarray:
    """Fixed point of ``cost = min(cost, d + cost[vertical predecessor])``: equal, bit for bit, to the
    sequential recurrence over increasing database frames (``d + min(a, b) == min(d + a, d + b)``). Takes as
    many passes as the longest chain of improving vertical steps."""
    masked = [(np.where(found[:, None], dd, np.inf), idx) for _, found, idx in vertical]  # inf: no predecessor
    improved = bool(masked)
    while improved:
        improved = False
        for dm, idx in masked:
            cand = dm + cost[idx]
            better = cand < cost
            if better.any():
                cost = np.where(better, cand, cost)
                improved = True
    return cost


def _choose(cost: np.ndarray, dd: np.ndarray, cands: list[np.ndarray | None]) -> np.ndarray:
    """``(k, S)`` int8: the first candidate (in order) whose ``d + cost`` equals the node's cost."""
    choice = np.full(cost.shape, -1, dtype=np.int8)
    reached = np.isfinite(cost)
    for c, cand in enumerate(cands):
        if cand is not None:
            hit = reached & (choice < 0) & (dd + cand == cost)
            choice[hit] = c
    return choice


def _trace(g: np.ndarray, choice: np.ndarray, steps: tuple[Step, ...], pos: np.ndarray,
           preds: dict[int, tuple[_Column, np.ndarray | None, float]],
           vertical: list[tuple[int, np.ndarray, np.ndarray]]) -> np.ndarray:
    """``(k, S)`` packed first database frame and length (nodes + skipped query frames) of each node's best
    path (see ``_LEN_BITS``)."""
    trace = np.where(choice == 0, (g[:, None] << _LEN_BITS) + 1, -1)
    for c, (dq, _) in enumerate(steps):
        if dq >= 1 and dq in preds:
            trace = np.where(choice == c + 1, preds[dq][0].trace[np.maximum(pos[c], 0)] + dq, trace)
    hits = [(choice == c + 1, idx) for c, _, idx in vertical]
    hits = [(hit, idx) for hit, idx in hits if hit.any()]
    if not hits:
        return trace
    # vertical choices form chains inside the column: pointer jumping to their roots, O(log chain) passes
    ptr = np.repeat(np.arange(choice.shape[0])[:, None], choice.shape[1], axis=1)
    slot = np.arange(choice.shape[1])[None, :]
    inc = np.zeros(choice.shape, dtype=np.int64)
    for hit, idx in hits:
        ptr = np.where(hit, idx[:, None], ptr)
        inc = np.where(hit, 1, inc)
    while True:
        nxt = ptr[ptr, slot]
        if np.array_equal(nxt, ptr):
            break
        inc = inc + inc[ptr, slot]
        ptr = nxt
    return np.where(inc > 0, trace[ptr, slot] + inc, trace)


def _unpack(trace: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(start frames, node counts)`` of packed traces."""
    return trace >> _LEN_BITS, trace & ((1 << _LEN_BITS) - 1)


def _backtrack(columns: list[_Column] | deque[_Column], last: int, node: int, slot: int,
               steps: tuple[Step, ...]) -> np.ndarray:
    """``(L, 2)`` path ``(query frame, database frame)`` ending at ``columns[last]``'s node, one slot."""
    first_t = columns[0].t
    out: list[tuple[int, int]] = []
    i, j = last, node
    while True:
        col = columns[i]
        c = int(col.choice[j, slot])
        out.append((col.t, int(col.g[j])))
        if c <= 0:
            break
        j = int(col.pos[c - 1, j])
        i = col.t - steps[c - 1][0] - first_t
    return np.array(out[::-1], dtype=np.int64)


def _ranked(columns: list[_Column] | deque[_Column], slot: int, m: int, steps: tuple[Step, ...],
            normalize: str, top: int, takes: TakeBounds) -> list[Match]:
    """Ranked, overlap-suppressed matches ending in the last column, for one start slot."""
    last = columns[-1]
    starts, lengths = _unpack(last.trace[:, slot])
    costs = normalized(last.cost[:, slot], lengths, m, normalize)
    chosen = select_matches(costs, starts, last.g, top)
    matches = []
    for j in chosen:
        start = int(starts[j])
        path = _backtrack(columns, len(columns) - 1, j, slot, steps)
        matches.append(Match(start, int(last.g[j]), float(costs[j]), path, int(takes.take_id[start])))
    return matches


def lng_match(indices: np.ndarray, distances: np.ndarray, takes: TakeBounds | np.ndarray, *,
              steps: tuple[Step, ...] = THESIS_STEPS, normalize: Normalization = "none", top: int = 1,
              skip_cost: float | None = None) -> list[Match]:
    """Ranked database segments matching the whole query, best first (§2.4.1).

    ``indices``/``distances``: ``(m, k)`` each query frame's neighbours (global database frames) and their
    feature distances, padding ``-1``/``inf`` allowed; ``takes``: :class:`TakeBounds` or ``next_in_take (n,)``;
    ``steps``: ``(query, database)`` step sizes; ``normalize``, ``skip_cost``: see the module docstring;
    ``top``: at most this many non-overlapping matches. Paths' query frames count from 0. Empty when no
    path exists.
    """
    tb = TakeBounds.coerce(takes)
    steps = check_steps(steps)
    check_normalization(normalize)
    skip_cost = check_skip_cost(skip_cost)
    g, d = _prepare(indices, distances, tb.n)
    m = g.shape[0]
    skips = frame_skip_costs(d, skip_cost)
    columns: list[_Column] = []
    for i in range(m):
        source = np.array([0.0 if i == 0 else np.inf])
        preds = {dq: (columns[i - dq], None, skip_penalty(skips[i - dq + 1:i]))
                 for dq in {s[0] for s in steps} if 1 <= dq <= i}
        columns.append(_build_column(i, g[i], d[i], float(skips[i]), steps, tb, source, preds))
    return _ranked(columns, 0, m, steps, normalize, top, tb)


class OnlineLNG:
    """Online lazy neighbourhood graph (§2.7, Fig. 2.10): a sliding window over a stream of query frames.

    Each :meth:`push` adds one column (the new frame's neighbours and the edges into it) and drops the
    column that left the window; the columns in between are reused as they are. Every node keeps one
    accumulated cost per possible start frame in the window (``(k, window)`` values, O(k · window) work per
    push), so the match over any suffix of the window — the whole window, or a shorter one — is exact: on
    every window it equals :func:`lng_match` on the same frames and steps, bit for bit. The default steps are
    :data:`ONLINE_STEPS`, which let a path skip single query or database frames. Query frames in paths
    are stream frame numbers (0 = the first push).
    """

    def __init__(self, window: int, takes: TakeBounds | np.ndarray, *, steps: tuple[Step, ...] = ONLINE_STEPS,
                 normalize: Normalization = "none", skip_cost: float | None = None) -> None:
        if not isinstance(window, int | np.integer) or window < 1:
            raise ValueError(f"window must be a positive number of frames, got {window!r}")
        self.window = int(window)
        self.takes = TakeBounds.coerce(takes)
        self.steps = check_steps(steps)
        self.normalize = check_normalization(normalize)
        self.skip_cost = check_skip_cost(skip_cost)
        self._columns: deque[_Column] = deque(maxlen=self.window)
        self._t = -1

    @property
    def frames_seen(self) -> int:
        """Number of frames pushed so far."""
        return self._t + 1

    def reset(self) -> None:
        """Forget the stream."""
        self._columns.clear()
        self._t = -1

    def push(self, indices: np.ndarray, distances: np.ndarray) -> Match | None:
        """Add the next query frame's neighbours ``(k,)`` and distances ``(k,)``; return the best match of
        the last ``window`` frames (fewer until the window fills), or ``None`` when no path spans them."""
        ind, dist = np.asarray(indices), np.asarray(distances)
        if ind.ndim != 1 or dist.ndim != 1:
            raise ValueError(f"push takes one frame's neighbours (k,), got shapes {ind.shape} and {dist.shape}")
        g, d = _prepare(ind[None], dist[None], self.takes.n)
        t = self._t + 1
        w = self.window
        slot_start = t - ((t - np.arange(w)) % w)  # the start frame each slot holds at time t
        source = np.where(slot_start == t, 0.0, np.inf)
        cols = self._columns
        preds = {}
        for dq in {s[0] for s in self.steps}:
            if 1 <= dq <= min(t, w - 1):
                col = cols[len(cols) - dq]
                skipped = [cols[j].skip for j in range(len(cols) - dq + 1, len(cols))]
                preds[dq] = (col, (slot_start >= 0) & (slot_start <= col.t), skip_penalty(skipped))
        skip = float(frame_skip_costs(d, self.skip_cost)[0])
        self._columns.append(_build_column(t, g[0], d[0], skip, self.steps, self.takes, source, preds))
        self._t = t
        best = self.matches(top=1)
        return best[0] if best else None

    def matches(self, top: int = 1, frames: int | None = None) -> list[Match]:
        """Ranked matches of the last ``frames`` pushed frames (default: the whole window, or all frames
        seen while fewer), best first, overlapping ones suppressed."""
        if self._t < 0:
            raise ValueError("no frame pushed yet")
        span = min(self.window, self._t + 1)
        frames = span if frames is None else frames
        if not isinstance(frames, int | np.integer) or not 1 <= frames <= span:
            raise ValueError(f"frames must be between 1 and {span}, got {frames!r}")
        start_t = self._t - frames + 1
        return _ranked(self._columns, start_t % self.window, frames, self.steps, self.normalize, top, self.takes)
