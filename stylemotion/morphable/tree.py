"""Space-partitioning tree over a primitive's latent samples (Du §4.4.2, §4.5.2).

``N`` codes drawn from the primitive's mixture (10,000 by default) are split recursively into
``branching`` (4) children until a node holds at most ``leaf_size`` codes. Splits:

* ``kmeans`` (the thesis'): k-means (scipy's ``kmeans2``, k-means++ start, seeded) on the node's codes;
* ``gmm``: a ``branching``-component Gaussian mixture, codes to their most likely component;
* ``median``: median splits along the axis of largest spread, twice per level (4 children).

Every node is represented by the mean of its codes. :meth:`SpaceTree.search` descends with a beam of
``candidates`` nodes: at each level the children of the kept nodes are scored by the objective (one
evaluation each, on their mean code), the ``candidates`` best are kept, and at the bottom every code of
the kept leaves is scored. Evaluations: O(levels × branching × candidates). The tree is plain arrays
(:meth:`SpaceTree.to_arrays`), saved inside the model's ``.npz``.
"""

from __future__ import annotations

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
    """The best code found, its objective value and how many codes were evaluated."""

    latent: np.ndarray
    cost: float
    evaluations: int
    index: int = -1


@dataclass
class SpaceTree:
    """Attributes: ``latent`` ``(N, d)`` codes, ordered so every node's codes are contiguous;
    ``centroid`` ``(M, d)`` node means; ``children`` ``(M, branching)`` child node ids (-1: none; a node
    without children is a leaf); ``start``/``stop`` ``(M,)`` the node's codes ``latent[start:stop]``;
    ``split``: how it was built. Node 0 is the root."""

    latent: np.ndarray
    centroid: np.ndarray
    children: np.ndarray
    start: np.ndarray
    stop: np.ndarray
    split: str = "kmeans"

    @classmethod
    def build(cls, latent: np.ndarray, branching: int = 4, leaf_size: int = 16, split: str = "kmeans",
              seed: int = 0) -> SpaceTree:
        """Build over ``(N, d)`` codes (see the module doc)."""
        if split not in SPLITS:
            raise ValueError(f"unknown tree split {split!r}; one of {list(SPLITS)}")
        if branching < 2 or leaf_size < 1:
            raise ValueError(f"need branching ≥ 2 and leaf_size ≥ 1, got {branching}, {leaf_size}")
        if split == "median" and branching != 4:
            raise ValueError("the median tree splits twice per level: branching must be 4")
        latent = np.asarray(latent, dtype=np.float64)
        if latent.ndim != 2 or len(latent) == 0 or not np.isfinite(latent).all():
            raise ValueError(f"tree codes must be a finite, non-empty (N, d) array, got shape {latent.shape}")
        order: list[np.ndarray] = []
        nodes: list[dict] = []

        def grow(idx: np.ndarray) -> int:
            node = len(nodes)
            nodes.append({"centroid": latent[idx].mean(0), "children": []})
            parts = _split(latent[idx], branching, split, seed) if len(idx) > leaf_size else []
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
                   np.array([n["start"] for n in nodes]), np.array([n["stop"] for n in nodes]), split)

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

    def to_arrays(self, prefix: str = "tree_") -> dict[str, np.ndarray]:
        return {f"{prefix}latent": self.latent.astype(np.float32), f"{prefix}centroid": self.centroid,
                f"{prefix}children": self.children, f"{prefix}start": self.start, f"{prefix}stop": self.stop,
                f"{prefix}split": np.array(self.split)}

    @classmethod
    def from_arrays(cls, arrays, prefix: str = "tree_") -> SpaceTree:
        return cls(np.asarray(arrays[f"{prefix}latent"], dtype=np.float64), arrays[f"{prefix}centroid"],
                   arrays[f"{prefix}children"], arrays[f"{prefix}start"], arrays[f"{prefix}stop"],
                   str(arrays[f"{prefix}split"]))


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
