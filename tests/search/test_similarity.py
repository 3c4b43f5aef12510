"""Numerical and logical similarity searches (§2.5.1): the numerical search is the ranked LNG search; the logical
search starts with it, queries each new segment once, adds only segments unlike the known ones, records each
round, and stops at a fixed point, its round limit or its segment cap."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.registry import load_dataset
from stylemotion.search import (
    FrameIndex,
    MotionDatabase,
    logical_search,
    numerical_search,
    search_features,
    search_motion,
)
from stylemotion.search.similarity import same_segment

TAKE = "synthetic_walk_normal_000"


@pytest.fixture(scope="module")
def index() -> FrameIndex:
    return FrameIndex(MotionDatabase.from_takeset(load_dataset("synthetic", takes_per_pair=1)), "E15")


def query(index: FrameIndex) -> np.ndarray:
    return index.database.take_positions(TAKE)[30:90]


def test_the_numerical_search_is_the_ranked_lng_search(index):
    found = numerical_search(query(index), index, top=5, k=64)
    again = search_motion(query(index), index, 64, 5).matches
    assert [m.record() for m in found] == [m.record() for m in again]
    assert found[0].take == TAKE and found[0].cost == 0.0


def test_each_round_queries_the_segments_the_last_one_added(index):
    result = logical_search(query(index), index, top=5, k=64, rounds=4)
    rounds = result.rounds
    assert [r["round"] for r in rounds] == list(range(len(rounds))) and len(rounds) <= 4
    first = numerical_search(query(index), index, top=5, k=64)
    assert [f.match.record() for f in result.segments[:len(rounds[0]["added"])]] == [m.record() for m in first]
    assert rounds[0]["queries"] == [None]
    for before, after in zip(rounds, rounds[1:]):
        assert after["queries"] == before["added"]
    added = [i for r in rounds for i in r["added"]]
    assert added == list(range(len(result.segments)))  # every segment added once, in order
    for i, found in enumerate(result.segments):
        assert found.round == next(r["round"] for r in rounds if i in r["added"])
        assert found.found_by is None if found.round == 0 else result.segments[found.found_by].round == found.round - 1
        assert not any(same_segment(found.match, other.match, 0.5) for other in result.segments[:i])
    assert len(result.segments) > len(first)  # the iteration found more than the numerical search
    assert {r["take"] for r in result.records()} > {m.take for m in first}
    assert result.stopped in ("rounds", "fixed point")


def test_a_small_database_reaches_a_fixed_point():
    one = FrameIndex(MotionDatabase.from_takeset(load_dataset("synthetic", takes_per_pair=1, contents=["walk"],
                                                              styles=["normal"])), "E15")
    result = logical_search(one.database.take_positions(0)[30:90], one, top=10, k=64, rounds=20)
    assert result.stopped == "fixed point" and result.rounds[-1]["added"] == []
    assert len(result.rounds) < 20 and len(result.segments) >= 3


def test_the_round_limit_and_the_segment_cap(index):
    once = logical_search(query(index), index, top=5, k=64, rounds=1)
    assert once.stopped == "rounds" and len(once.rounds) == 1
    assert [f.match.record() for f in once.segments] == [m.record() for m in numerical_search(query(index), index,
                                                                                              top=5, k=64)]
    capped = logical_search(query(index), index, top=5, k=64, rounds=5, max_segments=6)
    assert capped.stopped == "max_segments" and len(capped.segments) == 6
    with pytest.raises(ValueError, match="rounds must be a whole number ≥ 1, got 0"):
        logical_search(query(index), index, rounds=0)
    with pytest.raises(ValueError, match=r"same_overlap must be in \(0, 1\], got 0"):
        logical_search(query(index), index, same_overlap=0)


def test_a_found_segment_as_query_finds_itself_at_cost_zero(index):
    result = logical_search(query(index), index, top=5, k=64, rounds=2)
    seg = result.segments[1].match
    best = search_features(index.features[seg.global_start:seg.global_end], index, 64, 1).matches[0]
    assert (best.take, best.start, best.end, best.cost) == (seg.take, seg.start, seg.end, 0.0)
