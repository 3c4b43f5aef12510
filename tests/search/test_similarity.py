"""Numerical and logical similarity searches (§2.5.1) against references built into the data: a database with
planted segments whose distances to the query are known, so which segment each round must find follows from
the construction, not from the code under test."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.base import Take, TakeSet
from stylemotion.search import FrameIndex, MotionDatabase, logical_search, numerical_search
from stylemotion.search.similarity import same_segment

M, TAKE_FRAMES, STARTS = 20, 60, {"A": 10, "B": 25, "C": 5, "D": 30}
U, V = np.eye(15)[0], np.eye(15)[1]  # two orthogonal unit directions of the 15-d feature space


def _planted() -> tuple[FrameIndex, np.ndarray]:
    """Four takes A–D of far-apart random-walk features; 20-frame segments planted in A, B and C.

    Per frame, A = Q + 0.2u, C = Q + 0.25v, B = A + 0.2u (u ⟂ v), so from the query Q: A (0.2) < C (0.25) < B (0.4);
    from A: B (0.2) < C (0.32); from C: A (0.32) < B (0.47); from B: A (0.2). D holds no segment."""
    rng = np.random.default_rng(0)
    query = np.cumsum(rng.normal(scale=0.3, size=(M, 15)), axis=0)
    segments = {"A": query + 0.2 * U, "C": query + 0.25 * V, "B": query + 0.4 * U}
    features, takes = [], []
    for t, name in enumerate(STARTS):
        block = 100.0 * (t + 1) + np.cumsum(rng.normal(size=(TAKE_FRAMES, 15)), axis=0)
        if name in segments:
            block[STARTS[name]:STARTS[name] + M] = segments[name]
        features.append(block)
        takes.append(Take(name, np.zeros((TAKE_FRAMES, 21, 3), np.float32), 30.0, {"content": "c", "style": "s"}))
    database = MotionDatabase.from_takeset(TakeSet("planted", takes, 30.0))
    index = FrameIndex(database, "E15", np.concatenate(features).astype(np.float32))
    # The searches compute a query's features from its positions: here the "positions" are the features.
    index.features_of = lambda positions: np.asarray(positions, np.float32).reshape(len(positions), 15)
    return index, query.reshape(M, 5, 3)


@pytest.fixture(scope="module")
def planted() -> tuple[FrameIndex, np.ndarray]:
    return _planted()


def _segments(matches) -> list[tuple[str, int, int]]:
    return [(m.take, m.start, m.end) for m in matches]


def seg(name: str) -> tuple[str, int, int]:
    return name, STARTS[name], STARTS[name] + M


def test_numerical_search_ranks_the_planted_segments_by_their_distance(planted):
    index, query = planted
    found = numerical_search(query, index, top=3, k=8)
    assert _segments(found) == [seg("A"), seg("C"), seg("B")]
    expected = [0.2 * M, 0.25 * M, 0.4 * M]  # the per-frame distance times the frames, by construction
    assert [m.cost for m in found] == pytest.approx(expected, rel=1e-5)
    assert _segments(numerical_search(query, index, top=1, k=8)) == [seg("A")]


def test_logical_search_finds_what_the_query_alone_ranks_lower(planted):
    """top = 2: round 0 finds A and C; round 1 from A finds A itself and B (nearer A than C), from C finds C and
    A; round 2 from B finds B and A, nothing new: a fixed point after three rounds, B found by A."""
    index, query = planted
    assert _segments(numerical_search(query, index, top=2, k=8)) == [seg("A"), seg("C")]
    result = logical_search(query, index, top=2, k=8, rounds=5)
    assert [(_segments([f.match])[0], f.round) for f in result.segments] == [(seg("A"), 0), (seg("C"), 0),
                                                                            (seg("B"), 1)]
    assert result.segments[2].found_by == 0  # A's query found B
    assert [r["added"] for r in result.rounds] == [[0, 1], [2], []]
    assert [r["queries"] for r in result.rounds] == [[None], [0, 1], [2]]
    assert result.stopped == "fixed point"
    records = result.records()
    assert [(r["take"], r["round"], r["found_by"]) for r in records] == [("A", 0, None), ("C", 0, None), ("B", 1, 0)]


def test_round_limit_and_segment_cap(planted):
    index, query = planted
    once = logical_search(query, index, top=2, k=8, rounds=1)
    assert once.stopped == "rounds" and _segments([f.match for f in once.segments]) == [seg("A"), seg("C")]
    capped = logical_search(query, index, top=2, k=8, rounds=5, max_segments=1)
    assert capped.stopped == "max_segments" and _segments([f.match for f in capped.segments]) == [seg("A")]
    with pytest.raises(ValueError, match="rounds must be a whole number ≥ 1, got 0"):
        logical_search(query, index, rounds=0)
    with pytest.raises(ValueError, match="max_segments must be a whole number ≥ 1, got 0"):
        logical_search(query, index, max_segments=0)
    with pytest.raises(ValueError, match=r"same_overlap must be in \(0, 1\], got 0"):
        logical_search(query, index, same_overlap=0)


def test_same_segment_by_overlap(planted):
    index, query = planted
    a = numerical_search(query, index, top=1, k=8)[0]
    shifted = type(a)(**{**a.__dict__, "start": a.start + 8, "end": a.end + 8})  # 12 of 20 frames shared
    assert same_segment(a, shifted, 0.5) and not same_segment(a, shifted, 0.7)
    other_take = type(a)(**{**a.__dict__, "take": "B"})
    assert not same_segment(a, other_take, 0.1)
