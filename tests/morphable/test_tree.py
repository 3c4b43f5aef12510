"""The space-partitioning tree: brute-force optimum on small cases, evaluation counts, the three splits."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.morphable.tree import SpaceTree, brute_force


@pytest.mark.parametrize("split", ["kmeans", "gmm", "median"])
def test_tree_returns_the_brute_force_optimum_on_small_cases(split):
    rng = np.random.default_rng(0)
    codes = rng.standard_normal((64, 4))
    tree = SpaceTree.build(codes, leaf_size=4, split=split, seed=0)
    assert sorted(map(tuple, tree.latent)) == sorted(map(tuple, codes))  # every code in exactly one leaf
    leaves = [(int(a), int(b)) for a, b, kids in zip(tree.start, tree.stop, tree.children) if (kids < 0).all()]
    assert sum(b - a for a, b in leaves) == 64 and max(b - a for a, b in leaves) <= 4
    hits = 0
    for q in range(40):
        target = codes[rng.integers(64)] + rng.normal(0.0, 0.05, 4) if q < 20 else rng.normal(0.0, 1.0, 4)

        def cost(z, target=target):
            return np.linalg.norm(z - target, axis=-1)

        exact = brute_force(codes, cost)
        wide = tree.search(cost, candidates=len(tree.centroid))  # a beam holding every node: exhaustive
        assert wide.cost == exact.cost
        narrow = tree.search(cost, candidates=4)
        assert narrow.evaluations < 64 and narrow.cost >= exact.cost
        hits += q < 20 and narrow.cost == exact.cost
    assert hits >= 19  # near targets: the default beam finds the optimum (99 of 100 over five code sets, k-means)


def test_tree_arrays_round_trip_and_bad_input():
    codes = np.random.default_rng(1).standard_normal((300, 3))
    tree = SpaceTree.build(codes, seed=0)
    back = SpaceTree.from_arrays(tree.to_arrays())
    assert back.split == "kmeans" and np.array_equal(back.children, tree.children) and back.depth == tree.depth

    def cost(z):
        return np.abs(z).sum(-1)

    assert back.search(cost).index == tree.search(cost).index
    with pytest.raises(ValueError, match="unknown tree split 'kd'"):
        SpaceTree.build(codes, split="kd")
    with pytest.raises(ValueError, match="finite"):
        SpaceTree.build(np.full((5, 2), np.nan))
    with pytest.raises(ValueError, match="candidates"):
        tree.search(cost, candidates=0)


def _box_bound(tree: SpaceTree, points: np.ndarray, target: np.ndarray):
    """Distance from ``target`` to each node's box of ``points`` (a true lower bound of the distance cost)."""
    lo, hi = tree.node_bounds(points)

    def bound(nodes):
        gap = np.maximum(np.maximum(lo[nodes] - target, target - hi[nodes]), 0.0)
        return np.linalg.norm(gap, axis=-1), np.linalg.norm((lo[nodes] + hi[nodes]) / 2 - target, axis=-1)

    return bound


def test_node_bounds_hold_every_code_below_each_node():
    codes = np.random.default_rng(2).standard_normal((500, 3))
    tree = SpaceTree.build(codes, leaf_size=4, seed=0)
    lo, hi = tree.node_bounds(tree.latent)
    for node in range(len(tree.start)):
        part = tree.latent[tree.start[node]:tree.stop[node]]
        assert (part >= lo[node]).all() and (part <= hi[node]).all()
        assert np.allclose(part.min(0), lo[node]) and np.allclose(part.max(0), hi[node])
    with pytest.raises(ValueError, match="one value per code"):
        tree.node_bounds(tree.latent[:10])


@pytest.mark.parametrize("space", ["latent", "features"])
def test_bounded_search_proves_the_brute_force_optimum_and_keeps_its_budget(space):
    rng = np.random.default_rng(3)
    codes = rng.standard_normal((2000, 6))
    points = codes[:, :3] * [1.0, 0.5, 2.0] + 0.1 * codes[:, 3:]  # what the cost measures: 3 of 6 directions
    features = points if space == "features" else None
    tree = SpaceTree.build(codes, leaf_size=4, seed=0, features=features, space=space if features is not None else None)
    assert tree.space == space
    ordered = tree.latent[:, :3] * [1.0, 0.5, 2.0] + 0.1 * tree.latent[:, 3:]
    proved = 0
    for _ in range(30):
        target = ordered[rng.integers(len(ordered))] + rng.normal(0.0, 0.05, 3)

        def cost(z, target=target):
            return np.linalg.norm(z[:, :3] * [1.0, 0.5, 2.0] + 0.1 * z[:, 3:] - target, axis=-1)

        exact = brute_force(tree.latent, cost)
        full = tree.search_bounded(cost, _box_bound(tree, ordered, target), max_evaluations=len(codes))
        assert full.exact and full.cost == exact.cost and full.index == exact.index
        assert full.evaluations < len(codes) and full.bound_checks > 0
        small = tree.search_bounded(cost, _box_bound(tree, ordered, target), max_evaluations=40)
        assert small.evaluations < 40 + 4 and small.cost >= exact.cost  # stops within the leaf it opened
        proved += small.exact
        if small.exact:
            assert small.cost == exact.cost
    if space == "features":  # boxes of the very values the cost measures: most searches end proved optimal
        assert proved >= 20
    with pytest.raises(ValueError, match="max_evaluations"):
        tree.search_bounded(cost, _box_bound(tree, ordered, target), max_evaluations=0)
