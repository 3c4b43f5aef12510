"""Shortest forward walks of bounded curvature (Dubins paths): the cost-to-go of the keyframe search's D_node."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.reconstruct.turning import dubins_length, walk_end


def test_length_bounds_every_walk_and_meets_many():
    rng = np.random.default_rng(3)
    radius = 0.7
    equal = 0
    for _ in range(600):
        start, yaw = rng.uniform(-3, 3, 2), rng.uniform(-np.pi, np.pi)
        word = "".join(rng.choice(list("LRS"), 3))
        lengths = tuple(rng.uniform(0.0, 3.0, 3))
        end, end_yaw = walk_end(start, yaw, word, lengths, radius)
        shortest = float(dubins_length(start, yaw, end, end_yaw, radius))
        # no walk of that turning radius is shorter than the shortest, none shorter than the straight line
        assert np.linalg.norm(end - start) - 1e-9 <= shortest <= sum(lengths) + 1e-6, (word, lengths, shortest)
        equal += abs(shortest - sum(lengths)) < 1e-6
    # many random walks are shortest themselves (measured 53 %); a formula that missed a word would lower this
    assert equal > 0.4 * 600


def test_known_lengths_and_broadcasting():
    r = 0.5
    zero = np.zeros(2)
    # straight ahead (yaw 0 faces +z): the distance; a half circle to the left (+x): π r
    assert dubins_length(zero, 0.0, np.array([0.0, 2.0]), 0.0, r) == pytest.approx(2.0)
    assert dubins_length(zero, 0.0, np.array([2 * r, 0.0]), np.pi, r) == pytest.approx(np.pi * r)
    # a key behind, facing back: a loop, longer than going straight there and back
    assert dubins_length(zero, 0.0, np.array([0.0, 2.0]), np.pi, r) > 2.0 + np.pi * r - 1e-9
    # turning on the spot is not free: at least a full circle's worth of walking
    assert dubins_length(zero, 0.0, zero, np.pi, r) > np.pi * r
    grid = dubins_length(np.zeros((4, 1, 2)), np.zeros((4, 1)), np.ones((1, 5, 2)), np.zeros((1, 5)), r)
    assert grid.shape == (4, 5) and np.isfinite(grid).all()
    with pytest.raises(ValueError, match="radius=0"):
        dubins_length(zero, 0.0, zero, 0.0, 0.0)
