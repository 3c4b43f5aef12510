"""Lazy neighbourhood graph matching (stylemotion.search.lng), validated against subsequence DTW."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.search.dtw import feature_distances, subsequence_dtw
from stylemotion.search.lng import (
    ONLINE_STEPS,
    THESIS_STEPS,
    Match,
    OnlineLNG,
    TakeBounds,
    lng_match,
)

STEP_SETS = [THESIS_STEPS, ONLINE_STEPS, ((1, 0), (1, 1), (1, 2)), ((1, 1), (0, 1), (0, 2), (2, 1), (1, 0))]


def _walk(n: int, seed: int, dims: int = 4) -> np.ndarray:
    """``(n, dims)`` a random walk: smooth features whose frames are all distinct."""
    return np.cumsum(np.random.default_rng(seed).normal(size=(n, dims)), axis=0)


def _knn(cost: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Brute-force ``k`` nearest database frames per query frame from a ``(m, n)`` distance matrix."""
    ind = np.argsort(cost, axis=1, kind="stable")[:, :k]
    return ind, np.take_along_axis(cost, ind, axis=1)


def _all_neighbours(cost: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Every database frame a neighbour of every query frame, in a random order per row."""
    ind = np.argsort(rng.random(cost.shape), axis=1)
    return ind, np.take_along_axis(cost, ind, axis=1)


def _random_takes(n: int, rng: np.random.Generator) -> TakeBounds:
    lengths, left = [], n
    while left:
        lengths.append(int(rng.integers(1, left + 1)))
        left -= lengths[-1]
    return TakeBounds.from_lengths(lengths)


def _same(a: Match, b: Match, query_offset: int = 0) -> None:
    assert (a.start, a.end, a.cost, a.take) == (b.start, b.end, b.cost, b.take)
    assert np.array_equal(a.path[:, 1], b.path[:, 1])
    assert np.array_equal(a.path[:, 0] + query_offset, b.path[:, 0])


@pytest.mark.parametrize("steps", STEP_SETS)
@pytest.mark.parametrize("normalize", ["none", "length", "query"])
@pytest.mark.parametrize("seed", range(6))
def test_equals_dtw_exactly_when_every_frame_is_a_neighbour(steps, normalize, seed):
    rng = np.random.default_rng(seed)
    m, n = int(rng.integers(1, 8)), int(rng.integers(5, 40))
    cost = rng.random((m, n))
    if seed % 2:
        cost = cost.round(1)  # many exact ties: the tie order must agree too
    takes = _random_takes(n, rng)
    ind, dist = _all_neighbours(cost, rng)
    lng = lng_match(ind, dist, takes, steps=steps, normalize=normalize, top=5)
    dtw = subsequence_dtw(cost, takes, steps=steps, normalize=normalize, top=5).matches
    assert len(lng) == len(dtw)
    for a, b in zip(lng, dtw):
        _same(a, b)


def test_cut_out_query_found_at_its_position_with_zero_cost():
    x = _walk(300, 0)
    takes = TakeBounds.from_lengths([100, 120, 80])
    for start, m in ((5, 30), (130, 30), (230, 60)):
        ind, dist = _knn(feature_distances(x[start:start + m], x), 16)
        best = lng_match(ind, dist, takes)[0]
        assert (best.start, best.end, best.cost) == (start, start + m - 1, 0.0)
        assert best.take == int(takes.take_id[start])
        assert np.array_equal(best.path, np.stack([np.arange(m), np.arange(start, start + m)], axis=1))
        assert np.array_equal(best.frames_per_query(), np.arange(start, start + m))


def test_time_stretched_queries_are_found():
    x = _walk(400, 1)
    start, m = 200, 40
    doubled = np.repeat(x[start:start + m], 2, axis=0)
    ind, dist = _knn(feature_distances(doubled, x), 16)
    best = lng_match(ind, dist, np.ones(400, bool))[0]
    assert (best.start, best.end, best.cost) == (start, start + m - 1, 0.0)
    assert np.array_equal(best.frames_per_query(), np.repeat(np.arange(start, start + m), 2))
    halved = x[start:start + m:2]
    ind, dist = _knn(feature_distances(halved, x), 16)
    best = lng_match(ind, dist, np.ones(400, bool), steps=ONLINE_STEPS)[0]
    assert (best.start, best.end, best.cost) == (start, start + m - 2, 0.0)


def test_paths_never_cross_takes():
    x = _walk(120, 2)
    takes = TakeBounds.from_lengths([60, 60])
    query = x[50:70]  # straddles the boundary between the takes
    cost = feature_distances(query, x)
    ind, dist = _all_neighbours(cost, np.random.default_rng(0))
    free = lng_match(ind, dist, np.ones(120, bool))[0]
    assert (free.start, free.end, free.cost) == (50, 69, 0.0)
    for steps in STEP_SETS:
        matches = lng_match(ind, dist, takes, steps=steps, top=5)
        reference = subsequence_dtw(cost, takes, steps=steps, top=5).matches
        for match, ref in zip(matches, reference):
            _same(match, ref)
            assert match.cost > 0
            assert len(set(takes.take_id[match.path[:, 1]])) == 1


@pytest.mark.parametrize("steps", STEP_SETS)
@pytest.mark.parametrize("seed", range(5))
def test_fewer_neighbours_can_only_miss_paths(steps, seed):
    x = _walk(150, 10 + seed)
    takes = TakeBounds.from_lengths([70, 80])
    start = 20 + 7 * seed
    query = x[start:start + 25] + np.random.default_rng(seed).normal(scale=0.8, size=(25, 4))
    cost = feature_distances(query, x)
    dtw = subsequence_dtw(cost, takes, steps=steps, skip_cost=0.5).best  # one skip penalty for both
    for k in (2, 4, 8):
        ind, dist = _knn(cost, k)
        found = lng_match(ind, dist, takes, steps=steps, skip_cost=0.5)
        assert not found or found[0].cost >= dtw.cost
    # add the DTW path's nodes to the 2 nearest (radius-style padded rows): then the costs are equal
    ind, dist = _knn(cost, 2)
    extra = [sorted(set(dtw.path[dtw.path[:, 0] == i, 1]) - set(ind[i])) for i in range(25)]
    width = 2 + max(len(e) for e in extra)
    rows_i = np.full((25, width), -1)
    rows_d = np.full((25, width), np.inf)
    for i in range(25):
        frames = np.concatenate([ind[i], extra[i]]).astype(int)
        rows_i[i, :frames.size], rows_d[i, :frames.size] = frames, cost[i, frames]
    best = lng_match(rows_i, rows_d, takes, steps=steps, skip_cost=0.5)[0]
    assert best.cost == dtw.cost
    assert (best.start, best.end) == (dtw.start, dtw.end)


def test_radius_padding_is_ignored():
    x = _walk(200, 3)
    query = x[60:90] + 0.01
    cost = feature_distances(query, x)
    ind, dist = _knn(cost, 8)
    plain = lng_match(ind, dist, np.ones(200, bool), top=3)
    padded_i = np.concatenate([ind, np.full((30, 3), -1), np.full((30, 2), 200)], axis=1)  # cKDTree pads with n
    padded_d = np.concatenate([dist, np.full((30, 3), np.inf), np.full((30, 2), np.inf)], axis=1)
    order = np.argsort(np.random.default_rng(0).random(padded_i.shape), axis=1)
    padded = lng_match(np.take_along_axis(padded_i, order, 1), np.take_along_axis(padded_d, order, 1),
                       np.ones(200, bool), top=3)
    assert len(plain) == len(padded) >= 1
    for a, b in zip(plain, padded):
        _same(a, b)
    only_padding = lng_match(np.full((4, 3), -1), np.full((4, 3), np.inf), np.ones(200, bool))
    assert only_padding == []


def test_paths_follow_steps_and_neighbours_and_cost_is_their_sum():
    x = _walk(300, 4)
    query = x[100:140:2] + np.random.default_rng(1).normal(scale=0.3, size=(20, 4))
    cost = feature_distances(query, x)
    ind, dist = _knn(cost, 32)

    def path_cost(path: np.ndarray) -> tuple[float, int]:
        skipped = sorted(set(range(20)) - set(path[:, 0]))  # a skipped frame costs its 32nd distance
        return sum(cost[i, g] for i, g in path) + dist[skipped].max(axis=1).sum(), len(path) + len(skipped)

    for steps in STEP_SETS:
        for normalize in ("none", "length", "query"):
            for match in lng_match(ind, dist, np.ones(300, bool), steps=steps, normalize=normalize, top=4):
                assert {tuple(s) for s in np.diff(match.path, axis=0)} <= set(steps)
                assert match.path[0, 0] == 0 and match.path[-1, 0] == 19
                assert all(g in ind[i] for i, g in match.path)
                total, length = path_cost(match.path)
                scale = {"none": 1, "length": length, "query": 20}[normalize]
                assert match.cost == pytest.approx(total / scale, rel=1e-12)


def test_ranking_and_overlap_suppression():
    x = _walk(600, 5)
    query = x[100:130]
    db = x.copy()
    db[300:330] = query + 0.05
    db[450:480] = query + 0.2
    cost = feature_distances(query, db)
    ind, dist = _knn(cost, 24)
    matches = lng_match(ind, dist, TakeBounds.from_lengths([250, 350]), top=10)
    assert [(m.start, m.end) for m in matches[:3]] == [(100, 129), (300, 329), (450, 479)]
    assert [m.take for m in matches[:3]] == [0, 1, 1]
    costs = [m.cost for m in matches]
    assert costs == sorted(costs) and costs[0] == 0.0
    for a in range(len(matches)):
        for b in range(a + 1, len(matches)):
            assert matches[a].end < matches[b].start or matches[b].end < matches[a].start
    assert len(lng_match(ind, dist, np.ones(600, bool), top=2)) == 2


def test_take_bounds():
    takes = TakeBounds.from_lengths([3, 1, 2])
    assert takes.remaining.tolist() == [2, 1, 0, 0, 1, 0]
    assert takes.take_id.tolist() == [0, 0, 0, 1, 2, 2]
    same = TakeBounds.from_next_in_take(np.array([1, 1, 0, 0, 1, 1], bool), take_ids=np.array([7, 7, 7, 3, 5, 5]))
    assert same.remaining.tolist() == takes.remaining.tolist()
    assert same.take_id.tolist() == [7, 7, 7, 3, 5, 5]
    assert takes.allows(np.array([-1, 0, 1, 2, 5, 6]), 1).tolist() == [False, True, True, False, False, False]
    with pytest.raises(ValueError, match="frames 1 and 2"):
        TakeBounds.from_next_in_take(np.array([1, 1, 0], bool), take_ids=np.array([0, 0, 1]))
    with pytest.raises(ValueError, match="boolean"):
        TakeBounds.from_next_in_take(np.array([1, 0]))
    with pytest.raises(ValueError, match=r"\[2, 0\]"):
        TakeBounds.from_lengths([2, 0])


TAKES = TakeBounds.from_lengths([10])


@pytest.mark.parametrize(
    ("indices", "distances", "kwargs", "message"),
    [
        (np.arange(3), np.ones(3), {}, r"shape \(m, k\), got \(3,\)"),
        (np.zeros((2, 3), int), np.ones((2, 2)), {}, r"\(2, 2\), indices \(2, 3\)"),
        (np.zeros((0, 3), int), np.ones((0, 3)), {}, "empty"),
        (np.zeros((2, 0), int), np.ones((2, 0)), {}, "empty"),
        (np.zeros((1, 2)), np.ones((1, 2)), {}, "integers"),
        (np.array([[1, 2]]), np.array([[0.5, np.nan]]), {}, r"nan at \(frame, neighbour\) \(0, 1\)"),
        (np.array([[1, 2]]), np.array([[0.5, -np.inf]]), {}, "-inf"),
        (np.array([[1, 12]]), np.array([[0.5, 0.2]]), {}, "index 12 .* 10 frames"),
        (np.array([[1, -3]]), np.array([[0.5, 0.2]]), {}, "index -3"),
        (np.array([[1, 2]]), np.array([[0.5, -0.2]]), {}, "-0.2 at .* negative"),
        (np.array([[1, 2], [4, 4]]), np.ones((2, 2)), {}, "query frame 1 lists database frame 4 twice"),
        (np.array([[1, 2]]), np.ones((1, 2)), {"steps": ((0, 1),)}, "never advance"),
        (np.array([[1, 2]]), np.ones((1, 2)), {"steps": ((1, 1), (1, 1))}, "repeat"),
        (np.array([[1, 2]]), np.ones((1, 2)), {"steps": ((1, -1),)}, "invalid"),
        (np.array([[1, 2]]), np.ones((1, 2)), {"steps": "ab"}, "integer pairs"),
        (np.array([[1, 2]]), np.ones((1, 2)), {"normalize": "avg"}, "avg"),
        (np.array([[1, 2]]), np.ones((1, 2)), {"top": 0}, "top"),
    ],
)
def test_bad_inputs_raise(indices, distances, kwargs, message):
    with pytest.raises(ValueError, match=message):
        lng_match(indices, distances, TAKES, **kwargs)


def test_single_frame_query():
    best = lng_match(np.array([[4, 2, 7]]), np.array([[0.3, 0.1, 0.2]]), TAKES, top=2)
    assert [(m.start, m.end, m.cost) for m in best] == [(2, 2, 0.1), (7, 7, 0.2)]


# --- online variant -------------------------------------------------------------------------------------------


@pytest.mark.parametrize("steps", [ONLINE_STEPS, THESIS_STEPS, ((1, 1), (0, 1), (2, 1), (1, 2))])
@pytest.mark.parametrize("seed", range(4))
def test_online_equals_offline_on_every_window(steps, seed):
    rng = np.random.default_rng(seed)
    n, frames, k = 60, 24, int(rng.integers(3, 30))
    takes = TakeBounds.from_lengths([20, 25, 15])
    ind = np.argsort(rng.random((frames, n)), axis=1)[:, :k]
    dist = rng.random((frames, k)).round(1)
    dist[rng.random((frames, k)) < 0.15] = np.inf  # radius-style padding
    normalize = ["none", "length", "query"][seed % 3]
    window = int(rng.integers(1, 8))
    online = OnlineLNG(window, takes, steps=steps, normalize=normalize)
    for t in range(frames):
        got = online.push(ind[t], dist[t])
        first = max(0, t - window + 1)
        want = lng_match(ind[first:t + 1], dist[first:t + 1], takes, steps=steps, normalize=normalize)
        assert (got is None) == (want == [])
        if got is not None:
            _same(want[0], got, query_offset=first)
        for span in range(1, min(window, t + 1) + 1):
            ranked = online.matches(top=3, frames=span)
            offline = lng_match(ind[t - span + 1:t + 1], dist[t - span + 1:t + 1], takes, steps=steps,
                                normalize=normalize, top=3)
            assert len(ranked) == len(offline)
            for a, b in zip(offline, ranked):
                _same(a, b, query_offset=t - span + 1)
    assert online.frames_seen == frames


def test_online_steps_skip_a_frame_whose_neighbours_missed_the_path():
    x = _walk(300, 6)
    start, m = 150, 20
    ind, dist = _knn(feature_distances(x[start:start + m], x), 8)
    far = np.arange(8) * 30 + 1  # frame 9's neighbours: none near the true path
    ind[9], dist[9] = far, np.linalg.norm(x[far] - x[start + 9], axis=1)
    online = OnlineLNG(m, np.ones(300, bool))
    for t in range(m):
        best = online.push(ind[t], dist[t])
    assert (best.start, best.end, best.cost) == (start, start + m - 1, dist[9].max())  # pays frame 9's skip
    assert 9 not in best.path[:, 0]
    assert best.frames_per_query()[9] == start + 8
    strict = lng_match(ind, dist, np.ones(300, bool), steps=THESIS_STEPS)
    assert not strict or strict[0].cost > 0


def test_online_reset_and_bad_inputs():
    online = OnlineLNG(3, TAKES)
    with pytest.raises(ValueError, match="no frame pushed"):
        online.matches()
    assert online.push(np.array([1, 2]), np.array([0.1, 0.2])).start == 1
    with pytest.raises(ValueError, match=r"frames must be between 1 and 1, got 2"):
        online.matches(frames=2)
    with pytest.raises(ValueError, match=r"\(k,\), got shapes \(1, 2\)"):
        online.push(np.array([[1, 2]]), np.array([[0.1, 0.2]]))
    with pytest.raises(ValueError, match="index 10"):
        online.push(np.array([10]), np.array([0.1]))
    online.reset()
    assert online.frames_seen == 0
    with pytest.raises(ValueError, match="window"):
        OnlineLNG(0, TAKES)
