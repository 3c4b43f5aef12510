"""What suite ``reconstruct`` counts for keyframes (stylemotion.reconstruct.benchmark): every attempted key pair is
counted, a pair that cannot be joined is a failure in the figures and in the validation score, the key pairs are the
ones ``keys_from_motion`` gives, and the choice of a setting follows the validation scores."""

from __future__ import annotations

import math

import numpy as np
import pytest
from reconstruct_fixtures import synthetic_split

from stylemotion.reconstruct.benchmark import (
    choose_queries,
    choose_setting,
    choose_smallest_within,
    error_figures,
    key_pairs,
    pair_outcome,
    pairs_figures,
    pairs_score,
)
from stylemotion.reconstruct.keyframes import DynamicMotionGraph, Keyframe, keys_from_motion

FPS = 30.0


@pytest.fixture(scope="module")
def split():
    return synthetic_split()


@pytest.fixture(scope="module")
def graph(split):
    return DynamicMotionGraph(split[0], clean=False)


def test_key_pairs_are_the_consecutive_keys_of_keys_from_motion(split):
    take = split[2][0]
    for spacing in (1.0, 2.0):
        pairs = key_pairs(take.positions, FPS, spacing, 0.2)
        keys = keys_from_motion(np.asarray(take.positions, np.float64), FPS, spacing, 0.2)
        assert len(pairs) == len(keys) - 1
        for (a, b), (ka, kb) in zip(pairs, zip(keys[:-1], keys[1:])):
            assert (a.time_s, b.time_s) == pytest.approx((ka.time_s, kb.time_s))
            np.testing.assert_array_equal(a.pose, ka.pose)
            np.testing.assert_array_equal(b.pose, kb.pose)
    assert key_pairs(take.positions[:20], FPS, 1.0, 0.2) == []  # 20 frames hold no two keys 1 s apart


def test_a_pair_that_cannot_be_joined_is_counted_as_a_failure(split, graph):
    """Held-out walk keys 2 s apart are all joined; a key moved 25 m away is not, and it is counted, not dropped."""
    take = [t for t in split[2] if t.content == "walk"][0]
    pairs = key_pairs(take.positions, FPS, 2.0, 0.5)
    small = DynamicMotionGraph(split[0], max_iterations=2, clean=False, index=graph.index)
    far = Keyframe(2.0, np.asarray(take.positions[80], np.float64) + np.array([25.0, 0.0, 0.0]))
    outcomes = [pair_outcome(graph, a, b) for a, b in pairs]
    outcomes.append(pair_outcome(small, pairs[0][0], far))
    figures = pairs_figures(outcomes)
    assert figures["attempted"] == len(pairs) + 1
    assert figures["joined"] == len(pairs) and figures["failed"] == 1
    assert outcomes[-1] == {"spacing_s": 2.0, "joined": False, "seconds": outcomes[-1]["seconds"]}
    for outcome in outcomes[:-1]:  # the duration error is the path's frames against the keys' 61 frames
        assert outcome["duration_error_s"] == pytest.approx((outcome["frames"] - 61) / FPS, abs=1e-4)
    # the failed pair enters the score with its whole spacing
    joined_mean = np.mean([abs(o["duration_error_s"]) for o in outcomes[:-1]])
    assert pairs_score(outcomes) == pytest.approx((joined_mean * len(pairs) + 2.0) / (len(pairs) + 1))
    assert figures["duration_error_s"]["max"] >= figures["duration_error_s"]["p95"] >= 0


def test_keys_of_a_database_take_are_joined_with_their_own_duration(split, graph):
    """Reference: the take's own frames are in the database, so each 1 s pair has a path of exactly 31 frames; the
    duration term must find one within a frame (without it, a shorter path would do)."""
    take = [t for t in split[1] if t.content == "walk"][0]
    outcomes = [pair_outcome(graph, a, b) for a, b in key_pairs(take.positions, FPS, 1.0, 0.5)[:3]]
    assert all(o["joined"] for o in outcomes)
    assert max(abs(o["duration_error_s"]) for o in outcomes) <= 1.0 / FPS + 1e-9


def test_choice_and_scores():
    assert choose_setting({0.0: 0.3, 1.0: 0.1, 10.0: 0.1, 30.0: None}) == 1.0  # lowest; first of a tie
    assert choose_setting({16: math.nan, 32: 2.0}) == 32
    with pytest.raises(ValueError, match="no candidate"):
        choose_setting({1: None})
    assert math.isnan(pairs_score([]))
    table = np.arange(42, dtype=float).reshape(2, 21)  # joint j: errors j and 21 + j
    figures = error_figures([table[:1], table[1:]])
    assert figures["mean_cm"] == pytest.approx(20.5) and figures["max_cm"] == 41.0
    assert figures["per_joint"]["Hips"] == {"mean_cm": 10.5, "p95_cm": pytest.approx(19.95), "max_cm": 21.0}


def test_smallest_candidate_within_a_tolerance_of_the_best():
    scores = {32: 0.95, 64: 0.77, 128: 0.67, 256: 0.651, 512: 0.640, 1024: 0.636}
    assert choose_smallest_within(scores, 0.0) == 1024  # the lowest itself
    assert choose_smallest_within(scores, 0.01) == 512  # 0.640 <= 1.01 * 0.636; 0.651 is not
    assert choose_smallest_within(scores, 0.03) == 256
    assert choose_smallest_within({64: math.nan, 128: None, 256: 1.0, 512: 0.99}, 0.5) == 256  # no score: never
    with pytest.raises(ValueError, match="tolerance"):
        choose_smallest_within(scores, -0.1)
    with pytest.raises(ValueError, match="no candidate"):
        choose_smallest_within({1: None}, 0.01)


def test_queries_are_drawn_by_seed_and_spread_over_styles(split):
    takes = split[1]
    a = choose_queries(takes, ["walk", "run"], 2, np.random.default_rng(0))
    b = choose_queries(takes, ["walk", "run"], 2, np.random.default_rng(0))
    assert [t.name for t in a] == [t.name for t in b]
    assert [t.content for t in a] == ["walk", "walk", "run", "run"]
    assert len({t.style for t in a[:2]}) == 2
    with pytest.raises(ValueError, match="no take of content"):
        choose_queries(takes, ["swim"], 1, np.random.default_rng(0))
