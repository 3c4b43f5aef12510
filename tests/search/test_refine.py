"""Re-ranking LNG candidates by exact DTW in windows (stylemotion.search.refine) against subsequence DTW over the
whole database, and its use in search_features."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.registry import load_dataset
from stylemotion.search import FrameIndex
from stylemotion.search.dtw import subsequence_dtw_features
from stylemotion.search.lng import Match, TakeBounds
from stylemotion.search.matching import search_features
from stylemotion.search.refine import candidate_windows, refine_matches

SKIP = 1e3  # one skip penalty for both sides (the default is a row's largest distance, which depends on the frames)


def _walks(rng: np.random.Generator, lengths: list[int], d: int = 6) -> np.ndarray:
    return np.concatenate([np.cumsum(rng.normal(0, 0.3, (n, d)), axis=0) for n in lengths])


def test_windows_are_clipped_to_takes_and_merged():
    takes = TakeBounds.from_lengths([100, 50, 80])  # frames 0–99, 100–149, 150–229

    def match(a: int, b: int) -> Match:
        return Match(a, b, 1.0, np.zeros((1, 2), dtype=np.int64), 0)

    got = candidate_windows([match(10, 20), match(25, 40), match(105, 110), match(200, 229), match(90, 99)],
                            takes, 10)
    # 10–20 and 25–40 widen to 0–30 and 15–50 (merged); 90–99 to 80–99 (its own window: 50 < 80 - 1);
    # 105–110 to 100–120 (not merged with frame 99's window: another take); 200–229 to 190–229
    assert got == [(0, 50), (80, 99), (100, 120), (190, 229)]
    assert candidate_windows([match(10, 20)], takes, 0) == [(10, 20)]
    with pytest.raises(ValueError, match="widen"):
        candidate_windows([match(10, 20)], takes, -1)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_refine_finds_the_exact_best_when_a_candidate_lies_near_it(seed):
    rng = np.random.default_rng(seed)
    lengths = [int(n) for n in rng.integers(60, 200, size=12)]
    database = _walks(rng, lengths)
    takes = TakeBounds.from_lengths(lengths)
    take = int(rng.integers(len(lengths)))
    first = sum(lengths[:take])
    query = database[first + 10:first + 40] + rng.normal(0, 0.05, (30, 6))
    full = subsequence_dtw_features(query, database, takes, skip_cost=SKIP, top=3).matches
    best = full[0]
    near = Match(best.start + 5, best.end - 3, np.inf, best.path, best.take)  # a candidate off by a few frames
    far = [m for m in full[1:]]
    got = refine_matches(query, database, takes, [*far, near], top=3, skip_cost=SKIP)
    assert (got[0].start, got[0].end, got[0].take) == (best.start, best.end, best.take)
    assert got[0].cost == pytest.approx(best.cost, rel=1e-12)
    assert [m.cost for m in got] == sorted(m.cost for m in got)
    np.testing.assert_array_equal(got[0].path, best.path)


def test_refine_never_beats_the_whole_database_and_stays_in_its_windows():
    rng = np.random.default_rng(5)
    lengths = [150] * 8
    database = _walks(rng, lengths)
    takes = TakeBounds.from_lengths(lengths)
    query = database[620:660] + rng.normal(0, 0.05, (40, 6))  # take 4
    best = subsequence_dtw_features(query, database, takes, skip_cost=SKIP).best
    wrong = Match(100, 140, np.inf, np.zeros((1, 2), dtype=np.int64), 0)  # take 0 only
    got = refine_matches(query, database, takes, [wrong], skip_cost=SKIP)
    assert got and got[0].take == 0 and 60 <= got[0].start and got[0].end <= 149
    assert got[0].cost >= best.cost
    assert refine_matches(query, database, takes, [], skip_cost=SKIP) == []


@pytest.fixture(scope="module")
def held_out_query() -> tuple[FrameIndex, np.ndarray]:
    """An E15 index over the synthetic takes but one, and the features of 60 frames of that one."""
    takeset = load_dataset("synthetic", takes_per_pair=1)
    held_out = takeset.takes[3]
    index = FrameIndex.build(takeset.__class__(takeset.name, [t for t in takeset.takes if t is not held_out],
                                               takeset.fps), "E15", use_cache=False)
    return index, index.features_of(held_out.positions[5:65].astype(np.float64))


def test_search_with_refine_reports_exact_dtw_costs(held_out_query):
    index, features = held_out_query
    plain = search_features(features, index, k=8, top=3, k_max=64, grow="path")
    refined = search_features(features, index, k=8, top=3, k_max=64, grow="path", refine=8)
    assert refined.matches and "refine" in refined.timings
    full = subsequence_dtw_features(features, index.features, index.database.take_bounds, top=1).best
    assert refined.matches[0].cost <= plain.matches[0].cost + 1e-9
    assert refined.matches[0].cost >= full.cost - 1e-9  # never below the exact optimum over every frame
    for m in refined.matches:  # each reported cost is exact DTW of the query on that segment alone
        seg = index.features[m.global_start:m.global_end]
        alone = subsequence_dtw_features(features, seg, TakeBounds.from_lengths([len(seg)]), top=1).best
        assert alone.cost <= m.cost + 1e-9
    # refine < top: windows around every one of the LNG's top candidates, so the list never shrinks
    few = search_features(features, index, k=8, top=3, k_max=64, grow="path", refine=1)
    assert len(plain.matches) <= len(few.matches) <= 3
    assert {(m.global_start, m.global_end) for m in few.matches} == {(m.global_start, m.global_end)
                                                                      for m in refined.matches}
    with pytest.raises(ValueError, match="refine"):
        search_features(features, index, k=8, refine=-1)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_verify_puts_the_exact_best_first_whatever_the_candidates(seed):
    """verify_best against the plain-Python DTW (tests/dtw_reference.py) over every take: a wrong or missing
    candidate list still yields the exact best; matches overlapping it are dropped; excluded takes are never
    answered; the number of takes swept is bounded by the takes."""
    from dtw_reference import brute_dtw

    from stylemotion.search.dtw import feature_distances
    from stylemotion.search.refine import verify_best

    rng = np.random.default_rng(40 + seed)
    lengths = [int(n) for n in rng.integers(20, 60, size=8)]
    database = _walks(rng, lengths, d=3)
    takes = TakeBounds.from_lengths(lengths)
    take = int(rng.integers(len(lengths)))
    first = sum(lengths[:take])
    query = database[first + 3:first + 12] + rng.normal(0, 0.05, (9, 3))
    cost = feature_distances(query, database)
    ref_cost, ref_start, ref_end = brute_dtw(cost, lengths)[:3]
    other = sum(lengths[:(take + 1) % len(lengths)])  # a candidate in another take
    wrong = Match(other, other + 8, 1e9, np.zeros((1, 2), dtype=np.int64), (take + 1) % len(lengths))
    for candidates in ([], [wrong]):
        got, swept = verify_best(query, database, takes, candidates)
        assert (got[0].start, got[0].end) == (ref_start, ref_end) and got[0].cost == pytest.approx(ref_cost, rel=1e-12)
        assert 1 <= swept <= len(lengths) and 1 <= len(got) <= len(candidates) + 1
        assert all(m.take != got[0].take or m.end < got[0].start or m.start > got[0].end for m in got[1:])
    exact, _ = verify_best(query, database, takes, [])
    kept, swept = verify_best(query, database, takes, exact)  # already the best: unchanged, few takes swept
    assert kept == exact and swept <= len(lengths)
    others, _ = verify_best(query, database, takes, [], excluded_takes=[exact[0].take])
    assert others[0].take != exact[0].take and others[0].cost >= exact[0].cost - 1e-12


def test_take_bounds_in_chunks_equal_the_whole_matrix(monkeypatch):
    import stylemotion.search.dtw as dtw

    rng = np.random.default_rng(9)
    lengths = [int(n) for n in rng.integers(1, 40, size=15)]
    database = _walks(rng, lengths, d=4)
    takes = TakeBounds.from_lengths(lengths)
    query = rng.normal(size=(7, 4))
    whole = np.minimum.reduceat(dtw.feature_distances(query, database), takes.spans()[0], axis=1).sum(axis=0)
    for cells in (7, 7 * 13, 7 * 1000):  # one frame, chunks cutting takes, one chunk
        monkeypatch.setattr(dtw, "BOUND_CHUNK_CELLS", cells)
        np.testing.assert_array_equal(dtw.take_lower_bounds(query, database, takes), whole)


def test_search_with_verify_answers_exact_dtw_over_every_take(held_out_query):
    index, features = held_out_query
    full = subsequence_dtw_features(features, index.features, index.database.take_bounds, top=1).best
    for k in (1, 8):  # k = 1: the LNG finds no path or a poor one; verify still answers DTW's best
        got = search_features(features, index, k=k, top=3, verify=True)
        assert (got.matches[0].global_start, got.matches[0].global_end - 1) == (full.start, full.end)
        assert got.matches[0].cost == pytest.approx(full.cost, rel=1e-12)
        assert "verify" in got.timings and 1 <= got.takes_verified <= index.database.num_takes
    name = index.database.take_names[full.take]
    without = search_features(features, index, k=8, top=1, verify=True, exclude_takes=[name])
    assert without.matches[0].take != name and without.matches[0].cost >= full.cost - 1e-9
    assert search_features(features, index, k=8, top=1).takes_verified is None
    with pytest.raises(ValueError, match="verify needs the thesis' steps"):
        search_features(features, index, k=8, verify=True, normalize="length")


@pytest.mark.parametrize("k", [1, 5, 40])
def test_the_neighbour_floor_never_exceeds_the_take_bounds_and_prunes_the_same_best(k):
    """neighbour_floor from brute-force k nearest frames: ≤ the exact take bounds everywhere, equal where every query
    frame has a neighbour in the take; verify with it answers what verify without it does; ``only`` bounds just the
    takes it names."""
    from stylemotion.search.dtw import feature_distances, take_lower_bounds
    from stylemotion.search.refine import neighbour_floor, verify_best

    rng = np.random.default_rng(k)
    lengths = [int(n) for n in rng.integers(15, 50, size=10)]
    database = _walks(rng, lengths, d=3)
    takes = TakeBounds.from_lengths(lengths)
    query = database[40:52] + rng.normal(0, 0.05, (12, 3))
    cost = feature_distances(query, database)
    nearest = np.argsort(cost, axis=1, kind="stable")[:, :k]
    dist = np.take_along_axis(cost, nearest, axis=1)
    floor = neighbour_floor(nearest, dist, takes)
    exact = take_lower_bounds(query, database, takes)
    assert np.all(floor <= exact + 1e-12)
    starts, ends = takes.spans()
    covered = [all(np.any((row >= a) & (row <= b)) for row in nearest) for a, b in zip(starts, ends)]
    np.testing.assert_allclose(floor[covered], exact[covered], rtol=1e-12)
    assert any(covered) and not all(covered)
    plain, _ = verify_best(query, database, takes, [])
    start = sum(lengths[:3])  # a poor candidate in take 3: a loose bound, so the floor must do the pruning
    poor = Match(start, start + 11, float(cost[np.arange(12), np.arange(start, start + 12)].sum()),
                 np.zeros((1, 2), dtype=np.int64), 3)
    floored, swept = verify_best(query, database, takes, [poor], neighbours=(nearest, dist))
    unfloored, swept_all = verify_best(query, database, takes, [poor])
    assert (floored[0].start, floored[0].end) == (unfloored[0].start, unfloored[0].end) == (plain[0].start,
                                                                                            plain[0].end)
    assert swept <= swept_all
    only = take_lower_bounds(query, database, takes, only=np.array([4, 1]))
    np.testing.assert_array_equal(only[[1, 4]], exact[[1, 4]])
    assert np.isinf(np.delete(only, [1, 4])).all()
