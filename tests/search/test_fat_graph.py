"""Fast fat-graph base poses on databases whose clusters are known: tight, well separated blobs of feature
vectors give one base pose per blob in order of size; the greedy choice equals a plain O(n²) reference on
random data; the export round-trips."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from stylemotion.datasets.base import Take, TakeSet
from stylemotion.search import FrameIndex, MotionDatabase, base_poses, greedy_bases, write_clusters


def database_of(lengths: list[int]) -> MotionDatabase:
    takes = [Take(f"take{i}", np.zeros((n, 21, 3), dtype=np.float32), 30.0,
                  {"content": f"c{i % 2}", "style": "normal"}) for i, n in enumerate(lengths)]
    return MotionDatabase.from_takeset(TakeSet("blobs", takes, 30.0))


def blob_index(sizes: list[int], seed: int = 0) -> tuple[FrameIndex, np.ndarray]:
    """An E15-shaped index whose features are ``len(sizes)`` blobs (radius ≤ 0.05, centres 10 apart), shuffled
    over two takes; returns it and each frame's blob."""
    rng = np.random.default_rng(seed)
    label = rng.permutation(np.repeat(np.arange(len(sizes)), sizes))
    centres = 10.0 * np.eye(15)[: len(sizes)]
    offsets = rng.normal(size=(len(label), 15))
    offsets *= 0.05 * rng.uniform(0, 1, (len(label), 1)) / np.linalg.norm(offsets, axis=1, keepdims=True)
    n = len(label)
    database = database_of([n // 2, n - n // 2])
    return FrameIndex(database, "E15", (centres[label] + offsets).astype(np.float32)), label


def test_separated_blobs_give_one_base_pose_each_largest_first(tmp_path: Path) -> None:
    index, label = blob_index([50, 30, 12])
    clusters = base_poses(index, radius=0.2, k=64)
    assert clusters.num_clusters == 3
    np.testing.assert_array_equal(label[clusters.bases], [0, 1, 2])
    np.testing.assert_array_equal(clusters.sizes, [50, 30, 12])
    np.testing.assert_array_equal(clusters.assignment, label)  # cluster c is blob c
    np.testing.assert_array_equal(clusters.counts, np.array([50, 30, 12])[label])
    json_path, npz_path = write_clusters(clusters, index, tmp_path / "export")
    meta = json.loads(json_path.read_text())
    assert meta["clusters"] == 3 and meta["radius"] == 0.2 and meta["k"] == 64 and meta["features"] == "E15"
    first = meta["base_poses"][0]
    where = index.locate(int(clusters.bases[0]))
    assert first == {"cluster": 0, "base": int(clusters.bases[0]), "take": where.take, "frame": where.frame,
                     "content": where.content, "style": "normal", "members": 50, "neighbours": 50}
    with np.load(npz_path, allow_pickle=False) as npz:
        np.testing.assert_array_equal(npz["assignment"], clusters.assignment)
        np.testing.assert_array_equal(npz["bases"], clusters.bases)
        np.testing.assert_array_equal(npz["take_id"], index.database.take_id)


def test_k_caps_the_counts_and_a_capped_blob_splits(tmp_path: Path) -> None:
    index, label = blob_index([50, 30, 12], seed=1)
    clusters = base_poses(index, radius=0.2, k=20)
    assert clusters.counts.max() == 20 and clusters.counts[label == 2].max() == 12
    assert clusters.sizes.sum() == len(label) and (clusters.assignment >= 0).all()  # every frame in one cluster
    for c, base in enumerate(clusters.bases):  # a cluster never mixes blobs, and its base is its member
        assert clusters.assignment[base] == c
        assert len(set(label[clusters.assignment == c])) == 1
    assert clusters.num_clusters > 3  # blobs of more than k frames need several base poses


def reference_greedy(features: np.ndarray, radius: float, k: int) -> tuple[np.ndarray, np.ndarray]:
    """O(n²): all distances, the k nearest within radius per frame, the greedy sweep one frame at a time."""
    d = np.linalg.norm(features[:, None].astype(np.float64) - features[None].astype(np.float64), axis=-1)
    order = np.argsort(d, axis=1, kind="stable")[:, :k]
    within = np.take_along_axis(d, order, axis=1) <= radius
    counts = within.sum(axis=1)
    assignment = np.full(len(features), -1)
    bases = []
    remaining = set(range(len(features)))
    while remaining:
        g = max(remaining, key=lambda f: (counts[f], -f))
        bases.append(g)
        assignment[g] = len(bases) - 1
        remaining.discard(g)
        for h in order[g][within[g]]:
            if assignment[h] < 0:
                assignment[h] = len(bases) - 1
                remaining.discard(int(h))
    return np.array(bases), assignment


@pytest.mark.parametrize("radius, k", [(0.6, 8), (0.9, 30), (0.3, 4)])
def test_greedy_choice_equals_the_quadratic_reference(radius: float, k: int) -> None:
    rng = np.random.default_rng(2)
    features = rng.normal(size=(300, 15)).astype(np.float32) * 0.3
    index = FrameIndex(database_of([100, 200]), "E15", features)
    clusters = base_poses(index, radius=radius, k=k, chunk=64)
    bases, assignment = reference_greedy(features, radius, k)
    np.testing.assert_array_equal(clusters.bases, bases)
    np.testing.assert_array_equal(clusters.assignment, assignment)


def test_bad_k_is_refused_and_padding_is_no_neighbour() -> None:
    index, _ = blob_index([5, 5])
    with pytest.raises(ValueError, match="k must be a whole number between 1 and the database's 10 frames, got 11"):
        base_poses(index, radius=0.2, k=11)
    counts, bases, assignment = greedy_bases(np.array([[0, -1], [1, 0], [2, -1]]))
    np.testing.assert_array_equal(counts, [1, 2, 1])
    np.testing.assert_array_equal(bases, [1, 2])
    np.testing.assert_array_equal(assignment, [0, 0, 1])


def hub_index() -> FrameIndex:
    """Two takes of hub poses A, B, C (exact copies, centres 10 apart) and transit frames x (each alone):
    take 0 ``A A A x x B B x C C x A A``, take 1 ``B B x A A x C C``."""
    layout = ["AAAxxBBxCCxAA", "BBxAAxCC"]
    database = database_of([len(t) for t in layout])
    centres = {"A": 0, "B": 1, "C": 2}
    features = np.zeros((database.num_frames, 15), dtype=np.float32)
    for g, symbol in enumerate("".join(layout)):
        if symbol == "x":
            features[g, 3 + g % 12] = 100.0 + 10.0 * g  # far from everything and from each other
        else:
            features[g, centres[symbol]] = 10.0
    return FrameIndex(database, "E15", features)


def test_fat_graph_nodes_are_the_hubs_and_edges_the_motion_between_visits() -> None:
    from stylemotion.search.clip_graph import largest_scc
    from stylemotion.search.fat_graph import fat_graph, hub_visits

    index = hub_index()
    clusters = base_poses(index, radius=0.5, k=16)
    reps, cluster = hub_visits(clusters, index, min_members=2)
    np.testing.assert_array_equal(reps, [0, 5, 8, 11, 13, 16, 19])  # each visit's first frame (all tie)
    graph = fat_graph(index, radius=0.5, k=16, min_members=2)
    # clusters by neighbour count: A (7 frames), then B and C (4 each; B's first frame is earlier)
    np.testing.assert_array_equal(graph.node_frame, [0, 5, 8])
    assert graph.settings["hubs"] == 3 and graph.candidates == 7
    edges = list(zip(graph.src.tolist(), graph.dst.tolist(), graph.start.tolist(), graph.end.tolist()))
    assert edges == [(0, 1, 0, 5), (1, 2, 5, 8), (2, 0, 8, 11), (1, 0, 13, 16), (0, 2, 16, 19)]
    assert graph.coverage == pytest.approx(19 / 21)  # take 0's last frame and take 1's last one: after the visits
    pruned = largest_scc(graph)
    assert pruned.num_nodes == 3 and pruned.num_edges == 5
    # a hub needs 5 frames: A alone, visited twice in take 0 and once in take 1: one self-loop A → A in take 0
    lone = fat_graph(index, radius=0.5, k=16, min_members=5)
    assert list(zip(lone.src.tolist(), lone.dst.tolist(), lone.start.tolist(), lone.end.tolist())) == [(0, 0, 0, 11)]
    with pytest.raises(ValueError, match="exceeds k"):
        fat_graph(index, radius=0.5, k=16, min_members=17)
