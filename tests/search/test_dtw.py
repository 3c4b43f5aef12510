"""Subsequence DTW reference (stylemotion.search.dtw): checked against brute-force path enumeration."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.search.dtw import feature_distances, subsequence_dtw, subsequence_dtw_features
from stylemotion.search.lng import ONLINE_STEPS, THESIS_STEPS, TakeBounds


def _walk(n: int, seed: int, dims: int = 4) -> np.ndarray:
    """``(n, dims)`` a random walk: smooth features whose frames are all distinct."""
    return np.cumsum(np.random.default_rng(seed).normal(size=(n, dims)), axis=0)


def _brute_force(cost: np.ndarray, takes: TakeBounds, steps) -> float:
    """Best accumulated cost over every path, enumerated recursively from every start frame; a skipped query
    frame costs its row's largest distance."""
    m, n = cost.shape
    skip = cost.max(axis=1)

    def best_from(i: int, g: int) -> float:
        here = cost[i, g]
        if i == m - 1:
            rest = [0.0]
        else:
            rest = []
        for dq, dg in steps:
            qi, gg = i + dq, g + dg
            if qi < m and gg < n and takes.remaining[g] >= dg:
                rest.append(best_from(qi, gg) + skip[i + 1:qi].sum())
        return here + min(rest) if rest else np.inf

    return min(best_from(0, g) for g in range(n))


def _path_cost(cost: np.ndarray, path: np.ndarray) -> float:
    """Sum of the path's cells plus the skipped rows' largest distances."""
    skipped = sorted(set(range(path[0, 0], path[-1, 0] + 1)) - set(path[:, 0]))
    return float(sum(cost[i, g] for i, g in path) + cost[skipped].max(axis=1).sum())


@pytest.mark.parametrize("steps", [THESIS_STEPS, ONLINE_STEPS, ((1, 0), (1, 1), (1, 2))])
@pytest.mark.parametrize("seed", range(4))
def test_matches_brute_force_enumeration(steps, seed):
    rng = np.random.default_rng(seed)
    cost = rng.random((4, 9))
    takes = TakeBounds.from_lengths([5, 4])
    result = subsequence_dtw(cost, takes, steps=steps)
    best = result.best
    assert best.cost == pytest.approx(_brute_force(cost, takes, steps), rel=1e-12)
    assert best.cost == pytest.approx(_path_cost(cost, best.path), rel=1e-12)
    assert best.path[0, 0] == 0 and best.path[-1, 0] == 3
    assert (best.start, best.end) == (best.path[0, 1], best.path[-1, 1])
    moves = {tuple(s) for s in np.diff(best.path, axis=0)}
    assert moves <= set(steps)


def test_cut_out_query_found_at_its_position_with_zero_cost():
    x = _walk(200, 0)
    takes = TakeBounds.from_lengths([80, 120])
    for start, m in ((10, 30), (95, 20), (150, 50)):
        result = subsequence_dtw_features(x[start:start + m], x, takes)
        assert (result.best.start, result.best.end, result.best.cost) == (start, start + m - 1, 0.0)
        assert result.best.take == (0 if start < 80 else 1)
        assert np.array_equal(result.best.path[:, 1], np.arange(start, start + m))


def test_time_stretched_queries_are_found():
    x = _walk(300, 1)
    start, m = 120, 40
    doubled = np.repeat(x[start:start + m], 2, axis=0)
    result = subsequence_dtw_features(doubled, x, steps=THESIS_STEPS)
    assert (result.best.start, result.best.end, result.best.cost) == (start, start + m - 1, 0.0)
    halved = x[start:start + m:2]
    end = start + 2 * (len(halved) - 1)
    best = subsequence_dtw_features(halved, x, steps=ONLINE_STEPS).best  # (1, 2) skips the dropped frames
    assert (best.start, best.end, best.cost) == (start, end, 0.0)
    best = subsequence_dtw_features(halved, x, steps=THESIS_STEPS).best  # pays for every dropped frame,
    assert abs(best.start - start) <= 2 and abs(best.end - end) <= 2  # so it may trim one at either end


def test_paths_never_cross_takes():
    x = _walk(100, 2)
    takes = TakeBounds.from_lengths([50, 50])
    query = x[40:60]  # straddles the boundary between the takes
    free = subsequence_dtw_features(query, x).best
    assert (free.start, free.end, free.cost) == (40, 59, 0.0)
    for steps in (THESIS_STEPS, ONLINE_STEPS):
        result = subsequence_dtw_features(query, x, takes, steps=steps, top=5)
        for match in result.matches:
            assert match.cost > 0
            assert len(set(takes.take_id[match.path[:, 1]])) == 1


def test_normalizations_rescale_the_same_paths():
    rng = np.random.default_rng(3)
    cost = rng.random((6, 40))
    plain = subsequence_dtw(cost, top=3, keep_matrix=True)
    assert np.array_equal(plain.accumulated[-1], plain.end_costs)
    assert plain.best.cost == plain.end_costs.min()
    by_length = subsequence_dtw(cost, normalize="length").best
    assert by_length.cost == pytest.approx(_path_cost(cost, by_length.path) / len(by_length.path))
    by_query = subsequence_dtw(cost, normalize="query")
    assert by_query.best.cost == plain.best.cost / 6
    assert np.array_equal(by_query.end_starts, plain.end_starts)


def test_ranked_matches_do_not_overlap():
    x = _walk(400, 4)
    query = x[50:80]
    db = x.copy()
    db[250:280] = query + 0.05  # a second, slightly worse copy
    result = subsequence_dtw_features(query, db, top=6)
    assert [(m.start, m.end) for m in result.matches[:2]] == [(50, 79), (250, 279)]
    costs = [m.cost for m in result.matches]
    assert costs == sorted(costs) and len(result.matches) == 6
    for a in range(6):
        for b in range(a + 1, 6):
            ma, mb = result.matches[a], result.matches[b]
            assert ma.end < mb.start or mb.end < ma.start


def test_feature_distances_are_euclidean():
    q, x = _walk(5, 5), _walk(7, 6)
    expected = np.linalg.norm(q[:, None] - x[None], axis=-1)
    assert np.allclose(feature_distances(q, x), expected)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"cost": np.ones(5)}, "non-empty"),
        ({"cost": np.ones((0, 5))}, "non-empty"),
        ({"cost": np.array([[0.0, np.nan]])}, "nan"),
        ({"cost": np.array([[0.0, np.inf]])}, "inf"),
        ({"cost": np.array([[0.0, -1.0]])}, "-1.0"),
        ({"cost": np.ones((2, 5)), "takes": TakeBounds.from_lengths([3])}, "3 database frames"),
        ({"cost": np.ones((2, 5)), "steps": ((0, 1),)}, "never advance"),
        ({"cost": np.ones((2, 5)), "steps": ((0, 0), (1, 1))}, "(0, 0)"),
        ({"cost": np.ones((2, 5)), "normalize": "mean"}, "mean"),
        ({"cost": np.ones((2, 5)), "top": 0}, "top"),
        ({"cost": np.ones((2, 5)), "ties": "last"}, "last"),
    ],
)
def test_bad_inputs_raise(kwargs, message):
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        subsequence_dtw(**kwargs)


def test_bad_features_raise():
    with pytest.raises(ValueError, match=r"\(3, 2\) and \(4, 3\)"):
        feature_distances(np.ones((3, 2)), np.ones((4, 3)))
    with pytest.raises(ValueError, match="non-finite"):
        feature_distances(np.full((3, 2), np.nan), np.ones((4, 2)))


def _argmin_starts(cost: np.ndarray, steps) -> np.ndarray:
    """Start frame of the best path ending at each last-row cell, written cell by cell with the exact argmin
    of the predecessor sums (first of least in step order; skipped query frames free)."""
    m, n = cost.shape
    acc, start = np.full((m, n), np.inf), np.full((m, n), -1)
    acc[0], start[0] = cost[0], np.arange(n)
    for i in range(1, m):
        for g in range(n):
            options = [(acc[i - dq, g - dg], start[i - dq, g - dg]) if i >= dq and g >= dg else (np.inf, -1)
                       for dq, dg in steps]
            best, s = min(options, key=lambda o: o[0])
            if np.isfinite(best):
                acc[i, g], start[i, g] = cost[i, g] + best, s
    return start[-1]


def test_ties_by_predecessor_take_the_exact_argmin_where_by_total_may_not():
    """Costs of a few fractions tie after rounding: ``ties="predecessor"`` follows the exact argmin on every
    matrix, ``"total"`` (the LNG's rule) picks another start on some; both give the same totals."""
    steps = ((1, 1), (2, 1), (1, 2))
    rng = np.random.default_rng(11)
    differed = 0
    for _ in range(60):
        cost = rng.integers(0, 8, (int(rng.integers(5, 15)), 40)) / int(rng.integers(3, 43))
        by_pred = subsequence_dtw(cost, steps=steps, skip_cost=0.0, ties="predecessor")
        by_total = subsequence_dtw(cost, steps=steps, skip_cost=0.0)
        assert np.array_equal(by_pred.end_starts, _argmin_starts(cost, steps))
        assert np.array_equal(by_pred.end_costs, by_total.end_costs)
        differed += not np.array_equal(by_total.end_starts, by_pred.end_starts)
    assert differed > 0
