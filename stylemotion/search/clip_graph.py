"""Motion graphs whose edges are clips of database frames: pruning to the largest strongly connected component,
walks and their motion (Kovar et al. 2002; fat graphs: Shin and Oh 2006, Krüger §2.5.3). docs/search.md,
"Graphs that synthesize".

A :class:`ClipGraph` has nodes ``0 … m−1``; edge ``e`` runs from node ``src[e]`` to node ``dst[e]`` and plays the
database frames ``start[e] … end[e]`` (global indices, one take, inclusive, ``end > start``). The two builders are
:func:`stylemotion.search.fat_graph.fat_graph` (nodes: hub clusters) and
:func:`stylemotion.search.motion_graph.motion_graph` (nodes: cut frames, Kovar-style transitions).

A walk is a list of edges, each starting where the one before ended. Its motion joins the clips at shared
keyframes with :func:`stylemotion.synthesis.stitching.append_clip` in the placement-free 66-dim representation
(:mod:`stylemotion.representation`), integrated once at the end: the first frame of the next clip takes the
place of the last frame of the one before. Where the two are different database frames (a *transition*), the
jump (pose, root velocity, yaw rate) fades out over ``blend_frames`` frames; where they are the same frame (two
edges that follow each other in a take) nothing changes.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.geometry import rotate_yaw
from stylemotion.representation import JOINT_DIMS, ROOT_JOINT, facing_yaw, positions_to_frames
from stylemotion.search.database import MotionDatabase
from stylemotion.skeleton import NUM_JOINTS

#: Frames over which a transition's jump fades (``append_clip``'s ``blend_frames``): 1/3 s at 30 fps.
BLEND_FRAMES = 10
#: Seconds a random walk plays on in its take after a transition before it may take another.
MIN_PLAY_S = 0.5


@dataclass(frozen=True, eq=False)
class DatabaseFrames:
    """What walks need of every database frame.

    Attributes:
        database: the frames.  frames66: ``(n, 66)`` float64 the 66-dim frames of each take
            (:func:`~stylemotion.representation.positions_to_frames`).
        yaw: ``(n,)`` each frame's facing (:func:`~stylemotion.representation.facing_yaw`, radians).
        local_velocity: ``(n, 21, 3)`` joint velocities in the body frame (the facing of
            :func:`~stylemotion.representation.facing_yaw`), m/s, central differences within the take.
    """

    database: MotionDatabase
    frames66: np.ndarray
    yaw: np.ndarray
    local_velocity: np.ndarray

    @classmethod
    def of(cls, database: MotionDatabase) -> DatabaseFrames:
        n, fps = database.num_frames, float(database.fps)
        frames = np.zeros((n, JOINT_DIMS.stop + 3))
        velocity = np.zeros((n, NUM_JOINTS, 3))
        yaws = np.zeros(n)
        for t in range(database.num_takes):
            a, z = int(database.take_start[t]), int(database.take_start[t + 1])
            if z - a < 2:
                continue
            p = np.asarray(database.positions[a:z], dtype=np.float64)
            frames[a:z] = positions_to_frames(p, fps)[0]
            yaw = yaws[a:z] = facing_yaw(p, fps)
            velocity[a:z] = rotate_yaw(np.gradient(p, axis=0) * fps, -yaw[:, None])
        return cls(database, frames, yaws, velocity)

    def gaps(self, before: np.ndarray, after: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Pose gap (cm: mean over joints of the body-frame distance) and velocity gap (m/s: mean over joints of
        the body-frame velocity difference) between database frames ``before`` and ``after`` (same shapes)."""
        pose_b = self.frames66[before][..., JOINT_DIMS].reshape(np.shape(before) + (NUM_JOINTS, 3))
        pose_a = self.frames66[after][..., JOINT_DIMS].reshape(np.shape(after) + (NUM_JOINTS, 3))
        pose = np.linalg.norm(pose_b - pose_a, axis=-1).mean(axis=-1) * 100.0
        vel = np.linalg.norm(self.local_velocity[before] - self.local_velocity[after], axis=-1).mean(axis=-1)
        return pose, vel


@dataclass(frozen=True, eq=False)
class ClipGraph:
    """A motion graph whose edges are clips of database frames (module docstring).

    Attributes:
        kind: ``"fat graph"`` or ``"motion graph"``.  frames: the database's :class:`DatabaseFrames`.
        num_nodes: m.  node_frame: ``(m,)`` a database frame standing for each node (a hub's base pose, a cut
            frame).  src, dst, start, end: ``(e,)`` int64 edges (module docstring).
        settings: JSON-ready construction settings.  candidates: what the builder joined the clips at, before
            pruning (fat graph: hub visits; motion graph: transitions), for the record.
    """

    kind: str
    frames: DatabaseFrames
    num_nodes: int
    node_frame: np.ndarray
    src: np.ndarray
    dst: np.ndarray
    start: np.ndarray
    end: np.ndarray
    settings: dict[str, Any] = field(default_factory=dict)
    candidates: int = 0

    @property
    def database(self) -> MotionDatabase:
        return self.frames.database

    @property
    def num_edges(self) -> int:
        return int(self.src.shape[0])

    def covered(self) -> np.ndarray:
        """``(n,)`` bool: database frames that some edge plays."""
        marks = np.zeros(self.database.num_frames + 1, dtype=np.int64)
        np.add.at(marks, self.start, 1)
        np.add.at(marks, self.end + 1, -1)
        return np.cumsum(marks)[:-1] > 0

    @property
    def coverage(self) -> float:
        """Share of the database's frames that some edge plays."""
        return float(self.covered().mean()) if self.database.num_frames else 0.0

    def out_edges(self, node: int) -> np.ndarray:
        """Edges leaving ``node``, ascending."""
        order, offsets = self._out
        return order[offsets[node]:offsets[node + 1]]

    @property
    def _out(self) -> tuple[np.ndarray, np.ndarray]:
        cached = self.__dict__.get("_out_cache")
        if cached is None:
            order = np.argsort(self.src, kind="stable")
            offsets = np.searchsorted(self.src[order], np.arange(self.num_nodes + 1))
            cached = (order, offsets)
            self.__dict__["_out_cache"] = cached
        return cached

    def records(self) -> dict[str, Any]:
        """JSON-ready figures: nodes, edges, transitions, coverage and settings."""
        return {"kind": self.kind, "nodes": self.num_nodes, "edges": self.num_edges,
                "candidates": self.candidates, "coverage": self.coverage, "settings": self.settings,
                "database": {"name": self.database.name, "takes": self.database.num_takes,
                             "frames": self.database.num_frames, "fps": float(self.database.fps)}}


def edges_graph(kind: str, frames: DatabaseFrames, node_frame: np.ndarray, src: np.ndarray, dst: np.ndarray,
                start: np.ndarray, end: np.ndarray, settings: dict[str, Any], candidates: int = 0) -> ClipGraph:
    """A :class:`ClipGraph` from edge arrays, checked: every clip inside one take, ``end > start``."""
    src, dst, start, end = (np.asarray(x, dtype=np.int64).reshape(-1) for x in (src, dst, start, end))
    db = frames.database
    if not (len(src) == len(dst) == len(start) == len(end)):
        raise ValueError("src, dst, start and end must have one entry per edge")
    if len(src):
        if (end <= start).any() or start.min() < 0 or end.max() >= db.num_frames:
            raise ValueError("every edge needs database frames start < end")
        if (db.take_id[start] != db.take_id[end]).any():
            raise ValueError("every edge's clip must lie in one take")
    return ClipGraph(kind, frames, int(len(node_frame)), np.asarray(node_frame, dtype=np.int64), src, dst, start,
                     end, dict(settings), int(candidates))


def largest_scc(graph: ClipGraph) -> ClipGraph:
    """The graph cut to its largest strongly connected component (most nodes, then most edges): the nodes a walk
    can both reach and leave forever; nodes renumbered in their old order, edges kept in order."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    m = graph.num_nodes
    if m == 0 or graph.num_edges == 0:
        return edges_graph(graph.kind, graph.frames, np.zeros(0, np.int64), *([np.zeros(0, np.int64)] * 4),
                           graph.settings, graph.candidates)
    adjacency = csr_matrix((np.ones(graph.num_edges), (graph.src, graph.dst)), shape=(m, m))
    _, labels = connected_components(adjacency, directed=True, connection="strong")
    inner = labels[graph.src] == labels[graph.dst]
    nodes = np.bincount(labels)
    edges = np.bincount(labels[graph.src][inner], minlength=len(nodes))
    best = int(np.lexsort((-np.arange(len(nodes)), edges, nodes))[-1])
    keep_nodes = np.flatnonzero(labels == best)
    renumber = np.full(m, -1, dtype=np.int64)
    renumber[keep_nodes] = np.arange(len(keep_nodes))
    keep = (labels[graph.src] == best) & (labels[graph.dst] == best)
    return edges_graph(graph.kind, graph.frames, graph.node_frame[keep_nodes], renumber[graph.src[keep]],
                       renumber[graph.dst[keep]], graph.start[keep], graph.end[keep], graph.settings,
                       graph.candidates)


@dataclass(frozen=True)
class Walk:
    """Edges of a walk, in order; ``stuck``: it reached a node without an edge out before its length."""

    edges: tuple[int, ...]
    stuck: bool = False


def walk_frames(graph: ClipGraph, edges: tuple[int, ...] | list[int]) -> int:
    """Frames of a walk's motion (shared keyframes counted once)."""
    e = np.asarray(edges, dtype=np.int64)
    return int((graph.end[e] - graph.start[e]).sum() + 1) if len(e) else 0


def random_walk(graph: ClipGraph, seconds: float, rng: np.random.Generator, start: int | None = None,
                min_play_s: float = MIN_PLAY_S) -> Walk:
    """A seeded random walk of at least ``seconds``: from node ``start`` (a random node when None), each step an
    edge out of the current node drawn uniformly — except that until ``min_play_s`` seconds have played since the
    last transition, the walk keeps to the edge that continues its take where there is one (so clips last;
    0: every step uniform). ``stuck`` when a node has no edge out (never inside an SCC) or the graph has none."""
    if graph.num_nodes == 0 or graph.num_edges == 0:
        return Walk((), stuck=True)
    node = int(rng.integers(graph.num_nodes)) if start is None else int(start)
    need = max(2, int(np.ceil(seconds * graph.database.fps)) + 1)
    min_play = int(round(min_play_s * graph.database.fps))
    edges: list[int] = []
    frames, since, last_end = 1, 0, -1
    while frames < need:
        out = graph.out_edges(node)
        if not len(out):
            return Walk(tuple(edges), stuck=True)
        if since < min_play and last_end >= 0:
            onward = out[graph.start[out] == last_end]
            out = onward if len(onward) else out
        e = int(out[rng.integers(len(out))])
        length = int(graph.end[e] - graph.start[e])
        since = since + length if graph.start[e] == last_end else length
        edges.append(e)
        frames += length
        node, last_end = int(graph.dst[e]), int(graph.end[e])
    return Walk(tuple(edges))


def goal_walk(graph: ClipGraph, start: int, goal_frame: int) -> Walk | None:
    """The shortest walk (in frames) from node ``start`` that plays database frame ``goal_frame``, ending with the
    edge that plays it; None when no edge of the graph plays it or none of those can be reached."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import dijkstra

    holders = np.flatnonzero((graph.start <= goal_frame) & (graph.end >= goal_frame))
    if not len(holders) or not 0 <= start < graph.num_nodes:
        return None
    m = graph.num_nodes
    # the cheapest edge per (src, dst) pair carries the distance; parallel edges would be summed by csr_matrix
    length = (graph.end - graph.start).astype(np.float64)
    order = np.lexsort((length, graph.dst, graph.src))
    first = np.ones(len(order), dtype=bool)
    first[1:] = (graph.src[order][1:] != graph.src[order][:-1]) | (graph.dst[order][1:] != graph.dst[order][:-1])
    chosen = order[first]
    adjacency = csr_matrix((length[chosen], (graph.src[chosen], graph.dst[chosen])), shape=(m, m))
    dist, pred = dijkstra(adjacency, directed=True, indices=int(start), return_predecessors=True)
    reach = dist[graph.src[holders]]
    if not np.isfinite(reach).any():
        return None
    last = int(holders[np.argmin(reach)])
    best_edge = {(int(graph.src[e]), int(graph.dst[e])): int(e) for e in chosen}
    path: list[int] = [last]
    node = int(graph.src[last])
    while node != start:
        before = int(pred[node])
        path.append(best_edge[(before, node)])
        node = before
    return Walk(tuple(path[::-1]))


@dataclass(frozen=True, eq=False)
class WalkMotion:
    """The motion of a walk.

    Attributes:
        positions: ``(frames, 21, 3)`` metres.  fps: frames per second.
        junctions: ``(j,)`` frames where one edge's clip meets the next's.
        transition: ``(j,)`` bool: the junction joins two different database frames (blended).
        before, after: ``(j,)`` the database frames that meet there (the old clip's last, the new one's first).
        played: ``(frames,)`` the database frame played at each frame (before blending).
    """

    positions: np.ndarray
    fps: float
    junctions: np.ndarray
    transition: np.ndarray
    before: np.ndarray
    after: np.ndarray
    played: np.ndarray


def synthesize(graph: ClipGraph, walk: Walk, blend_frames: int = BLEND_FRAMES) -> WalkMotion:
    """The motion of ``walk`` (module docstring), its first frame placed where that database frame stands."""
    from stylemotion.representation import frames_to_positions
    from stylemotion.synthesis.stitching import append_clip

    if not walk.edges:
        raise ValueError("a walk without edges has no motion")
    f = graph.frames
    motion, junctions, played = None, [], []
    for e in walk.edges:
        a, z = int(graph.start[e]), int(graph.end[e])
        motion, junction = append_clip(motion, f.frames66[a:z + 1], blend_frames)
        played = played[:-1] + list(range(a, z + 1))
        junctions.append(junction)
    edges = np.asarray(walk.edges, dtype=np.int64)
    before, after = graph.end[edges[:-1]], graph.start[edges[1:]]
    first = int(graph.start[edges[0]])
    start_xz = np.asarray(graph.database.positions[first, ROOT_JOINT], dtype=np.float64)[[0, 2]]
    positions = frames_to_positions(motion, graph.database.fps, start_xz, float(f.yaw[first]))
    return WalkMotion(np.asarray(positions), float(graph.database.fps), np.asarray(junctions[1:], dtype=np.int64),
                      before != after, before, after, np.asarray(played, dtype=np.int64))


def walk_figures(graph: ClipGraph, motion: WalkMotion) -> dict[str, Any]:
    """JSON-ready figures of a walk's motion: ``seconds``, ``edges``, ``transitions`` (blended junctions) and per
    second, the transitions' pose gap (cm) and velocity gap (m/s) before blending (:meth:`DatabaseFrames.gaps`;
    mean and max, None without transitions), ``foot_skating`` (:func:`stylemotion.synthesis.quality.skating` of
    the motion) and ``transition_accel_ratio`` (:func:`stylemotion.synthesis.stitching.transition_speed_ratio`
    at the transitions; None without any)."""
    from stylemotion.synthesis.quality import skating
    from stylemotion.synthesis.stitching import transition_speed_ratio

    seconds = (len(motion.positions) - 1) / motion.fps
    t = motion.transition
    pose, vel = graph.frames.gaps(motion.before[t], motion.after[t])
    skate, _ = skating(motion.positions, motion.fps)
    ratio = (transition_speed_ratio(motion.positions, motion.fps, [int(j) for j in motion.junctions[t]])
             if t.any() else None)

    def stat(values: np.ndarray, how: Any) -> float | None:
        return float(how(values)) if len(values) else None

    return {"seconds": seconds, "edges": int(len(motion.junctions) + 1), "transitions": int(t.sum()),
            "transitions_per_s": float(t.sum() / seconds) if seconds > 0 else None,
            "pose_gap_cm": stat(pose, np.mean), "pose_gap_cm_max": stat(pose, np.max),
            "velocity_gap_mps": stat(vel, np.mean), "velocity_gap_mps_max": stat(vel, np.max),
            "foot_skating": float(skate), "transition_accel_ratio": None if ratio is None else ratio["accel_ratio"]}


def write_walk(graph: ClipGraph, walk: Walk, motion: WalkMotion, folder: str | os.PathLike) -> tuple[Path, Path]:
    """Write ``walk.bvh`` (the motion, rotations fitted by :func:`stylemotion.io.export.write_motion_bvh`) and
    ``walk.json`` (per edge its take, first and last frame in the take, and :func:`walk_figures`) into
    ``folder``, atomically; returns both paths."""
    from stylemotion.io.export import write_motion_bvh
    from stylemotion.io.jsonfile import write_json

    folder = Path(folder)
    db = graph.database
    clips = []
    for e in walk.edges:
        where = db.locate(int(graph.start[e]))
        clips.append({"edge": int(e), "from_node": int(graph.src[e]), "to_node": int(graph.dst[e]),
                      "take": where.take, "first": where.frame,
                      "last": where.frame + int(graph.end[e] - graph.start[e])})
    bvh, meta = folder / "walk.bvh", folder / "walk.json"
    write_motion_bvh(motion.positions, bvh, motion.fps)
    write_json(meta, {"graph": graph.records(), "clips": clips, "figures": walk_figures(graph, motion)})
    return bvh, meta
