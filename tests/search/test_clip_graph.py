"""Clip graphs against ground truth: the largest SCC equals a brute-force mutual-reachability reference on random
graphs; walks follow edges and never get stuck inside an SCC; a walk that stays in its take reproduces the
database's frames; a transition between a take and a copy of it raised by 10 cm has a 10 cm pose gap; the
shortest goal walk is the known one; a walk exports as BVH and JSON."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from stylemotion.datasets.base import Take, TakeSet
from stylemotion.datasets.registry import load_dataset
from stylemotion.io.bvh import read_bvh
from stylemotion.search import MotionDatabase
from stylemotion.search.clip_graph import (
    DatabaseFrames,
    Walk,
    edges_graph,
    goal_walk,
    largest_scc,
    random_walk,
    synthesize,
    walk_figures,
    walk_frames,
    write_walk,
)


def zeros_database(lengths: list[int]) -> MotionDatabase:
    takes = [Take(f"take{i}", np.zeros((n, 21, 3), dtype=np.float32), 30.0, {"content": "c", "style": "s"})
             for i, n in enumerate(lengths)]
    return MotionDatabase.from_takeset(TakeSet("zeros", takes, 30.0))


def graph_of(edges: list[tuple[int, int]], nodes: int, database: MotionDatabase):
    """A graph whose edge e plays frames 2e … 2e + 1 of one long take."""
    src, dst = np.array([e[0] for e in edges]), np.array([e[1] for e in edges])
    start = 2 * np.arange(len(edges))
    frames = DatabaseFrames.of(database)
    return edges_graph("test", frames, np.arange(nodes), src, dst, start, start + 1, {})


def reference_components(nodes: int, src: np.ndarray, dst: np.ndarray) -> list[set[int]]:
    reach = np.eye(nodes, dtype=bool)
    reach[src, dst] = True
    for k in range(nodes):  # Warshall's transitive closure
        reach |= reach[:, k:k + 1] & reach[k:k + 1, :]
    mutual = reach & reach.T
    return [set(np.flatnonzero(mutual[v]).tolist()) for v in range(nodes)]


@pytest.mark.parametrize("seed", range(6))
def test_largest_scc_matches_mutual_reachability(seed: int) -> None:
    rng = np.random.default_rng(seed)
    nodes, count = 12, 16
    edges = [(int(a), int(b)) for a, b in rng.integers(0, nodes, (count, 2))]
    graph = graph_of(edges, nodes, zeros_database([2 * count]))
    pruned = largest_scc(graph)
    components = reference_components(nodes, graph.src, graph.dst)

    def inner_edges(c: set[int]) -> int:
        return sum(a in c and b in c for a, b in edges)

    best = max(len(c) for c in components)
    candidates = [c for c in components if len(c) == best]
    most = max(inner_edges(c) for c in candidates)
    kept = set(pruned.node_frame.tolist())  # node_frame holds the old node ids here
    assert kept in [c for c in candidates if inner_edges(c) == most]
    assert pruned.num_edges == most
    old = pruned.node_frame
    assert {(int(old[a]), int(old[b])) for a, b in zip(pruned.src, pruned.dst)} <= set(edges)


def test_walks_follow_edges_and_never_get_stuck_in_an_scc() -> None:
    edges = [(0, 1), (1, 2), (2, 0), (1, 3), (3, 1), (2, 4)]  # node 4: a dead end outside the SCC
    graph = graph_of(edges, 5, zeros_database([2 * len(edges)]))
    pruned = largest_scc(graph)
    assert pruned.num_nodes == 4 and pruned.num_edges == 5
    rng = np.random.default_rng(0)
    for _ in range(20):
        walk = random_walk(pruned, 2.0, rng, min_play_s=0.0)
        assert not walk.stuck
        e = np.asarray(walk.edges)
        assert (pruned.dst[e[:-1]] == pruned.src[e[1:]]).all()
        assert walk_frames(pruned, walk.edges) >= 61
    stuck = random_walk(graph, 10.0, np.random.default_rng(1), start=4)
    assert stuck.stuck and stuck.edges == ()
    assert random_walk(largest_scc(graph_of([(0, 1)], 2, zeros_database([2]))), 1.0, rng).stuck


@pytest.fixture(scope="module")
def walk_database() -> MotionDatabase:
    """A synthetic walk take and the same take raised by 10 cm."""
    take = next(t for t in load_dataset("synthetic", takes_per_pair=1).takes if "walk" in t.name)
    raised = np.asarray(take.positions) + np.array([0.0, 0.1, 0.0], dtype=np.float32)
    takes = [Take("walk", np.asarray(take.positions), 30.0, {"content": "walk", "style": "s"}),
             Take("raised", raised, 30.0, {"content": "walk", "style": "s"})]
    return MotionDatabase.from_takeset(TakeSet("walks", takes, 30.0))


def test_a_walk_inside_its_take_reproduces_the_take(walk_database: MotionDatabase) -> None:
    frames = DatabaseFrames.of(walk_database)
    graph = edges_graph("test", frames, np.array([0, 40, 80]), np.array([0, 1]), np.array([1, 2]),
                        np.array([40, 80]), np.array([80, 120]), {})
    motion = synthesize(graph, Walk((0, 1)))
    np.testing.assert_allclose(motion.positions, walk_database.positions[40:121], atol=2e-3)
    assert not motion.transition.any() and list(motion.junctions) == [40]
    np.testing.assert_array_equal(motion.played, np.arange(40, 121))
    assert walk_figures(graph, motion)["transitions"] == 0


def test_a_transition_to_the_raised_copy_has_a_10_cm_pose_gap(walk_database: MotionDatabase,
                                                               tmp_path: Path) -> None:
    n = walk_database.take_slice("walk").stop
    frames = DatabaseFrames.of(walk_database)
    graph = edges_graph("test", frames, np.array([0, 60]), np.array([0, 1]), np.array([1, 0]),
                        np.array([20, n + 60]), np.array([60, n + 100]), {})
    motion = synthesize(graph, Walk((0, 1)), blend_frames=8)
    assert motion.transition.tolist() == [True]
    assert motion.before.tolist() == [60] and motion.after.tolist() == [n + 60]
    figures = walk_figures(graph, motion)
    assert figures["transitions"] == 1
    assert figures["pose_gap_cm"] == pytest.approx(10.0, abs=1e-3)
    assert figures["velocity_gap_mps"] == pytest.approx(0.0, abs=1e-4)
    # the jump fades: the junction frame is the old clip's pose, the raised pose is reached 8 frames later
    hips_y = motion.positions[:, 0, 1]
    assert hips_y[40] == pytest.approx(walk_database.positions[60, 0, 1], abs=1e-4)
    assert hips_y[48] == pytest.approx(walk_database.positions[n + 68, 0, 1], abs=1e-4)
    bvh, meta = write_walk(graph, Walk((0, 1)), motion, tmp_path / "out")
    assert read_bvh(bvh).num_frames == len(motion.positions)
    record = json.loads(meta.read_text())
    assert [c["take"] for c in record["clips"]] == ["walk", "raised"]
    assert record["clips"][1] == {"edge": 1, "from_node": 1, "to_node": 0, "take": "raised", "first": 60,
                                  "last": 100}


def test_goal_walk_is_the_shortest_and_a_goal_off_the_graph_fails() -> None:
    database = zeros_database([40])
    frames = DatabaseFrames.of(database)
    # 0 → 1 (frames 0-5), 1 → 2 (5-8), 2 → 0 (8-11), 0 → 2 long (12-30), 2 → 1 (30-33)
    graph = edges_graph("test", frames, np.arange(3), np.array([0, 1, 2, 0, 2]), np.array([1, 2, 0, 2, 1]),
                        np.array([0, 5, 8, 12, 30]), np.array([5, 8, 11, 30, 33]), {})
    assert goal_walk(graph, 0, 31).edges == (0, 1, 4)  # via 1 and 2 (8 frames), not the long edge (18)
    assert goal_walk(graph, 0, 20).edges == (3,)
    assert goal_walk(graph, 1, 2).edges == (1, 2, 0)
    assert goal_walk(graph, 0, 35) is None
