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
