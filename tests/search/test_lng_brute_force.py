"""The LNG and the benchmark's helpers against independent references: a plain-Python subsequence DTW
(tests/dtw_reference.py: a double loop over cells, no code shared with stylemotion.search), scipy's Spearman ρ,
and counting."""

from __future__ import annotations

import math

import numpy as np
import pytest
from dtw_reference import brute_dtw
from scipy.stats import spearmanr

from stylemotion.search.dtw import best_subsequence_match, feature_distances, subsequence_dtw
from stylemotion.search.evaluation import precision_at, spearman_with_misses, summarize_lng
from stylemotion.search.lng import TakeBounds, lng_match


def _case(seed: int) -> tuple[np.ndarray, list[int], np.random.Generator]:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(12, 40))
    cuts = np.sort(rng.choice(np.arange(1, n), size=int(rng.integers(0, 4)), replace=False))
    lengths = np.diff(np.concatenate([[0], cuts, [n]])).tolist()
    walk = np.cumsum(rng.normal(size=(n, 3)), axis=0)
    m = int(rng.integers(2, 7))
    begin = int(rng.integers(0, n - m + 1))
    query = walk[begin:begin + m] + rng.normal(scale=rng.choice([0.1, 1.0]), size=(m, 3))
    return feature_distances(query, walk), lengths, rng


def test_lng_equals_brute_force_dtw_over_its_nodes_and_counts_its_misses():
    """With k neighbours per query frame, the LNG's best match is the brute-force DTW best over the cells that
    are neighbours (no path exactly when that DTW has none), never cheaper than DTW over all cells, and equal to
    it at k = n. Across the cases some queries have no path at small k: the counts must agree."""
    lng_misses = brute_misses = checked = 0
    for seed in range(40):
        cost, lengths, rng = _case(seed)
        n = cost.shape[1]
        takes = TakeBounds.from_lengths(lengths)
        full = brute_dtw(cost, lengths)
        for k in (1, 2, 3, 5, n):
            order = np.argsort(cost, axis=1, kind="stable")[:, :k]
            shuffled = np.take_along_axis(order, np.argsort(rng.random(order.shape), axis=1), axis=1)
            dist = np.take_along_axis(cost, shuffled, axis=1)
            found = lng_match(shuffled, dist, takes, top=1)
            masked = np.full_like(cost, np.inf)
            np.put_along_axis(masked, order, np.take_along_axis(cost, order, axis=1), axis=1)
            ref = brute_dtw(masked, lengths)
            lng_misses += not found
            brute_misses += not math.isfinite(ref[0])
            assert (not found) == (not math.isfinite(ref[0])), (seed, k)
            checked += 1
            if found:
                best = found[0]
                assert best.cost == pytest.approx(ref[0], rel=1e-12, abs=1e-12), (seed, k)
                assert best.cost >= full[0] - 1e-12
                if k == n:
                    assert (best.start, best.end) == (full[1], full[2]), seed
            if k == n:
                assert found and best.cost == pytest.approx(full[0], rel=1e-12)
    assert lng_misses == brute_misses
    assert 0 < lng_misses < checked  # the cases exercise both outcomes


@pytest.mark.parametrize("seed", range(6))
def test_exact_dtw_with_take_bounds_equals_brute_force(seed):
    """best_subsequence_match (the benchmark's DTW: skips takes whose lower bound exceeds the best cost) returns
    the brute-force best and the full sweep's segment, with or without an upper bound."""
    rng = np.random.default_rng(100 + seed)
    lengths = rng.integers(5, 30, size=int(rng.integers(3, 12))).tolist()
    walk = np.cumsum(rng.normal(size=(sum(lengths), 4)), axis=0)
    m = int(rng.integers(2, 8))
    begin = int(rng.integers(0, sum(lengths) - m))
    query = walk[begin:begin + m] + rng.normal(scale=0.5, size=(m, 4))
    cost = feature_distances(query, walk)
    takes = TakeBounds.from_lengths(lengths)
    ref = brute_dtw(cost, lengths)
    sweep = subsequence_dtw(cost, takes).best
    for upper in (None, ref[0] * 1.5, ref[0]):
        got, swept = best_subsequence_match(query, walk, takes, upper_bound=upper, first_takes=2)
        assert got.cost == pytest.approx(ref[0], rel=1e-12)
        assert (got.start, got.end, got.take) == (sweep.start, sweep.end, sweep.take)
        assert np.array_equal(got.path, sweep.path)
        assert 1 <= swept <= len(lengths)


def test_spearman_with_misses_against_scipy():
    rng = np.random.default_rng(7)
    dtw = rng.random(30)
    lng = dtw * (1 + rng.random(30))
    missed = rng.random(30) < 0.3
    with_misses = [None if miss else float(v) for miss, v in zip(missed, lng)]
    worst = np.where(missed, lng.max() + 1.0, lng)  # every miss tied at the worst rank
    assert spearman_with_misses(with_misses, dtw) == pytest.approx(spearmanr(worst, dtw).statistic, rel=1e-12)
    assert spearman_with_misses(list(lng), dtw) == pytest.approx(spearmanr(lng, dtw).statistic, rel=1e-12)
    assert spearman_with_misses([None, None, None], [1.0, 2.0, 3.0]) is None
    assert spearman_with_misses([1.0, 2.0], [1.0, 2.0]) is None
    with pytest.raises(ValueError, match="3 LNG costs but 2 DTW costs"):
        spearman_with_misses([1.0, 2.0, 3.0], [1.0, 2.0])


def test_precision_counts_missing_matches_wrong():
    assert precision_at(["walk"] * 4, "walk", 10) == 0.4
    assert precision_at(["walk", "run"] + ["walk"] * 12, "walk", 10) == 0.9
    assert precision_at([], "walk", 10) == 0.0
    with pytest.raises(ValueError, match="n must be ≥ 1"):
        precision_at(["walk"], "walk", 0)


def test_summary_counts_no_path_queries_as_misses():
    hit = {"no_path": False, "same_segment": True, "overlap": True, "cost_ratio": 1.0, "lng_cost": 1.0, "dtw_cost": 1.0}
    near = {**hit, "same_segment": False, "cost_ratio": 1.5, "lng_cost": 3.0, "dtw_cost": 2.0}
    miss = {"no_path": True, "same_segment": False, "overlap": False, "cost_ratio": None, "lng_cost": None,
            "dtw_cost": 3.0}
    s = summarize_lng([hit, near, miss, miss])
    assert (s["queries"], s["no_path"], s["same_segment"], s["overlap"]) == (4, 2, 0.25, 0.5)
    assert (s["cost_ratio_n"], s["cost_ratio_max"], s["cost_ratio_mean"]) == (2, 1.5, 1.25)
    assert s["lng_never_below_dtw"] is True


def test_rank_agreement_against_scipy():
    from stylemotion.datasets.registry import load_dataset
    from stylemotion.search import FrameIndex, MotionDatabase
    from stylemotion.search.evaluation import rank_agreement

    database = MotionDatabase.from_takeset(load_dataset("synthetic", takes_per_pair=1, contents=["walk"]))
    rng = np.random.default_rng(3)
    base = rng.normal(size=(database.num_frames, 15)).astype(np.float32)
    indexes = {"E15": FrameIndex(database, "E15", base),
               "pca8": FrameIndex(database, "pca8", (base[:, :8] + rng.normal(scale=0.5, size=(len(base), 8)))
                                  .astype(np.float32))}
    frames = rng.choice(database.num_frames, 12, replace=False)
    got = rank_agreement(indexes, frames, 20)
    for a, ia in indexes.items():
        _, near = ia.query(ia.features[frames], 20)
        for b, ib in indexes.items():
            rhos = [spearmanr(np.linalg.norm(ia.features[n] - ia.features[f], axis=1),
                              np.linalg.norm(ib.features[n] - ib.features[f], axis=1)).statistic
                    for f, n in zip(frames, near)]
            assert got[a][b] == pytest.approx(float(np.mean(rhos)), rel=1e-9)
    assert got["E15"]["E15"] == pytest.approx(1.0) and got["E15"]["pca8"] < 0.9
