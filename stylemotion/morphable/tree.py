"""Space-partitioning tree over a primitive's latent samples (Du §4.4.2, §4.5.2).

``N`` codes drawn from the primitive's mixture (10,000 by default) are split recursively into
``branching`` (4) children until a node holds at most ``leaf_size`` codes. Splits:

* ``kmeans`` (the thesis'): k-means (scipy's ``kmeans2``, k-means++ start, seeded) on the node's codes;
* ``gmm``: a ``branching``-component Gaussian mixture, codes to their most likely component;
* ``median``: median splits along the axis of largest spread, twice per level (4 children).

The split runs on the codes themselves (``space="latent"``, the thesis') or on other per-code values
given to :meth:`SpaceTree.build` as ``features`` (e.g. ``space="keyframes"``: each code's joint positions and
rotations at the primitive's keyframes, what keyframe constraints measure; see
:meth:`~stylemotion.morphable.model.MorphableModel.build_tree`).

Two searches:

* :meth:`SpaceTree.search` (the thesis'): every node is represented by the mean of its codes; a beam of
  ``candidates`` nodes descends: at each level the children of the kept nodes are scored by the objective
  (one evaluation each, on their mean code), the ``candidates`` best are kept, and at the bottom every code
  of the kept leaves is scored. Evaluations: O(levels × branching × candidates). Works for any objective.
* :meth:`SpaceTree.search_bounded` (branch and bound, beyond the thesis): given a *lower bound* of the
  objective over each node's codes (e.g. from per-node boxes of the codes' keyframe features,
  :meth:`SpaceTree.node_bounds`), nodes are opened best first and leaves' codes evaluated until the budget of
  evaluations is spent or no unopened node can beat the best code found (then the result is the exact
  optimum over all codes). Bound checks cost no decoding and are counted apart.

The tree is plain arrays (:meth:`SpaceTree.to_arrays`), saved inside the model's ``.npz``.
"""

from __future__ import annotations

import heapq
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.cluster.vq import kmeans2
from sklearn.mixture import GaussianMixture

SPLITS = ("kmeans", "gmm", "median")
#: Codes sampled per primitive (the thesis' 10,000).
TREE_SAMPLES = 10_000


@dataclass
class SearchResult:
    """The best code found, its objective value and how many codes were evaluated.

    ``bound_checks``: node lower bounds computed (:meth:`SpaceTree.search_bounded`; no decoding);
    ``exact``: the search proved the result optimal over every code of the tree."""

    latent: np.ndarray
    cost: float
    evaluations: int
    index: int = -1
    bound_checks: int = 0
    exact: bool = False


@dataclass
class SpaceTree:
    """Attributes: ``latent`` ``(N, d)`` codes, ordered so every node's codes are contiguous;
    ``centroid`` ``(M, d)`` node means; ``children`` ``(M, branching)`` child node ids (-1: none; a node
    without children is a leaf); ``start``/``stop`` ``(M,)`` the node's codes ``latent[start:stop]``;
    ``split``: how it was built; ``space``: what the split clustered (``latent`` or a name of the
    ``features`` given to :meth:`build`). Node 0 is the root; a node's children have larger ids."""

    latent: np.ndarray
    centroid: np.ndarray
    children: np.ndarray
    start: np.ndarray
    stop: np.ndarray
    split: str = "kmeans"
    space: str = "latent"

    @classmethod
    def build(cls, latent: np.ndarray, branching: int = 4, leaf_size: int = 16, split: str = "kmeans",
              seed: int = 0, features: np.ndarray | None = None, space: str | None = None) -> SpaceTree:
        """Build over ``(N, d)`` codes (see the module doc); with ``features`` ``(N, F)`` the splits cluster
        those instead of the codes (``space`` names them, default ``features``)."""
        if split not in SPLITS:
            raise ValueError(f"unknown tree split {split!r}; one of {list(SPLITS)}")
        if branching < 2 or leaf_size < 1:
            raise ValueError(f"need branching ≥ 2 and leaf_size ≥ 1, got {branching}, {leaf_size}")
        if split == "median" and branching != 4:
            raise ValueError("the median tree splits twice per level: branching must be 4")
        latent = np.asarray(latent, dtype=np.float64)
        if latent.ndim != 2 or len(latent) == 0 or not np.isfinite(latent).all():
            raise ValueError(f"tree codes must be a finite, non-empty (N, d) array, got shape {latent.shape}")
        points = latent if features is None else np.asarray(features, dtype=np.float64).reshape(len(features), -1)
        if len(points) != len(latent) or not np.isfinite(points).all():
            raise ValueError(f"tree features must be finite with one row per code: {len(points)} rows for "
                             f"{len(latent)} codes")
        space = space or ("latent" if features is None else "features")
        order: list[np.ndarray] = []
        nodes: list[dict] = []

        def grow(idx: np.ndarray) -> int:
            node = len(nodes)
            nodes.append({"centroid": latent[idx].mean(0), "children": []})
            parts = _split(points[idx], branching, split, seed) if len(idx) > leaf_size else []
            if len([p for p in parts if len(p)]) < 2:
                nodes[node]["start"] = sum(len(o) for o in order)
                order.append(idx)
                nodes[node]["stop"] = nodes[node]["start"] + len(idx)
                return node
            nodes[node]["start"] = sum(len(o) for o in order)
            nodes[node]["children"] = [grow(idx[p]) for p in parts if len(p)]
            nodes[node]["stop"] = sum(len(o) for o in order)
            return node

        grow(np.arange(len(latent)))
        children = np.full((len(nodes), branching), -1, dtype=np.int64)
        for i, n in enumerate(nodes):
            children[i, :len(n["children"])] = n["children"]
        return cls(latent[np.concatenate(order)], np.stack([n["centroid"] for n in nodes]), children,
                   np.array([n["start"] for n in nodes]), np.array([n["stop"] for n in nodes]), split, space)

    @property
    def is_leaf(self) -> np.ndarray:
        """``(M,)`` True where the node has no children."""
        return (self.children < 0).all(1)

    def node_bounds(self, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per-node elementwise ``(min, max)`` ``(M, ...)`` of per-code ``values`` ``(N, ...)`` (in the order of
        :attr:`latent`): the boxes that bound every code below each node."""
        values = np.asarray(values)
        if len(values) != len(self.latent):
            raise ValueError(f"need one value per code: {len(values)} for {len(self.latent)} codes")
        lo = np.empty((len(self.start),) + values.shape[1:], values.dtype)
        hi = np.empty_like(lo)
        leaf = self.is_leaf
        for node in range(len(self.start) - 1, -1, -1):  # children have larger ids: bottom-up in one pass
            if leaf[node]:
                part = values[self.start[node]:self.stop[node]]
                lo[node], hi[node] = part.min(0), part.max(0)
            else:
                kids = self.children[node][self.children[node] >= 0]
                lo[node], hi[node] = lo[kids].min(0), hi[kids].max(0)
        return lo, hi

    @property
    def depth(self) -> int:
        def down(node: int) -> int:
            kids = [c for c in self.children[node] if c >= 0]
            return 1 + (max(down(c) for c in kids) if kids else 0)
        return down(0)

    def search(self, objective: Callable[[np.ndarray], np.ndarray], candidates: int = 4) -> SearchResult:
        """The code minimizing ``objective`` (``(m, d)`` codes → ``(m,)`` costs) found by the beam descent."""
        if candidates < 1:
            raise ValueError(f"candidates must be ≥ 1, got {candidates}")
        beam, evaluations, leaves = [0], 0, []
        while beam:
            kids = np.array([c for n in beam for c in self.children[n] if c >= 0], dtype=np.int64)
            leaves += [n for n in beam if (self.children[n] < 0).all()]
            if not len(kids):
                break
            cost = np.asarray(objective(self.centroid[kids]), dtype=np.float64)
            evaluations += len(kids)
            beam = [int(k) for k in kids[np.argsort(cost, kind="stable")[:candidates]]]
        rows = np.concatenate([np.arange(self.start[n], self.stop[n]) for n in leaves])
        cost = np.asarray(objective(self.latent[rows]), dtype=np.float64)
        best = int(np.argmin(cost))
        return SearchResult(self.latent[rows[best]], float(cost[best]), evaluations + len(rows), int(rows[best]))

    def search_bounded(self, objective: Callable[[np.ndarray], np.ndarray],
                       lower_bound: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
                       max_evaluations: int = 120, guess_weight: float = 0.3, batch: int = 16) -> SearchResult:
        """Branch and bound (see the module doc).

        Args:
            objective: ``(m, d)`` codes → ``(m,)`` costs.
            lower_bound: ``(n,)`` node ids → ``(bound, guess)``, each ``(n,)``: ``bound`` ≤ the objective of
                every code below each node; ``guess`` a rough estimate of it (e.g. the distance to the node
                box's centre). Called once, on every node (no decoding: ``bound_checks`` counts them).
            max_evaluations: codes evaluated before the search stops (it finishes the leaves it opened).
            guess_weight: nodes are opened in the order of ``bound + guess_weight · guess`` (0: by the bound).
            batch: leaves that come next in that order are evaluated together, up to this many codes (one
                objective call; fewer calls, the same budget).
        """
        if max_evaluations < 1 or batch < 1:
            raise ValueError(f"max_evaluations and batch must be ≥ 1, got {max_evaluations}, {batch}")
        leaf = self.is_leaf
        bounds, guesses = (np.asarray(v, dtype=np.float64) for v in lower_bound(np.arange(len(self.start))))
        order = bounds + guess_weight * guesses
        heap: list[tuple[float, int]] = [(float(order[0]), 0)]
        by_bound: list[tuple[float, int]] = [(float(bounds[0]), 0)]  # the same nodes by bound (popped ones lazily)
        popped: set[int] = set()
        best, best_row, evaluations = np.inf, -1, 0

        def smallest_bound() -> float:
            while by_bound and by_bound[0][1] in popped:
                heapq.heappop(by_bound)
            return by_bound[0][0] if by_bound else np.inf

        def push(node: int) -> None:
            heapq.heappush(heap, (float(order[node]), node))
            heapq.heappush(by_bound, (float(bounds[node]), node))

        def pop() -> int:
            node = heapq.heappop(heap)[1]
            popped.add(node)
            return node

        while heap and evaluations < max_evaluations and smallest_bound() < best:
            node = pop()
            if bounds[node] >= best:
                continue
            if not leaf[node]:
                for kid in self.children[node][self.children[node] >= 0]:
                    push(int(kid))
                continue
            opened = [node]
            size = self.stop[node] - self.start[node]
            while (heap and leaf[heap[0][1]] and evaluations + size < max_evaluations
                   and size + self.stop[heap[0][1]] - self.start[heap[0][1]] <= batch):
                more = pop()
                if bounds[more] < best:
                    opened.append(more)
                    size += self.stop[more] - self.start[more]
            rows = np.concatenate([np.arange(self.start[n], self.stop[n]) for n in opened])
            cost = np.asarray(objective(self.latent[rows]), dtype=np.float64)
            evaluations += len(rows)
            i = int(np.argmin(cost))
            if cost[i] < best:
                best, best_row = float(cost[i]), int(rows[i])
        return SearchResult(self.latent[best_row], best, evaluations, best_row, len(self.start),
                            smallest_bound() >= best)

    def to_arrays(self, prefix: str = "tree_") -> dict[str, np.ndarray]:
        return {f"{prefix}latent": self.latent.astype(np.float32),
                f"{prefix}centroid": self.centroid.astype(np.float32),
                f"{prefix}children": self.children.astype(np.int32), f"{prefix}start": self.start.astype(np.int32),
                f"{prefix}stop": self.stop.astype(np.int32), f"{prefix}split": np.array(self.split),
                f"{prefix}space": np.array(self.space)}

    @classmethod
    def from_arrays(cls, arrays, prefix: str = "tree_") -> SpaceTree:
        keys = set(arrays.files if hasattr(arrays, "files") else arrays)
        space = str(arrays[f"{prefix}space"]) if f"{prefix}space" in keys else "latent"  # files before the option
        return cls(np.asarray(arrays[f"{prefix}latent"], dtype=np.float64),
                   np.asarray(arrays[f"{prefix}centroid"], dtype=np.float64),
                   np.asarray(arrays[f"{prefix}children"], dtype=np.int64),
                   np.asarray(arrays[f"{prefix}start"], dtype=np.int64),
                   np.asarray(arrays[f"{prefix}stop"], dtype=np.int64), str(arrays[f"{prefix}split"]), space)


def brute_force(latent: np.ndarray, objective: Callable[[np.ndarray], np.ndarray], chunk: int = 2000
                ) -> SearchResult:
    """The best of all ``(N, d)`` codes (``N`` evaluations)."""
    cost = np.concatenate([np.asarray(objective(latent[i:i + chunk])) for i in range(0, len(latent), chunk)])
    best = int(np.argmin(cost))
    return SearchResult(latent[best], float(cost[best]), len(latent), best)


def _split(x: np.ndarray, branching: int, split: str, seed: int) -> list[np.ndarray]:
    """Indices (into ``x``) of each child."""
    if split == "kmeans":
        _, labels = kmeans2(x, branching, seed=np.random.default_rng(seed), minit="++")
    elif split == "gmm":
        labels = GaussianMixture(branching, covariance_type="diag", random_state=seed, reg_covar=1e-6).fit(x).predict(x)
    else:
        return [p for half in _median_halves(np.arange(len(x)), x) for p in _median_halves(half, x)]
    return [np.flatnonzero(labels == k) for k in range(branching)]


def _median_halves(idx: np.ndarray, x: np.ndarray) -> list[np.ndarray]:
    axis = int(np.argmax(x[idx].var(0)))
    order = idx[np.argsort(x[idx, axis], kind="stable")]
    return [order[: len(order) // 2], order[len(order) // 2:]]
