"""Fast fat-graph base poses (Krüger §2.5.3; fat graphs: Shin and Oh 2006).

The base poses cluster a motion database: poses with many close poses become base poses and absorb their
neighbours. The thesis replaces the quadratic neighbourhood computation by k-d tree searches:

1. every frame's neighbours within a fixed radius ``r`` (at most ``k``), one batched radius query of the
   :class:`~stylemotion.search.index.FrameIndex` per chunk of frames — O(k n log n);
2. the frame with the most neighbours is a base pose.

Step 2 is repeated greedily (our reading of "base poses", plural): frames are visited once in order of
decreasing neighbour count (ties: lower global index first); a frame not yet in a cluster becomes a base
pose, and its listed neighbours not yet in a cluster join it. Every frame ends in exactly one cluster (a
frame reached uncovered is its own base). The order is one sort and the sweep O(n k): O(n log n) in all
for a constant ``k``. A frame counts itself among its neighbours (distance 0).

:func:`write_clusters` exports ``clusters.json`` (per base pose: its global index, take, frame, labels,
members, neighbour count) and ``clusters.npz`` (memberships).

:func:`fat_graph` builds the graph over the clusters (Shin and Oh's fat graph as the thesis describes it: the
base poses are hubs, the motion between them edges): the clusters with at least ``min_members`` frames are the
hubs (nodes); a *visit* is a run of consecutive frames of a take in one hub, represented by its frame nearest
the hub's base pose (features); the frames from one visit's representative to the next visit's, in each take,
are an edge from the first hub to the second. Many edges join the same two hubs (the graph is "fat"); a walk
(:mod:`stylemotion.search.clip_graph`) changes take only at a hub, blending the two representatives there.
"""

from __future__ import annotations

import io
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.jsonfile import write_json
from stylemotion.search.clip_graph import ClipGraph, DatabaseFrames, edges_graph
from stylemotion.search.index import FrameIndex

#: Frames per batched radius query (bounds the (chunk, k) arrays).
CHUNK = 65536


@dataclass(frozen=True, eq=False)
class FatGraphClusters:
    """Base poses and memberships of a database.

    Attributes:
        radius: the neighbourhood radius (feature units).  k: most neighbours per frame.
        counts: ``(n,)`` int64 neighbours of each frame within ``radius`` (itself included, at most ``k``).
        bases: ``(c,)`` int64 global frame of each cluster's base pose, in order of choice.
        assignment: ``(n,)`` int64 cluster of every frame (index into ``bases``).
    """

    radius: float
    k: int
    counts: np.ndarray
    bases: np.ndarray
    assignment: np.ndarray

    @property
    def num_clusters(self) -> int:
        return int(self.bases.shape[0])

    @property
    def sizes(self) -> np.ndarray:
        """``(c,)`` frames in each cluster, base pose included."""
        return np.bincount(self.assignment, minlength=self.num_clusters)


def neighbour_lists(index: FrameIndex, radius: float, k: int, chunk: int = CHUNK) -> np.ndarray:
    """``(n, k)`` int64 each database frame's neighbours within ``radius`` (at most ``k``, nearest first,
    ``-1`` padding), by batched radius queries of the index over its own features."""
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k <= index.size:
        raise ValueError(f"k must be a whole number between 1 and the database's {index.size} frames, got {k!r}")
    out = np.empty((index.size, int(k)), dtype=np.int64)
    for lo in range(0, index.size, chunk):
        _, ind = index.query(index.features[lo:lo + chunk], int(k), radius=radius)
        out[lo:lo + chunk] = ind
    return out


def greedy_bases(neighbours: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Greedy base poses from ``(n, k)`` neighbour lists (``-1`` padding): ``(counts (n,), bases (c,),
    assignment (n,))`` as the module docstring describes."""
    n = neighbours.shape[0]
    counts = np.count_nonzero(neighbours >= 0, axis=1).astype(np.int64)
    order = np.lexsort((np.arange(n), -counts))  # most neighbours first, ties by index
    assignment = np.full(n, -1, dtype=np.int64)
    bases: list[int] = []
    for g in order:
        if assignment[g] >= 0:
            continue
        cluster = len(bases)
        bases.append(int(g))
        assignment[g] = cluster
        members = neighbours[g]
        members = members[members >= 0]
        assignment[members[assignment[members] < 0]] = cluster
    return counts, np.array(bases, dtype=np.int64), assignment


def base_poses(index: FrameIndex, radius: float, k: int = 64, chunk: int = CHUNK) -> FatGraphClusters:
    """Fat-graph base poses of the whole database of ``index`` (its feature set, distance ≤ ``radius``,
    at most ``k`` neighbours per frame)."""
    neighbours = neighbour_lists(index, radius, k, chunk)
    counts, bases, assignment = greedy_bases(neighbours)
    return FatGraphClusters(float(radius), int(k), counts, bases, assignment)


def cluster_records(clusters: FatGraphClusters, index: FrameIndex) -> list[dict[str, Any]]:
    """Per base pose, in order of choice: ``{"cluster", "base", "take", "frame", "content", "style", "members",
    "neighbours"}`` (``base``: global frame; ``frame``: in the take at the dataset's fps; ``members``: frames in
    the cluster, the base included; ``neighbours``: its neighbour count)."""
    sizes = clusters.sizes
    out = []
    for c, g in enumerate(clusters.bases):
        where = index.locate(int(g))
        out.append({"cluster": c, "base": int(g), "take": where.take, "frame": where.frame,
                    "content": where.content, "style": where.style, "members": int(sizes[c]),
                    "neighbours": int(clusters.counts[g])})
    return out


def write_clusters(clusters: FatGraphClusters, index: FrameIndex, folder: str | os.PathLike) -> tuple[Path, Path]:
    """Write ``clusters.json`` (settings and :func:`cluster_records`) and ``clusters.npz`` (``assignment``
    (n,), ``bases`` (c,), ``counts`` (n,), ``take_id`` (n,), ``frame_in_take`` (n,)) into ``folder``,
    atomically; returns both paths."""
    folder = Path(folder)
    meta = {"dataset": index.database.name, "features": index.feature_set, "normalization": index.normalization,
            "radius": clusters.radius, "k": clusters.k, "frames": index.size, "clusters": clusters.num_clusters,
            "base_poses": cluster_records(clusters, index)}
    json_path, npz_path = folder / "clusters.json", folder / "clusters.npz"
    write_json(json_path, meta)
    buffer = io.BytesIO()
    np.savez(buffer, assignment=clusters.assignment, bases=clusters.bases, counts=clusters.counts,
             take_id=index.database.take_id, frame_in_take=index.database.frame_in_take)
    atomic_write_bytes(npz_path, buffer.getvalue())
    return json_path, npz_path


def hub_visits(clusters: FatGraphClusters, index: FrameIndex, min_members: int) -> tuple[np.ndarray, np.ndarray]:
    """Visits to the hubs (clusters of ≥ ``min_members`` frames), in database order: ``(representative (v,)
    global frames, cluster (v,))`` — per run of consecutive frames of one take in one hub, the frame nearest (in
    the index's features) the hub's base pose (ties: the earliest)."""
    if isinstance(min_members, bool) or not isinstance(min_members, (int, np.integer)) or min_members < 1:
        raise ValueError(f"min_members must be a whole number ≥ 1, got {min_members!r}")
    db = index.database
    a = clusters.assignment
    hub = np.where(clusters.sizes[a] >= min_members, a, -1)
    new_take = np.zeros(len(a), dtype=bool)
    new_take[db.take_start[:-1][db.take_start[:-1] < len(a)]] = True
    changed = np.ones(len(a), dtype=bool)
    changed[1:] = hub[1:] != hub[:-1]
    run_start = np.flatnonzero((hub >= 0) & (changed | new_take))
    bounds = np.flatnonzero(changed | new_take)
    run_end = np.append(bounds, len(a))[np.searchsorted(bounds, run_start, side="right")]
    distance = np.linalg.norm(index.features - index.features[clusters.bases[np.maximum(a, 0)]], axis=1)
    reps = np.array([s + int(np.argmin(distance[s:z])) for s, z in zip(run_start, run_end)], dtype=np.int64)
    return reps, hub[run_start]


def fat_graph(index: FrameIndex, radius: float, k: int = 64, min_members: int = 20,
              clusters: FatGraphClusters | None = None, frames: DatabaseFrames | None = None) -> ClipGraph:
    """The fat graph over the base-pose clusters of ``index``'s database (module docstring), not yet pruned
    (:func:`stylemotion.search.clip_graph.largest_scc`).

    Args:
        index: the database's frame index (its features define the clusters).
        radius, k: :func:`base_poses`' settings (ignored when ``clusters`` is given).
        min_members: least frames of a cluster that is a hub.
        clusters: base poses already computed on ``index``.  frames: the database's
            :class:`~stylemotion.search.clip_graph.DatabaseFrames` (computed when None).

    Returns:
        A :class:`~stylemotion.search.clip_graph.ClipGraph`: node ``h`` is the ``h``-th hub in the clusters'
        order (``node_frame``: its base pose), one edge per two consecutive visits of a take.
    """
    clusters = base_poses(index, radius, k) if clusters is None else clusters
    if isinstance(min_members, (int, np.integer)) and not isinstance(min_members, bool) and min_members > clusters.k:
        raise ValueError(f"min_members={min_members} exceeds k={clusters.k}: no cluster holds more than k frames")
    reps, cluster = hub_visits(clusters, index, min_members)
    hubs = np.flatnonzero(clusters.sizes >= min_members)
    node_of = np.full(clusters.num_clusters, -1, dtype=np.int64)
    node_of[hubs] = np.arange(len(hubs))
    same_take = index.database.take_id[reps[:-1]] == index.database.take_id[reps[1:]]
    first, second = np.flatnonzero(same_take), np.flatnonzero(same_take) + 1
    frames = DatabaseFrames.of(index.database) if frames is None else frames
    settings = {"features": index.feature_set, "radius": float(clusters.radius), "k": int(clusters.k),
                "min_members": int(min_members), "clusters": clusters.num_clusters, "hubs": int(len(hubs))}
    return edges_graph("fat graph", frames, clusters.bases[hubs], node_of[cluster[first]], node_of[cluster[second]],
                       reps[first], reps[second], settings, candidates=int(len(reps)))
