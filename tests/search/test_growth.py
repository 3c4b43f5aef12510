"""An LNG that answers (issue 28, item 2): the gap-tolerant step set and a k that grows until the answer holds,
checked against independent references — a plain double-loop subsequence DTW over any step set
(tests/dtw_reference.py, no code shared with stylemotion.search) and a brute-force k-NN by sorting every distance."""

from __future__ import annotations

import math

import numpy as np
import pytest
from dtw_reference import brute_dtw
from scipy.spatial.distance import cdist

from stylemotion.search.lng import GAP_STEPS, ONLINE_STEPS, STEP_SETS, THESIS_STEPS, TakeBounds, lng_match
from stylemotion.search.matching import GROWTH, grow_k


def _random_case(seed: int) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """A query ``(m, 3)`` cut from a random walk with noise, the walk ``(n, 3)`` and its take lengths."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(20, 45))
    cuts = np.sort(rng.choice(np.arange(1, n), size=int(rng.integers(0, 4)), replace=False))
    lengths = np.diff(np.concatenate([[0], cuts, [n]])).tolist()
    walk = np.cumsum(rng.normal(size=(n, 3)), axis=0)
    m = int(rng.integers(3, 8))
    begin = int(rng.integers(0, n - m + 1))
    return walk[begin:begin + m] + rng.normal(scale=0.5, size=(m, 3)), walk, lengths


def _knn(query: np.ndarray, database: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Brute-force ``(distances, indices)`` ``(m, k)``, ascending."""
    d = cdist(query, database)
    order = np.argsort(d, axis=1, kind="stable")[:, :k]
    return np.take_along_axis(d, order, axis=1), order


@pytest.mark.parametrize("seed", range(8))
@pytest.mark.parametrize("name", ["gaps", "online"])
def test_the_gap_tolerant_lng_equals_brute_force_dtw_under_the_same_steps(seed: int, name: str) -> None:
    query, walk, lengths = _random_case(seed)
    steps, skip = STEP_SETS[name], 0.7
    takes = TakeBounds.from_lengths(lengths)
    n = walk.shape[0]
    for k in (n, 6):  # every frame a neighbour, then only 6: the brute force sees the same nodes
        dist, ind = _knn(query, walk, k)
        cost = np.full((len(query), n), np.inf)
        np.put_along_axis(cost, ind, dist, axis=1)
        want = brute_dtw(cost, lengths, steps, skip)
        got = lng_match(ind, dist, takes, steps=steps, skip_cost=skip)
        if not math.isfinite(want[0]):
            assert got == [], (k, want)
            continue
        assert got, (k, want)
        assert got[0].cost == pytest.approx(want[0], rel=1e-12, abs=1e-12)
        assert (got[0].start, got[0].end) == (want[1], want[2])


def test_the_gap_set_holds_the_thesis_steps_and_the_online_skips() -> None:
    assert set(GAP_STEPS) == set(THESIS_STEPS) | set(ONLINE_STEPS)


def _still_database(rng: np.random.Generator, takes: int, still_frames: int) -> tuple[np.ndarray, list[int]]:
    """``takes`` takes of 40 frames, each a random walk that stands still (one pose plus sway) for
    ``still_frames`` frames in the middle: Bandai's takes begin and end standing."""
    parts = []
    pose = np.array([0.0, 1.0, 0.0])
    for _ in range(takes):
        walk = np.cumsum(rng.normal(size=(40, 3)), axis=0) + 5
        walk[10:10 + still_frames] = pose + rng.normal(scale=0.01, size=(still_frames, 3))
        parts.append(walk)
    return np.concatenate(parts), [40] * takes


def test_a_still_pose_query_answers_by_growing_k_and_stays_on_few_database_frames() -> None:
    rng = np.random.default_rng(3)
    walk, lengths = _still_database(rng, takes=30, still_frames=3)
    takes = TakeBounds.from_lengths(lengths)
    query = np.array([0.0, 1.0, 0.0]) + rng.normal(scale=0.01, size=(25, 3))  # 25 still frames
    assert lng_match(*_knn(query, walk, 4)[::-1], takes) == []  # 90 standing frames in 30 takes: 4 share no take

    def neighbours(k: int) -> tuple[np.ndarray, np.ndarray]:
        return _knn(query, walk, k)

    def match(ind: np.ndarray, dist: np.ndarray) -> list:
        return lng_match(ind, dist, takes)

    for grow in ("path", "stable"):
        found, dist, ind, tried = grow_k(neighbours, match, 4, walk.shape[0], grow)
        assert found and tried[0] == 4 and tried[-1] == ind.shape[1] == dist.shape[1] > 4
        assert all(b == min(2 * a, walk.shape[0]) for a, b in zip(tried, tried[1:]))
        best = found[0]
        assert best.end - best.start + 1 <= 3 < len(query)  # the path repeats database frames (horizontal steps)
        cost = cdist(query, walk)
        want = brute_dtw(cost, lengths, THESIS_STEPS, 0.0)
        assert best.cost >= want[0] - 1e-12  # never below exact DTW
        assert walk[best.start:best.end + 1, 1].min() > 0.9  # on a standing pose


@pytest.mark.parametrize("seed", range(6))
def test_growth_to_every_frame_is_exact_dtw(seed: int) -> None:
    query, walk, lengths = _random_case(seed)
    takes = TakeBounds.from_lengths(lengths)
    n = walk.shape[0]
    want = brute_dtw(cdist(query, walk), lengths, THESIS_STEPS, 0.0)
    calls = []

    def neighbours(k: int) -> tuple[np.ndarray, np.ndarray]:
        calls.append(k)
        return _knn(query, walk, k)

    found, _, ind, tried = grow_k(neighbours, lambda i, d: lng_match(i, d, takes), 1, n, "path")
    assert found and ind.shape[1] == tried[-1]  # a path exists at some k ≤ n: thesis steps always answer at n
    assert found[0].cost >= want[0] - 1e-12
    # the stable rule from k = n / 2 ends at n, where the LNG is exact DTW
    found, _, ind, tried = grow_k(neighbours, lambda i, d: lng_match(i, d, takes), n, n, "stable")
    assert tried == (n,) and found[0].cost == pytest.approx(want[0], rel=1e-12)
    assert (found[0].start, found[0].end) == (want[1], want[2])


def test_growth_rules_and_their_refusals() -> None:
    query, walk, lengths = _random_case(0)
    takes = TakeBounds.from_lengths(lengths)
    calls = []

    def neighbours(k: int) -> tuple[np.ndarray, np.ndarray]:
        calls.append(k)
        return _knn(query, walk, k)

    def match(i: np.ndarray, d: np.ndarray) -> list:
        return lng_match(i, d, takes)

    found, dist, _, tried = grow_k(neighbours, match, 5, 40, "none")
    assert tried == (5,) and calls == [5] and dist.shape[1] == 5
    assert GROWTH == ("none", "path", "stable")
    calls.clear()
    found, _, ind, tried = grow_k(neighbours, match, 2, 9, "stable")
    # stable: one k-NN query per k tried past the first (the first is sliced from the second's), capped at 9
    assert calls[0] == 4 and set(tried) <= {2, 4, 8, 9} and ind.shape[1] == tried[-1]
    if tried[-1] < 9:  # stopped early: the answer at the last k is the one at the k before
        prev = match(*neighbours(tried[-2])[::-1])
        assert (prev[0].start, prev[0].end) == (found[0].start, found[0].end)
    with pytest.raises(ValueError, match="grow must be one of"):
        grow_k(neighbours, match, 2, 9, "forever")
    with pytest.raises(ValueError, match="k_max=3 is below k=4"):
        grow_k(neighbours, match, 4, 3, "path")


def _longer_case(seed: int) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """A query ``(m, 3)`` of 6–10 frames cut from a noisy random walk of 70–110 frames in 1–5 takes: long enough
    that k doubles several times before it holds every frame."""
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(70, 111))
    cuts = np.sort(rng.choice(np.arange(12, n - 12), size=int(rng.integers(0, 5)), replace=False))
    lengths = np.diff(np.concatenate([[0], cuts, [n]])).tolist()
    walk = np.cumsum(rng.normal(size=(n, 3)), axis=0)
    m = int(rng.integers(6, 11))
    take = int(np.argmax(lengths))
    first = int(np.sum(lengths[:take]))
    begin = first + int(rng.integers(0, lengths[take] - m + 1))
    return walk[begin:begin + m] + rng.normal(scale=1.0, size=(m, 3)), walk, lengths


@pytest.mark.parametrize("seed", range(12))
def test_a_stricter_stable_stop_never_answers_worse_than_the_older_one_and_stops_by_k_max(seed: int) -> None:
    query, walk, lengths = _longer_case(seed)
    takes = TakeBounds.from_lengths(lengths)
    n = walk.shape[0]
    want = brute_dtw(cdist(query, walk), lengths, THESIS_STEPS, 0.0)  # exact subsequence DTW, independent code

    def neighbours(k: int) -> tuple[np.ndarray, np.ndarray]:
        return _knn(query, walk, k)

    def match(ind: np.ndarray, dist: np.ndarray) -> list:
        return lng_match(ind, dist, takes)

    def run(k_max: int, stable_for: int) -> tuple[list, tuple[int, ...]]:
        found, dist, ind, tried = grow_k(neighbours, match, 1, k_max, "stable", stable_for)
        assert tried[0] == 1 and tried[-1] == ind.shape[1] == dist.shape[1] <= k_max  # bounded by k_max
        assert all(b == min(2 * a, k_max) for a, b in zip(tried, tried[1:]))  # doubling, capped
        if tried[-1] < k_max:  # stopped early: the best segment held over the last stable_for doublings
            assert len(tried) > stable_for
            for j in tried[-1 - stable_for:-1]:
                earlier = match(*neighbours(j)[::-1])
                assert earlier and (earlier[0].start, earlier[0].end) == (found[0].start, found[0].end)
        return found, tried

    rules = [(k_max, stable_for) for k_max in (16, 64, n) for stable_for in (1, 2, 3)]
    answers = {rule: run(*rule) for rule in rules}
    for older in rules:  # e.g. (16, 1): k and 2k agree, to a small bound
        before, before_tried = answers[older]
        for stricter in rules:
            if stricter == older or stricter[0] < older[0] or stricter[1] < older[1]:
                continue  # only rules at least as strict in both the bound and the stop
            after, tried = answers[stricter]
            assert tried[:len(before_tried)] == before_tried  # it searches on from where the older rule stopped
            if before:
                assert after and after[0].cost <= before[0].cost + 1e-12, (older, stricter)  # never worse
                if (before[0].start, before[0].end) == (want[1], want[2]):  # DTW's segment is kept
                    assert (after[0].start, after[0].end) == (want[1], want[2])
    for found, _ in answers.values():
        assert not found or found[0].cost >= want[0] - 1e-12  # the LNG never beats exact DTW
    exact, tried = run(n, 2 * n)  # a stop that never holds runs to every frame: exact DTW
    assert tried[-1] == n and exact[0].cost == pytest.approx(want[0], rel=1e-12)
    assert (exact[0].start, exact[0].end) == (want[1], want[2])


def test_stable_for_is_refused_below_one() -> None:
    query, walk, lengths = _random_case(1)
    takes = TakeBounds.from_lengths(lengths)
    for bad in (0, -1, 1.5, True):
        with pytest.raises(ValueError, match="stable_for must be a whole number ≥ 1"):
            grow_k(lambda k: _knn(query, walk, k), lambda i, d: lng_match(i, d, takes), 1, 8, "stable", bad)


def test_where_k_and_2k_agree_on_a_wrong_segment_the_stricter_stop_finds_dtws() -> None:
    """A planted case (found by scanning seeds of :func:`_longer_case`): the older stop settles at k = 16 on a
    segment that is not exact DTW's; requiring two doublings in a row reaches DTW's best segment."""
    query, walk, lengths = _longer_case(10)
    takes = TakeBounds.from_lengths(lengths)
    n = walk.shape[0]
    want = brute_dtw(cdist(query, walk), lengths, THESIS_STEPS, 0.0)

    def grown(stable_for: int) -> tuple[list, tuple[int, ...]]:
        found, _, _, tried = grow_k(lambda k: _knn(query, walk, k), lambda i, d: lng_match(i, d, takes), 1, n,
                                    "stable", stable_for)
        return found, tried

    older, tried = grown(1)
    assert tried[-1] < n and (older[0].start, older[0].end) != (want[1], want[2]) and older[0].cost > want[0]
    stricter, _ = grown(2)
    assert (stricter[0].start, stricter[0].end) == (want[1], want[2])
    assert stricter[0].cost == pytest.approx(want[0], rel=1e-12)
