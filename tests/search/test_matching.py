"""Global motion matching of a query against a FrameIndex: a query cut from a take finds itself first at cost 0,
excluded takes are exactly the k-NN without them, matches map back to takes, labels and frames, the implicit
distance matrix holds just the k-NN distances, and the LNG's best match is subsequence DTW's where every
frame is a neighbour."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.registry import load_dataset
from stylemotion.search import MATCH_KEYS, FrameIndex, MotionDatabase, search_features, search_motion
from stylemotion.search.dtw import subsequence_dtw_features
from stylemotion.search.lng import TakeBounds
from stylemotion.search.matching import nearest_outside


@pytest.fixture(scope="module")
def database() -> MotionDatabase:
    return MotionDatabase.from_takeset(load_dataset("synthetic", takes_per_pair=1))


@pytest.fixture(scope="module")
def index(database) -> FrameIndex:
    return FrameIndex(database, "E15")


@pytest.mark.parametrize("take, start, end", [("synthetic_walk_normal_000", 30, 90),
                                              ("synthetic_run_elderly_000", 0, 45),
                                              ("synthetic_walk-turn-left_youthful_000", 200, 240)])
def test_a_query_cut_from_a_take_finds_that_take_at_its_own_frames_first(index, database, take, start, end):
    query = database.take_positions(take)[start:end]
    result = search_motion(query, index, k=16, top=5)
    best = result.matches[0]
    assert (best.take, best.start, best.end, best.rank) == (take, start, end, 1)
    assert best.cost == 0.0
    i = database.take_index(take)
    assert (best.content, best.style) == (database.contents[i], database.styles[i])
    first = database.global_index(take, start)
    assert (best.global_start, best.global_end) == (first, first + end - start)
    np.testing.assert_array_equal(best.path, np.stack([np.arange(end - start), np.arange(start, end)], axis=1))
    assert list(best.record()) == list(MATCH_KEYS)
    costs = [m.cost for m in result.matches]
    assert costs == sorted(costs) and [m.rank for m in result.matches] == list(range(1, len(costs) + 1))
    for m in result.matches:  # paths stay in their take, monotone, from start to end - 1
        assert m.path[0, 1] == m.start and m.path[-1, 1] == m.end - 1 and np.all(np.diff(m.path, axis=0) >= 0)
        assert 0 <= m.start < m.end <= database.take_slice(m.take).stop - database.take_slice(m.take).start


def test_excluding_a_take_is_the_knn_of_the_database_without_it(index, database):
    take = "synthetic_walk_normal_000"
    features = index.features_of(database.take_positions(take)[10:40])
    d, i = nearest_outside(index, features, 16, np.array([database.take_index(take)]))
    keep = np.flatnonzero(database.take_id != database.take_index(take))
    brute = np.linalg.norm(features[:, None, :].astype(np.float64) - index.features[keep][None], axis=-1)
    order = np.argsort(brute, axis=1, kind="stable")[:, :16]
    np.testing.assert_allclose(d, np.take_along_axis(brute, order, axis=1), rtol=1e-6, atol=1e-6)
    assert not np.isin(database.take_id[i], [database.take_index(take)]).any()
    result = search_motion(database.take_positions(take)[10:40], index, k=64, top=10, exclude_takes=[take])
    assert result.matches and all(m.take != take for m in result.matches)
    assert result.excluded_takes == (take,)
    with pytest.raises(ValueError, match=r"k=6720 exceeds the 6480 frames of the database outside the excluded"):
        search_motion(database.take_positions(take)[10:40], index, k=6720, exclude_takes=[take])


def test_the_implicit_distance_matrix_holds_the_knn_distances_only(index, database):
    query = database.take_positions("synthetic_walk_normal_000")[30:60]
    result = search_motion(query, index, k=8, top=3)
    take = database.take_slice("synthetic_walk_normal_000")
    lo, hi = take.start, take.stop
    block = result.implicit_distances(lo, hi)
    assert block.shape == (30, hi - lo)
    listed = (result.indices >= lo) & (result.indices < hi)
    assert np.count_nonzero(np.isfinite(block)) == np.count_nonzero(listed)
    rows, cols = np.nonzero(listed)
    np.testing.assert_array_equal(block[rows, result.indices[rows, cols] - lo], result.distances[rows, cols])
    exact = np.linalg.norm(index.features_of(query)[:, None, :] - index.features[lo:hi][None], axis=-1)
    seen = np.isfinite(block)
    np.testing.assert_allclose(block[seen], exact[seen], rtol=1e-5, atol=1e-6)
    with pytest.raises(ValueError, match="0 <= lo < hi"):
        result.implicit_distances(5, 5)


def test_with_every_frame_a_neighbour_the_best_match_is_subsequence_dtws(index, database):
    query = database.take_positions("synthetic_walk-turn-right_active_000")[50:80]
    features = index.features_of(query)
    result = search_features(features, index, k=index.size, top=1)
    reference = subsequence_dtw_features(features, index.features,
                                         TakeBounds.from_next_in_take(database.next_in_take)).best
    best = result.matches[0]
    assert (best.global_start, best.global_end - 1) == (reference.start, reference.end)
    assert best.cost == pytest.approx(reference.cost, rel=1e-12)


def test_a_short_query_or_bad_numbers_are_refused_naming_them(database):
    windowed = FrameIndex(database, "E15x3")
    with pytest.raises(ValueError, match=r"E15x3 needs at least 10 frames .* the query has 4"):
        search_motion(database.take_positions(0)[:4], windowed)
    index = FrameIndex(database, "E15")
    for kwargs, message in (({"k": 0}, "k must be a whole number ≥ 1, got 0"),
                            ({"top": 1.5}, "top must be a whole number ≥ 1, got 1.5")):
        with pytest.raises(ValueError, match=message):
            search_motion(database.take_positions(0)[:20], index, **kwargs)
    with pytest.raises(KeyError, match="no take 'nothing'"):
        search_motion(database.take_positions(0)[:20], index, exclude_takes=["nothing"])
