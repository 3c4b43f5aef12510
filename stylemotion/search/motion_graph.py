"""A plain motion graph with frame-to-frame transitions (Kovar, Gleicher and Pighin 2002), on the shared
:class:`~stylemotion.search.index.FrameIndex`: the baseline of the fat graph (docs/search.md, "Graphs that
synthesize").

1. **Candidates.** Every frame ``i``'s nearest frames ``j`` within ``threshold`` (feature units, at most ``k``),
   by batched radius queries of the index over its own features — O(k n log n) instead of Kovar's full distance
   matrix. Left out: ``j`` within ``min_gap_frames`` of ``i`` in the same take (the diagonal's trivial
   transitions) and ``j`` the last frame of its take (nothing follows it).
2. **Local minima.** A candidate ``(i, j)`` stays when no candidate among its 8 neighbours ``(i ± 1, j ± 1)`` (each
   in its frame's take) is closer (Kovar: local minima of the distance matrix; a neighbour that is no candidate
   is farther than the threshold or than the k-th neighbour, so it counts as larger).
3. **Graph.** A transition ``(i, j)`` means: after playing up to ``i``, play on from ``j`` (``j`` takes ``i``'s place
   at the junction, :mod:`stylemotion.search.clip_graph`). The cut frames are the transitions' ``i`` and ``j``
   and every take's first and last frame; each is a node. Edges: from each cut ``c`` to the next cut ``c'`` of its
   take, the clip ``c … c'``; for each transition ``(i, j)``, from node ``i`` to the cut after ``j``, the clip
   ``j … next cut``.

Pruning to the largest strongly connected component is :func:`~stylemotion.search.clip_graph.largest_scc`.
"""

from __future__ import annotations

import numpy as np

from stylemotion.search.clip_graph import ClipGraph, DatabaseFrames, edges_graph
from stylemotion.search.database import MotionDatabase
from stylemotion.search.index import FrameIndex

#: Frames per batched radius query.
CHUNK = 65536
NEIGHBOURS = [(a, b) for a in (-1, 0, 1) for b in (-1, 0, 1) if (a, b) != (0, 0)]


def candidate_transitions(index: FrameIndex, threshold: float, k: int = 32, min_gap_frames: int = 10,
                          chunk: int = CHUNK) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step 1 of the module docstring: ``(i (t,), j (t,), distance (t,))``, sorted by ``(i, j)``."""
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k <= index.size:
        raise ValueError(f"k must be a whole number between 1 and the database's {index.size} frames, got {k!r}")
    if isinstance(min_gap_frames, bool) or not isinstance(min_gap_frames, (int, np.integer)) or min_gap_frames < 1:
        raise ValueError(f"min_gap_frames must be a whole number ≥ 1, got {min_gap_frames!r}")
    db = index.database
    last = np.zeros(db.num_frames, dtype=bool)
    last[db.take_start[1:] - 1] = True
    out_i, out_j, out_d = [], [], []
    for lo in range(0, index.size, chunk):
        d, j = index.query(index.features[lo:lo + chunk], int(k), radius=threshold)
        i = np.broadcast_to(np.arange(lo, lo + len(j))[:, None], j.shape)
        keep = j >= 0
        i, j, d = i[keep], j[keep], d[keep]
        near = (db.take_id[i] == db.take_id[j]) & (np.abs(i - j) < min_gap_frames)
        keep = ~near & ~last[j]
        out_i.append(i[keep])
        out_j.append(j[keep])
        out_d.append(d[keep])
    i, j, d = np.concatenate(out_i), np.concatenate(out_j), np.concatenate(out_d)
    order = np.lexsort((j, i))
    return i[order].astype(np.int64), j[order].astype(np.int64), d[order]


def local_minima(database: MotionDatabase, i: np.ndarray, j: np.ndarray, distance: np.ndarray) -> np.ndarray:
    """Step 2 of the module docstring: ``(t,)`` bool, the candidates no neighbouring candidate beats."""
    n = database.num_frames
    keys = i * n + j
    order = np.argsort(keys, kind="stable")
    sorted_keys = keys[order]
    keep = np.ones(len(i), dtype=bool)
    for di, dj in NEIGHBOURS:
        ni, nj = i + di, j + dj
        ok = (ni >= 0) & (ni < n) & (nj >= 0) & (nj < n)
        ni, nj = np.clip(ni, 0, n - 1), np.clip(nj, 0, n - 1)
        ok &= (database.take_id[ni] == database.take_id[i]) & (database.take_id[nj] == database.take_id[j])
        pos = np.minimum(np.searchsorted(sorted_keys, ni * n + nj), max(len(keys) - 1, 0))
        found = ok & (sorted_keys[pos] == ni * n + nj) if len(keys) else ok
        keep &= ~(found & (distance[order[pos]] < distance))
    return keep


def motion_graph(index: FrameIndex, threshold: float, k: int = 32, min_gap_frames: int = 10,
                 frames: DatabaseFrames | None = None) -> ClipGraph:
    """The plain motion graph of ``index``'s database (module docstring), not yet pruned.

    Args:
        index: the database's frame index (its features define the frame distance).
        threshold: largest distance of a transition (feature units).  k: most candidates per frame.
        min_gap_frames: frames of the same take this close are no transition.
        frames: the database's :class:`~stylemotion.search.clip_graph.DatabaseFrames` (computed when None).
    """
    db = index.database
    i, j, d = candidate_transitions(index, threshold, k, min_gap_frames)
    minima = local_minima(db, i, j, d)
    i, j = i[minima], j[minima]
    bounds = np.concatenate([db.take_start[:-1], db.take_start[1:] - 1])
    cuts = np.unique(np.concatenate([i, j, bounds[(bounds >= 0) & (bounds < db.num_frames)]]))
    node_of = np.full(db.num_frames, -1, dtype=np.int64)
    node_of[cuts] = np.arange(len(cuts))
    # the next cut of each cut in its take (-1 for a take's last frame)
    following = np.append(cuts[1:], -1)
    following[(following < 0) | (db.take_id[np.maximum(following, 0)] != db.take_id[cuts])] = -1
    inside = following >= 0
    src = [node_of[cuts[inside]]]
    dst = [node_of[following[inside]]]
    start, end = [cuts[inside]], [following[inside]]
    after_j = following[node_of[j]]  # j is no take's last frame (step 1), so a cut follows it
    src.append(node_of[i])
    dst.append(node_of[after_j])
    start.append(j)
    end.append(after_j)
    frames = DatabaseFrames.of(db) if frames is None else frames
    settings = {"features": index.feature_set, "threshold": float(threshold), "k": int(k),
                "min_gap_frames": int(min_gap_frames)}
    return edges_graph("motion graph", frames, cuts, np.concatenate(src), np.concatenate(dst),
                       np.concatenate(start), np.concatenate(end), settings, candidates=int(len(i)))
