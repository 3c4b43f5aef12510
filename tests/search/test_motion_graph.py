"""The plain motion graph on a database whose transitions are known: two takes whose features run side by side,
closest at one frame, give exactly that pair of transitions (local minima of the distance valley), the cut frames
and edges the module docstring describes; frames of one take closer than ``min_gap_frames`` are no transition;
a graph without loops has an empty SCC and its walks get stuck."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.base import Take, TakeSet
from stylemotion.search import FrameIndex, MotionDatabase
from stylemotion.search.clip_graph import largest_scc, random_walk
from stylemotion.search.motion_graph import candidate_transitions, local_minima, motion_graph


def line_index(values: list[list[float]]) -> FrameIndex:
    """An E15-shaped index whose take ``t`` has 1-d features ``values[t]`` (first coordinate)."""
    takes = [Take(f"take{t}", np.zeros((len(v), 21, 3), dtype=np.float32), 30.0, {"content": "c", "style": "s"})
             for t, v in enumerate(values)]
    database = MotionDatabase.from_takeset(TakeSet("line", takes, 30.0))
    features = np.zeros((database.num_frames, 15), dtype=np.float32)
    features[:, 0] = np.concatenate(values)
    return FrameIndex(database, "E15", features)


def valley() -> FrameIndex:
    a = [float(t) for t in range(10)]
    b = [t + 0.1 + 0.05 * abs(t - 4) for t in range(10)]  # closest to take 0 at frame 4
    return line_index([a, b])


def test_local_minima_keep_the_bottom_of_the_valley() -> None:
    index = valley()
    i, j, d = candidate_transitions(index, threshold=0.5, k=8, min_gap_frames=2)
    pairs = set(zip(i.tolist(), j.tolist()))
    # candidates: frame t of one take with frame t of the other (0.1 + 0.05 |t − 4| ≤ 0.5 for every t), never a
    # take's last frame as the target
    expected = {(t, 10 + t) for t in range(9)} | {(10 + t, t) for t in range(9)}
    assert pairs == expected
    keep = local_minima(index.database, i, j, d)
    assert set(zip(i[keep].tolist(), j[keep].tolist())) == {(4, 14), (14, 4)}


def test_graph_cuts_and_edges_and_a_loopless_graph_has_an_empty_scc() -> None:
    graph = motion_graph(valley(), threshold=0.5, k=8, min_gap_frames=2)
    assert graph.candidates == 2
    np.testing.assert_array_equal(graph.node_frame, [0, 4, 9, 10, 14, 19])
    edges = set(zip(graph.src.tolist(), graph.dst.tolist(), graph.start.tolist(), graph.end.tolist()))
    assert edges == {(0, 1, 0, 4), (1, 2, 4, 9), (3, 4, 10, 14), (4, 5, 14, 19),  # in the takes
                     (1, 5, 14, 19), (4, 2, 4, 9)}  # the transitions 4 → 14 and 14 → 4
    assert graph.coverage == 1.0
    pruned = largest_scc(graph)
    assert pruned.num_edges == 0 and pruned.coverage == 0.0
    assert random_walk(pruned, 1.0, np.random.default_rng(0)).stuck


def test_a_looping_take_gives_an_scc_and_min_gap_holds() -> None:
    cycle = [float(t % 10) for t in range(30)]  # three identical cycles of ten frames
    index = line_index([cycle])
    i, j, _ = candidate_transitions(index, threshold=0.01, k=4, min_gap_frames=5)
    assert len(i) and (np.abs(i - j) >= 5).all() and ((j - i) % 10 == 0).all()
    graph = largest_scc(motion_graph(index, threshold=0.01, k=4, min_gap_frames=5))
    assert graph.num_edges > 0 and graph.coverage > 0.6
    walk = random_walk(graph, 5.0, np.random.default_rng(0))
    assert not walk.stuck


def test_bad_settings_are_refused() -> None:
    with pytest.raises(ValueError, match="min_gap_frames"):
        candidate_transitions(valley(), 0.5, 4, 0)
    with pytest.raises(ValueError, match="k must"):
        candidate_transitions(valley(), 0.5, 0, 2)
