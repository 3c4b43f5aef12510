"""Motion from a few keyframes with dynamic motion graphs (Krüger §4.3).

A keyframe is a whole pose in the world (``(21, 3)`` metres, so root position and facing included) and a time.
Between every two consecutive keys ``k_i → k_{i+1}`` (docs/reconstruct.md, "Dynamic motion graphs"):

1. **Placement.** Every pose has a ground placement: origin = the Hips' ground point, yaw =
   :func:`~stylemotion.representation.facing_yaw` (unsmoothed). A database frame ``n`` "placed onto" a node puts
   ``n``'s placement onto the node's; the frames of a segment follow rigidly (a turn about +Y and a shift).
2. **Trees.** The tree O of outgoing segments grows from ``k_i``, the tree I of incoming segments from
   ``k_{i+1}``. Expanding a node = its ``k`` nearest database frames in E15 (the pose of a key; a node's own
   database frame; near-duplicates in one take suppressed), each followed forward (O) or backward (I) until the
   feet's contact state changes (at least ``min_segment_frames``, at most ``max_segment_s``); the segment is an
   edge, its last (O) / first (I) frame a new node. Each iteration expands the ``b`` best unexpanded nodes of
   each tree by ``D_node`` (eq. 4.12: the distance of hands, feet and head, summed, to the nearest node of the
   other tree, eq. 4.13, plus ``facing_weight_m`` × their facing difference — our addition), so the trees grow
   towards each other; nothing is discarded. With ``turn_radius_m > 0`` (our addition) the world distance is
   replaced by the body-frame pose difference plus 5 × the length of the shortest forward walk that turns no
   tighter than ``turn_radius_m`` from the outgoing node's placement to the incoming one's
   (:func:`~stylemotion.reconstruct.turning.dubins_length`): a key turned against the direction of travel is then
   far from the trees that face it, and they grow along a loop rather than stalling face to face.
   With ``facing_first_iterations > 0`` the search of eq. 4.12 (with the facing term) runs first and the turn-aware
   one only when its trees do not meet in that many iterations.
3. **Connections.** The Hips of every incoming frame go into a spatial hash of ``voxel_m`` voxels; every
   outgoing frame looks in its 27 neighbouring voxels. A pair connects when the Hips are within ``voxel_m``,
   the facings within ``max_turn_deg``, the body-frame hands/feet/head within ``max_pose_m`` (mean) and the
   body-frame root velocities within ``max_velocity_m_s`` (our additions: the thesis blends any close frames).
   The search stops ``extra_iterations`` after the first iteration that finds connections (the thesis: at once)
   or fails after ``max_iterations``.
4. **Path.** Each connection closes one path key → O-edges → blend → I-edges → key (the graph of the two trees
   and the connecting edges is a DAG and each connection is its own path through it): the cheapest by
   ``C_edge`` (eq. 4.14: the speed of every joint summed over the frames, in metres) plus — our additions —
   ``duration_weight`` × the frames missing or too many against the keys' time difference, each frame priced at
   the database's median ``C_edge`` per frame, and ``key_weight`` × the distance (summed over joints, metres) of
   the path's first and last database poses to the keys.
5. **Blend.** ``blend_frames`` frames around the connection: placement (ground point, yaw) and body-frame pose
   blended with smoothstep weights between the outgoing segment (continued in its database take) and the
   incoming one (started earlier in its take).
6. **Intermediate → result.** The paths are joined (the key's own frame once), resampled to the keys' times
   (``retime``) and cleaned by motion texturing (§4.3.4: :class:`~stylemotion.reconstruct.texture.MotionTexturer`
   in texture mode) with the keyframes pinned exactly.
"""

from __future__ import annotations

import logging
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from stylemotion.geometry import rotate_yaw, wrap_angle
from stylemotion.io.errors import UserInputError
from stylemotion.primitives.contacts import foot_contacts
from stylemotion.reconstruct.settings import DynamicGraphSettings as _G
from stylemotion.reconstruct.texture import MotionTexturer
from stylemotion.reconstruct.turning import dubins_length
from stylemotion.representation import facing_yaw
from stylemotion.search.database import MotionDatabase
from stylemotion.search.features import E15_JOINTS
from stylemotion.search.index import FrameIndex
from stylemotion.skeleton import JOINT_INDEX, NUM_JOINTS

EFFECTORS = np.array([JOINT_INDEX[j] for j in E15_JOINTS])
HIPS = JOINT_INDEX["Hips"]
#: Nearest-neighbour E15 distance (metres) above which a keyframe's pose is reported as far from the database.
FAR_KEY_M = 0.5
#: Longest time (seconds) from the first key to the last: the motion planned between them is allocated frame by
#: frame, so a key at a huge time is refused before anything is built (docs/reconstruct.md, "Keyframe files").
MAX_KEYS_SPAN_S = 600.0

log = logging.getLogger(__name__)


class KeyframeError(UserInputError, ValueError):
    """A keyframe, setting or database that cannot be used; the message names the value."""


class NoConnectionError(UserInputError, RuntimeError):
    """Two consecutive keyframes whose trees never met; the message names the keys and how close they came."""


class FarKeyframeWarning(UserWarning):
    """A keyframe's pose has no database frame near it (the message names the key and the distance)."""


@dataclass(frozen=True)
class Keyframe:
    """A pose ``(21, 3)`` metres in the world (Y up) at ``time_s`` seconds."""

    time_s: float
    pose: np.ndarray


def check_keyframes(keys: Sequence[Keyframe]) -> list[Keyframe]:
    """The keys as given, checked: at least two, poses ``(21, 3)`` finite, times finite and strictly increasing,
    the last at most :data:`MAX_KEYS_SPAN_S` after the first (KeyframeError naming the key otherwise)."""
    keys = list(keys)
    if len(keys) < 2:
        raise KeyframeError(f"{len(keys)} keyframe(s) given; a motion needs at least 2")
    for i, key in enumerate(keys):
        pose = np.asarray(key.pose)
        if pose.shape != (NUM_JOINTS, 3):
            raise KeyframeError(f"keyframe {i}: the pose must be ({NUM_JOINTS}, 3) metres, got {pose.shape}")
        if not np.isfinite(pose).all():
            raise KeyframeError(f"keyframe {i}: the pose has values that are not finite")
        if not np.isfinite(key.time_s):
            raise KeyframeError(f"keyframe {i}: time {key.time_s} is not finite")
        if i and key.time_s <= keys[i - 1].time_s:
            raise KeyframeError(f"keyframe {i}: time {key.time_s:g} s is not after keyframe {i - 1}'s "
                                f"{keys[i - 1].time_s:g} s (keys must be in time order)")
        if key.time_s - keys[0].time_s > MAX_KEYS_SPAN_S:
            raise KeyframeError(f"keyframe {i}: time {key.time_s:g} s is {key.time_s - keys[0].time_s:g} s after the "
                                f"first key; the keys may span at most {MAX_KEYS_SPAN_S:g} s (split the motion, or "
                                "check the time's unit: seconds)")
    return keys


def keys_from_motion(positions: np.ndarray, fps: float, every_s: float, start_s: float = 0.0,
                     end_s: float | None = None) -> list[Keyframe]:
    """Keyframes taken from a motion ``(frames, 21, 3)`` every ``every_s`` seconds from ``start_s`` (times
    relative to ``start_s``), up to ``end_s`` (default: the end)."""
    positions = np.asarray(positions, dtype=np.float64)
    last = (len(positions) - 1) / fps if end_s is None else min(end_s, (len(positions) - 1) / fps)
    first = int(round(start_s * fps))
    step = every_s * fps
    if every_s <= 0 or step < 1:
        raise KeyframeError(f"every_s={every_s} must be at least one frame (1/{fps:g} s)")
    frames = [first + int(round(i * step)) for i in range(int(np.floor((last - start_s) / every_s + 1e-9)) + 1)]
    if len(frames) < 2:
        raise KeyframeError(f"the motion ({len(positions)} frames at {fps:g} fps) holds fewer than two keys "
                            f"{every_s:g} s apart from {start_s:g} s")
    return [Keyframe((f - first) / fps, positions[f]) for f in frames]


def turn_key(pose: np.ndarray, turn_rad: float, shift_m: np.ndarray | None = None) -> np.ndarray:
    """A pose ``(21, 3)`` m turned by ``turn_rad`` (radians, a positive turn is to the left) about the vertical
    through its Hips, then moved by ``shift_m`` ``(3,)`` metres (the ``turn_deg`` / ``shift_m`` of a keyframe
    file; the turned keys of suite ``moved_keys``)."""
    pose = np.asarray(pose, dtype=np.float64)
    hips = pose[HIPS] * np.array([1.0, 0.0, 1.0])
    moved = rotate_yaw(pose - hips, turn_rad) + hips
    return moved if shift_m is None else moved + np.asarray(shift_m, dtype=np.float64)


def move_key(first: np.ndarray, second: np.ndarray, scale: float, turn_rad: float) -> np.ndarray:
    """The second of two key poses ``(21, 3)`` m moved as Krüger §4.3 moves a key ("Move second key frame"): its
    Hips' ground offset from the first key's scaled by ``scale``, then pose and offset turned by ``turn_rad`` about
    the vertical through the first key's Hips (so the key lies ``scale`` × as far, in another direction, facing
    as much turned)."""
    first, second = np.asarray(first, dtype=np.float64), np.asarray(second, dtype=np.float64)
    origin = first[HIPS] * np.array([1.0, 0.0, 1.0])
    offset = (second[HIPS] - first[HIPS]) * np.array([1.0, 0.0, 1.0])
    return rotate_yaw(second - origin + (scale - 1.0) * offset, turn_rad) + origin


def placements(positions: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Ground points ``(..., 3)`` (y = 0) and yaws ``(...,)`` radians of poses ``(..., frames, 21, 3)``."""
    positions = np.asarray(positions, dtype=np.float64)
    ground = positions[..., HIPS, :] * np.array([1.0, 0.0, 1.0])
    return ground, facing_yaw(positions, fps, smooth_seconds=0.0)


def place(points: np.ndarray, src_ground: np.ndarray, src_yaw: np.ndarray | float, dst_ground: np.ndarray,
          dst_yaw: np.ndarray | float) -> np.ndarray:
    """Points ``(..., j, 3)`` moved rigidly so that the placement ``(src_ground, src_yaw)`` lands on
    ``(dst_ground, dst_yaw)`` (ground points ``(..., 3)``, yaws radians)."""
    turn = np.asarray(dst_yaw - np.asarray(src_yaw))[..., None]
    return rotate_yaw(points - src_ground[..., None, :], turn) + dst_ground[..., None, :]


@dataclass
class _Tree:
    """One search tree: nodes (a placed database frame) and the edges (segments) that made them."""

    forward: bool
    turn_radius_m: float = 0.0  # D_node's turning radius for this search (0: eq. 4.12 with the facing term)
    node_frame: list[int] = field(default_factory=list)  # database frame (-1: the key itself)
    node_ground: list[np.ndarray] = field(default_factory=list)
    node_yaw: list[float] = field(default_factory=list)
    node_effectors: list[np.ndarray] = field(default_factory=list)  # (5, 3) world
    node_edge: list[int] = field(default_factory=list)  # edge that made it (-1: root)
    node_frames: list[int] = field(default_factory=list)  # frames of the path root → node, the node's included
    node_cost: list[float] = field(default_factory=list)  # C_edge of that path, metres
    node_anchor: list[float] = field(default_factory=list)  # Σ_J distance of its root edge's first pose to the key
    expanded: list[bool] = field(default_factory=list)
    edge_frames: list[np.ndarray] = field(default_factory=list)  # database frames, in time order
    edge_turn: list[float] = field(default_factory=list)  # yaw added to a database frame's placement
    edge_shift: list[np.ndarray] = field(default_factory=list)  # ground shift after the turn (3,)
    edge_parent: list[int] = field(default_factory=list)  # node it grew from
    edge_child: list[int] = field(default_factory=list)  # node it made
    best: np.ndarray = field(default_factory=lambda: np.zeros(0))  # D_node of the nodes scored so far
    seen_other: int = 0  # nodes of the other tree those D_node values have seen

    def add_node(self, frame: int, ground: np.ndarray, yaw: float, effectors: np.ndarray, edge: int, frames: int,
                 cost: float, anchor: float = 0.0) -> int:
        self.node_frame.append(frame)
        self.node_ground.append(ground)
        self.node_yaw.append(float(yaw))
        self.node_effectors.append(effectors)
        self.node_edge.append(edge)
        self.node_frames.append(frames)
        self.node_cost.append(cost)
        self.node_anchor.append(anchor)
        self.expanded.append(False)
        return len(self.node_frame) - 1


@dataclass
class PairResult:
    """The motion between two consecutive keys.

    Attributes:
        positions: ``(frames, 21, 3)`` metres, first frame at the first key, last at the second (before retiming).
        found: always True (a pair without a path raises :class:`NoConnectionError`).
        figures: JSON-ready iterations, nodes, connections, frames, duration and cost.
    """

    positions: np.ndarray
    figures: dict


@dataclass
class KeyframeResult:
    """A motion through all keys.

    Attributes:
        positions: ``(frames, 21, 3)`` metres, the cleaned result (keys exact at ``key_frames``).
        intermediate: the same frames before cleaning (joined paths, retimed).
        key_frames: frame of each key.  pairs: :class:`PairResult` figures per key pair.
        settings, timings: JSON-ready.
    """

    positions: np.ndarray
    intermediate: np.ndarray
    key_frames: list[int]
    pairs: list[dict]
    settings: dict
    timings: dict


def _smoothstep(n: int) -> np.ndarray:
    x = (np.arange(n) + 1.0) / (n + 1.0)
    return x * x * (3.0 - 2.0 * x)


class DynamicMotionGraph:
    """Keyframe motion synthesis on ``database`` (module docstring).

    Args:
        database: the motion database.  k: nearest frames per expanded node.  b: nodes expanded per tree per
        iteration.  max_iterations: iterations before a pair fails.  voxel_m: spatial hash voxel (thesis 10 cm).
        min_segment_frames, max_segment_s: segment length bounds.  max_turn_deg, max_pose_m, max_velocity_m_s:
        connection tests.  blend_frames: frames blended at a connection.  duration_weight: price of a frame of
        timing error in median frames of motion (0: the thesis' cost alone).  turn_radius_m: turning radius
        (metres) of D_node's walk length (0: eq. 4.12 with the facing term; module docstring, step 2).
        facing_first_iterations: with ``turn_radius_m > 0``, iterations of eq. 4.12's search tried first; the
        turn-aware search runs only when its trees do not meet (0: the turn-aware search alone).
        retime: resample each pair to its keys' times.  clean: texture the intermediate result with the keys
        pinned.  index: an E15 :class:`FrameIndex` of ``database`` (built, cached, when None).  texturer: the cleaning
        :class:`MotionTexturer` (built in texture mode when None and ``clean``).
    """

    def __init__(self, database: MotionDatabase, k: int = _G.k, b: int = _G.b, max_iterations: int = _G.max_iterations,
                 voxel_m: float = _G.voxel_m, min_segment_frames: int = _G.min_segment_frames,
                 max_segment_s: float = _G.max_segment_s, max_turn_deg: float = _G.max_turn_deg,
                 max_pose_m: float = _G.max_pose_m, max_velocity_m_s: float = _G.max_velocity_m_s,
                 blend_frames: int = _G.blend_frames, duration_weight: float = _G.duration_weight,
                 facing_weight_m: float = _G.facing_weight_m, turn_radius_m: float = _G.turn_radius_m,
                 facing_first_iterations: int = _G.facing_first_iterations, key_weight: float = 10.0,
                 extra_iterations: int = 1,
                 retime: bool = _G.retime, clean: bool = _G.clean,
                 index: FrameIndex | None = None, texturer: MotionTexturer | None = None):
        for key, value, low in (("k", k, 1), ("b", b, 1), ("max_iterations", max_iterations, 1),
                                ("facing_first_iterations", facing_first_iterations, 0),
                                ("min_segment_frames", min_segment_frames, 1), ("blend_frames", blend_frames, 0)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
                raise KeyframeError(f"{key}={value} must be a whole number ≥ {low}")
        for key, value in (("voxel_m", voxel_m), ("max_segment_s", max_segment_s), ("max_turn_deg", max_turn_deg),
                           ("max_pose_m", max_pose_m), ("max_velocity_m_s", max_velocity_m_s)):
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
                raise KeyframeError(f"{key}={value} must be a positive number")
        if isinstance(extra_iterations, bool) or not isinstance(extra_iterations, (int, np.integer)) \
                or extra_iterations < 0:
            raise KeyframeError(f"extra_iterations={extra_iterations} must be a whole number ≥ 0")
        for key, value in (("duration_weight", duration_weight), ("facing_weight_m", facing_weight_m),
                           ("key_weight", key_weight), ("turn_radius_m", turn_radius_m)):
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value >= 0):
                raise KeyframeError(f"{key}={value} must be a number ≥ 0")
        if database.num_frames < 2:
            raise KeyframeError(f"database {database.name!r} holds {database.num_frames} frame(s)")
        self.database, self.fps = database, float(database.fps)
        self.k, self.b, self.max_iterations = int(min(k, database.num_frames)), int(b), int(max_iterations)
        self.voxel_m, self.min_segment_frames = float(voxel_m), int(min_segment_frames)
        self.max_segment_frames = max(self.min_segment_frames, int(round(max_segment_s * self.fps)))
        self.max_turn = np.deg2rad(float(max_turn_deg))
        self.max_pose_m, self.max_velocity_m_s = float(max_pose_m), float(max_velocity_m_s)
        self.blend_frames, self.duration_weight = int(blend_frames), float(duration_weight)
        self.facing_weight_m, self.key_weight = float(facing_weight_m), float(key_weight)
        self.turn_radius_m, self.facing_first_iterations = float(turn_radius_m), int(facing_first_iterations)
        self.extra_iterations = int(extra_iterations)
        self.retime, self.clean = bool(retime), bool(clean)
        self._prepare_database()
        self.index = index if index is not None else FrameIndex.build(database, "E15")
        if self.index.feature_set != "E15" or self.index.database is not database:
            raise KeyframeError(f"index: an E15 index of this database is needed, got {self.index.feature_set}")
        self.texturer = texturer if texturer is not None or not clean else MotionTexturer(database, "texture")

    # -- the database's per-frame facts ---------------------------------------------------------------------

    def _prepare_database(self) -> None:
        db = self.database
        n = db.num_frames
        self.ground = np.zeros((n, 3))
        self.yaw = np.zeros(n)
        self.local_effectors = np.zeros((n, len(EFFECTORS), 3))
        self.local_root_velocity = np.zeros((n, 3))
        self.speed = np.zeros(n)  # Σ_J |v_J| · Δt: metres moved by all joints from the frame before
        change = np.zeros(n, dtype=bool)
        for t in range(db.num_takes):
            a, z = int(db.take_start[t]), int(db.take_start[t + 1])
            p = np.asarray(db.positions[a:z], dtype=np.float64)
            ground, yaw = placements(p, self.fps)
            self.ground[a:z], self.yaw[a:z] = ground, yaw
            local = rotate_yaw(p - ground[:, None], -yaw[:, None])
            self.local_effectors[a:z] = local[:, EFFECTORS]
            if len(p) >= 2:
                step = np.linalg.norm(np.diff(p, axis=0), axis=-1).sum(axis=-1)
                self.speed[a + 1:z] = step
                self.speed[a] = step[0]
                velocity = np.gradient(p[:, HIPS], axis=0) * self.fps
                self.local_root_velocity[a:z] = rotate_yaw(velocity, -yaw)
                contact = foot_contacts(p, self.fps)
                change[a + 1:z] = (contact[1:] != contact[:-1]).any(axis=-1)
        self.change_frames = np.flatnonzero(change)
        self.median_frame_cost = float(np.median(self.speed))

    def _segment(self, n: int, forward: bool) -> np.ndarray | None:
        """Database frames of the segment after (``forward``) or before database frame ``n``, in time order."""
        take = int(self.database.take_id[n])
        a, z = int(self.database.take_start[take]), int(self.database.take_start[take + 1])
        if forward:
            if n + 1 >= z:
                return None
            i = np.searchsorted(self.change_frames, n + self.min_segment_frames)
            stop = int(self.change_frames[i]) if i < len(self.change_frames) else z - 1
            stop = min(stop, n + self.max_segment_frames, z - 1)
            return np.arange(n + 1, stop + 1)
        if n - 1 < a:
            return None
        i = np.searchsorted(self.change_frames, n - self.min_segment_frames, side="right") - 1
        start = int(self.change_frames[i]) if i >= 0 else a
        start = max(start, n - self.max_segment_frames, a)
        return np.arange(start, n)

    def _neighbours(self, features: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Up to ``k`` database frames per query row, near-duplicates (same take, closer than
        ``min_segment_frames``) suppressed: ``(queries, ≤k)`` lists of frames and distances."""
        wide = min(self.database.num_frames, 4 * self.k)
        distances, frames = self.index.query(np.atleast_2d(features), wide)
        out_f, out_d = [], []
        for dist, idx in zip(np.atleast_2d(distances), np.atleast_2d(frames)):
            kept: list[int] = []
            kept_d: list[float] = []
            for d, f in zip(dist, idx):
                if f < 0:
                    continue
                take = self.database.take_id[f]
                if any(take == self.database.take_id[g] and abs(int(f) - g) < self.min_segment_frames for g in kept):
                    continue
                kept.append(int(f))
                kept_d.append(float(d))
                if len(kept) == self.k:
                    break
            out_f.append(np.array(kept, dtype=np.int64))
            out_d.append(np.array(kept_d))
        return out_f, out_d

    # -- growing the trees ----------------------------------------------------------------------------------

    def _root(self, key: Keyframe, forward: bool, turn_radius_m: float) -> _Tree:
        tree = _Tree(forward, turn_radius_m)
        ground, yaw = placements(key.pose[None], self.fps)
        tree.add_node(-1, ground[0], float(yaw[0]), np.asarray(key.pose)[EFFECTORS], -1, 0, 0.0)
        return tree

    def _expand(self, tree: _Tree, nodes: Sequence[int], key: Keyframe) -> list[int]:
        """Expand ``nodes`` of ``tree``; returns the new edges."""
        queries = np.stack([self.index.features_of(np.asarray(key.pose)[None])[0] if tree.node_frame[v] < 0
                            else self.index.features[tree.node_frame[v]] for v in nodes])
        neighbour_lists, _ = self._neighbours(queries)
        new_edges = []
        for v, neighbours in zip(nodes, neighbour_lists):
            tree.expanded[v] = True
            root = tree.node_frame[v] < 0
            for n in neighbours:
                frames = self._segment(int(n), tree.forward)
                if frames is None:
                    continue
                if root:  # the neighbour itself stands at the key
                    frames = np.concatenate([[n], frames]) if tree.forward else np.concatenate([frames, [n]])
                turn = float(tree.node_yaw[v] - self.yaw[n])
                shift = tree.node_ground[v] - rotate_yaw(self.ground[n], turn)
                edge = len(tree.edge_frames)
                tree.edge_frames.append(frames)
                tree.edge_turn.append(turn)
                tree.edge_shift.append(shift)
                tree.edge_parent.append(v)
                end = int(frames[-1] if tree.forward else frames[0])
                world_end = rotate_yaw(np.asarray(self.database.positions[end], np.float64), turn) + shift
                cost = float(self.speed[frames].sum())
                anchor = tree.node_anchor[v]
                if root:
                    placed = rotate_yaw(np.asarray(self.database.positions[n], np.float64), turn) + shift
                    anchor = float(np.linalg.norm(placed - key.pose, axis=-1).sum())
                tree.edge_child.append(tree.add_node(
                    end, world_end[HIPS] * np.array([1.0, 0.0, 1.0]), self.yaw[end] + turn, world_end[EFFECTORS], edge,
                    tree.node_frames[v] + len(frames), tree.node_cost[v] + cost, anchor))
                new_edges.append(edge)
        return new_edges

    def _edge_world(self, tree: _Tree, edge: int, frames: np.ndarray | None = None) -> np.ndarray:
        """World positions ``(m, 21, 3)`` of an edge's frames (or of other database ``frames`` placed like it)."""
        frames = tree.edge_frames[edge] if frames is None else frames
        return rotate_yaw(np.asarray(self.database.positions[frames], np.float64), tree.edge_turn[edge]) \
            + tree.edge_shift[edge]

    def _pair_distance(self, a: _Tree, rows: np.ndarray, b: _Tree, cols: np.ndarray) -> np.ndarray:
        """D_node terms ``(len(rows), len(cols))`` between nodes ``rows`` of ``a`` and ``cols`` of ``b``.

        The trees' ``turn_radius_m`` = 0: eq. 4.13 (hands, feet and head, world, summed, metres) plus
        ``facing_weight_m`` × the facing difference (radians). ``turn_radius_m > 0``: the same joints in the body
        frame (the pose alone) plus their number × the length of the shortest forward walk of that turning radius
        from the O node's placement to the I node's (:func:`~stylemotion.reconstruct.turning.dubins_length`): a node
        turned against the way to the other tree is far, so the trees grow along a loop rather than meeting face to
        face.
        """
        ea, eb = np.stack(a.node_effectors)[rows], np.stack(b.node_effectors)[cols]
        ya, yb = np.asarray(a.node_yaw)[rows], np.asarray(b.node_yaw)[cols]
        radius = a.turn_radius_m
        if radius <= 0:
            d = np.linalg.norm(ea[:, None] - eb[None], axis=-1).sum(axis=-1)
            return d + self.facing_weight_m * np.abs(wrap_angle(ya[:, None] - yb[None]))
        ga, gb = np.stack(a.node_ground)[rows], np.stack(b.node_ground)[cols]
        la = rotate_yaw(ea - ga[:, None], -ya[:, None])
        lb = rotate_yaw(eb - gb[:, None], -yb[:, None])
        pose = np.linalg.norm(la[:, None] - lb[None], axis=-1).sum(axis=-1)
        xa, xb = ga[:, [0, 2]], gb[:, [0, 2]]
        if a.forward:
            walk = dubins_length(xa[:, None], ya[:, None], xb[None], yb[None], radius)
        else:
            walk = dubins_length(xb[None], yb[None], xa[:, None], ya[:, None], radius)
        return pose + len(EFFECTORS) * walk

    def _node_distance(self, a: _Tree, b: _Tree) -> np.ndarray:
        """D_node (eq. 4.12) of every node of ``a``: the smallest :meth:`_pair_distance` to a node of ``b``;
        updated incrementally (only pairs with a node added since the last call are computed)."""
        n_a, n_b = len(a.node_frame), len(b.node_frame)
        best = np.full(n_a, np.inf)
        best[:len(a.best)] = a.best
        for rows, cols in ((np.arange(len(a.best), n_a), np.arange(n_b)),
                           (np.arange(len(a.best)), np.arange(a.seen_other, n_b))):
            for start in range(0, len(cols), 256):
                if len(rows):
                    part = self._pair_distance(a, rows, b, cols[start:start + 256])
                    best[rows] = np.minimum(best[rows], part.min(axis=1))
        a.best, a.seen_other = best, n_b
        return best

    def _select(self, tree: _Tree, other: _Tree) -> list[int]:
        distance = self._node_distance(tree, other)
        open_nodes = np.flatnonzero(~np.asarray(tree.expanded))
        if not open_nodes.size:
            return []
        return [int(v) for v in open_nodes[np.argsort(distance[open_nodes], kind="stable")[:self.b]]]

    # -- connections ----------------------------------------------------------------------------------------

    def _frame_table(self, tree: _Tree, edges: Sequence[int]) -> dict[str, np.ndarray]:
        """Per frame of ``edges``: edge, position in it, database frame, world Hips and world yaw."""
        if not edges:
            return {"edge": np.zeros(0, np.int64), "pos": np.zeros(0, np.int64), "frame": np.zeros(0, np.int64),
                    "hips": np.zeros((0, 3)), "yaw": np.zeros(0)}
        edge_ids = np.concatenate([np.full(len(tree.edge_frames[e]), e) for e in edges])
        pos = np.concatenate([np.arange(len(tree.edge_frames[e])) for e in edges])
        frames = np.concatenate([tree.edge_frames[e] for e in edges])
        turn = np.asarray(tree.edge_turn)[edge_ids]
        shift = np.stack(tree.edge_shift)[edge_ids]
        hips = rotate_yaw(np.asarray(self.database.positions[frames, HIPS], np.float64), turn) + shift
        return {"edge": edge_ids, "pos": pos, "frame": frames, "hips": hips, "yaw": self.yaw[frames] + turn}

    def _connections(self, out_table: dict, in_table: dict) -> list[tuple[int, int, int, int]]:
        """``(out edge, position, in edge, position)`` pairs that pass the connection tests (module docstring)."""
        if not len(out_table["edge"]) or not len(in_table["edge"]):
            return []
        voxels: dict[tuple[int, int, int], list[int]] = {}
        for i, cell in enumerate(np.floor(in_table["hips"] / self.voxel_m).astype(np.int64)):
            voxels.setdefault(tuple(cell), []).append(i)
        offsets = [(x, y, z) for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1)]
        pairs_o, pairs_i = [], []
        for o, cell in enumerate(np.floor(out_table["hips"] / self.voxel_m).astype(np.int64)):
            for dx, dy, dz in offsets:
                hit = voxels.get((cell[0] + dx, cell[1] + dy, cell[2] + dz))
                if hit:
                    pairs_o.extend([o] * len(hit))
                    pairs_i.extend(hit)
        if not pairs_o:
            return []
        po, pi = np.asarray(pairs_o), np.asarray(pairs_i)
        fo, fi = out_table["frame"][po], in_table["frame"][pi]
        close = np.linalg.norm(out_table["hips"][po] - in_table["hips"][pi], axis=-1) <= self.voxel_m
        close &= np.abs(wrap_angle(out_table["yaw"][po] - in_table["yaw"][pi])) <= self.max_turn
        pose_gap = np.linalg.norm(self.local_effectors[fo] - self.local_effectors[fi], axis=-1).mean(-1)
        close &= pose_gap <= self.max_pose_m
        close &= np.linalg.norm(self.local_root_velocity[fo] - self.local_root_velocity[fi],
                                axis=-1) <= self.max_velocity_m_s
        po, pi = po[close], pi[close]
        # one connection per pair of edges: the closest (Hips gap in voxels + pose gap in max_pose_m)
        gap = (np.linalg.norm(out_table["hips"][po] - in_table["hips"][pi], axis=-1) / self.voxel_m
               + pose_gap[close] / self.max_pose_m)
        eo, ei = out_table["edge"][po], in_table["edge"][pi]
        order = np.lexsort((gap, ei, eo))
        first = np.ones(len(order), dtype=bool)
        first[1:] = (eo[order][1:] != eo[order][:-1]) | (ei[order][1:] != ei[order][:-1])
        keep = order[first]
        return [(int(eo[j]), int(out_table["pos"][po[j]]), int(ei[j]), int(in_table["pos"][pi[j]])) for j in keep]

    # -- paths ----------------------------------------------------------------------------------------------

    @staticmethod
    def _chain(tree: _Tree, edge: int) -> list[int]:
        """Edges from the root to ``edge`` (O: in time order; I: from ``edge`` back to the key, in time order)."""
        chain = []
        while edge >= 0:
            chain.append(edge)
            edge = tree.node_edge[tree.edge_parent[edge]]
        return chain[::-1] if tree.forward else chain

    def _path_figures(self, out_tree: _Tree, in_tree: _Tree, conn: tuple[int, int, int, int],
                      target_frames: int) -> tuple[float, int, float]:
        """(C_edge metres, frames key to key, score) of a connection's path."""
        eo, a, ei, c = conn
        parent_o, parent_i = out_tree.edge_parent[eo], in_tree.edge_parent[ei]
        frames_o, frames_i = out_tree.edge_frames[eo][:a + 1], in_tree.edge_frames[ei][c:]
        cost = (out_tree.node_cost[parent_o] + in_tree.node_cost[parent_i] + float(self.speed[frames_o].sum())
                + float(self.speed[frames_i].sum()))
        frames = out_tree.node_frames[parent_o] + len(frames_o) + len(frames_i) - 1 + in_tree.node_frames[parent_i]
        score = (cost + self.duration_weight * abs(frames - target_frames) * self.median_frame_cost
                 + self.key_weight * (out_tree.node_anchor[out_tree.edge_child[eo]]
                                      + in_tree.node_anchor[in_tree.edge_child[ei]]))
        return cost, frames, score

    def _in_take(self, frames: np.ndarray, like: int) -> np.ndarray:
        """The ``frames`` that lie in the take of database frame ``like``."""
        frames = frames[(frames >= 0) & (frames < self.database.num_frames)]
        return frames[self.database.take_id[frames] == self.database.take_id[like]]

    def _assemble(self, out_tree: _Tree, in_tree: _Tree, conn: tuple[int, int, int, int]) -> np.ndarray:
        """The path of a connection as positions ``(frames, 21, 3)``, key to key, blended at the connection."""
        eo, a, ei, c = conn
        out_parts = [self._edge_world(out_tree, e) for e in self._chain(out_tree, eo)]
        out_parts[-1] = out_parts[-1][:a + 1]
        in_parts = [self._edge_world(in_tree, e) for e in self._chain(in_tree, ei)]
        in_parts[0] = in_parts[0][c:]
        out_path, in_path = np.concatenate(out_parts), np.concatenate(in_parts)
        fo, fi = int(out_tree.edge_frames[eo][a]), int(in_tree.edge_frames[ei][c])
        half = self.blend_frames // 2
        after = self._in_take(fo + 1 + np.arange(half), fo)
        before = self._in_take(fi - half + np.arange(half), fi)
        h = min(len(after), len(before), len(out_path) - 2, len(in_path) - 2)
        if h <= 0:
            return np.concatenate([out_path, in_path[1:]])
        # windows of 2h + 1 frames with the connection frame (a ≡ c) in the middle
        out_window = np.concatenate([out_path[len(out_path) - h - 1:], self._edge_world(out_tree, eo, after[:h])])
        in_window = np.concatenate([self._edge_world(in_tree, ei, before[len(before) - h:]), in_path[:h + 1]])
        return np.concatenate([out_path[:len(out_path) - h - 1], self._blend(out_window, in_window),
                               in_path[h + 1:]])

    def _blend(self, first: np.ndarray, second: np.ndarray) -> np.ndarray:
        """Blend ``(m, 21, 3)`` windows from ``first`` to ``second`` with smoothstep weights: ground point, yaw
        and body-frame pose separately (so a turn between them is interpolated, not cut across)."""
        g1, y1 = placements(first, self.fps)
        g2, y2 = placements(second, self.fps)
        local1 = rotate_yaw(first - g1[:, None], -y1[:, None])
        local2 = rotate_yaw(second - g2[:, None], -y2[:, None])
        w = _smoothstep(len(first))[:, None]
        ground = (1 - w) * g1 + w * g2
        yaw = y1 + w[:, 0] * wrap_angle(y2 - y1)
        local = (1 - w[:, :, None]) * local1 + w[:, :, None] * local2
        return rotate_yaw(local, yaw[:, None]) + ground[:, None]

    def connect(self, first: Keyframe, second: Keyframe) -> PairResult:
        """The motion from ``first`` to ``second`` (module docstring, steps 2–5; NoConnectionError if none).

        With ``turn_radius_m > 0`` and ``facing_first_iterations > 0``, eq. 4.12's search (with the facing term)
        runs first for that many iterations; only when its trees do not meet does the turn-aware search start afresh
        (``max_iterations``). ``figures["search"]`` says which search joined the pair ("facing" or "turn-aware")."""
        started = time.perf_counter()
        if self.turn_radius_m > 0 and self.facing_first_iterations > 0:
            try:
                pair = self._search(first, second, 0.0, self.facing_first_iterations, started)
                pair.figures["search"] = "facing"
                return pair
            except NoConnectionError as error:
                log.info(f"  eq. 4.12's search did not join ({error}); the turn-aware search starts")
        pair = self._search(first, second, self.turn_radius_m, self.max_iterations, started)
        pair.figures["search"] = "turn-aware" if self.turn_radius_m > 0 else "facing"
        return pair

    def _search(self, first: Keyframe, second: Keyframe, turn_radius_m: float, max_iterations: int,
                started: float) -> PairResult:
        """One bidirectional search with D_node of ``turn_radius_m`` for at most ``max_iterations``; ``started``:
        the pair's start (``perf_counter``), so ``figures["seconds"]`` counts an earlier search that failed."""
        out_tree, in_tree = self._root(first, True, turn_radius_m), self._root(second, False, turn_radius_m)
        out_edges: list[int] = []
        in_edges: list[int] = []
        target_frames = int(round((second.time_s - first.time_s) * self.fps)) + 1
        connections: list[tuple[int, int, int, int]] = []
        iteration, met = 0, None
        for iteration in range(1, max_iterations + 1):
            new_out = self._expand(out_tree, self._select(out_tree, in_tree), first)
            new_in = self._expand(in_tree, self._select(in_tree, out_tree), second)
            out_edges += new_out
            in_edges += new_in
            out_all, in_all = self._frame_table(out_tree, out_edges), self._frame_table(in_tree, in_edges)
            connections += (self._connections(self._frame_table(out_tree, new_out), in_all)
                            + self._connections(out_all, self._frame_table(in_tree, new_in)))
            log.info(f"  iteration {iteration}: {len(out_tree.node_frame)} + {len(in_tree.node_frame)} nodes, "
                         f"{len(connections)} connection(s)")
            if connections and met is None:
                met = iteration
            if met is not None and iteration >= met + self.extra_iterations:
                break
        if not connections:
            gap = float(self._node_distance(out_tree, in_tree).min())
            raise NoConnectionError(
                f"keys at {first.time_s:g} s → {second.time_s:g} s: the trees did not meet in {max_iterations} "
                f"iterations ({len(out_tree.node_frame)} + {len(in_tree.node_frame)} nodes; the closest nodes are "
                f"{gap:.2f} m apart, hands, feet and head summed): add a key between them, raise max_iterations or "
                f"use a database that holds such motion")
        connections = sorted(set(connections))
        figures = [self._path_figures(out_tree, in_tree, conn, target_frames) for conn in connections]
        best = int(np.argmin([f[2] for f in figures]))
        positions = self._assemble(out_tree, in_tree, connections[best])
        cost, _, _ = figures[best]
        return PairResult(positions, {
            "from_s": first.time_s, "to_s": second.time_s, "iterations": iteration, "met_at_iteration": met,
            "nodes": [len(out_tree.node_frame), len(in_tree.node_frame)], "connections": len(connections),
            "frames": len(positions), "duration_s": round((len(positions) - 1) / self.fps, 4),
            "duration_error_s": round((len(positions) - target_frames) / self.fps, 4),
            "cost_m": round(cost, 3), "seconds": round(time.perf_counter() - started, 4)})

    # -- the whole motion -----------------------------------------------------------------------------------

    def settings(self) -> dict:
        return {"k": self.k, "b": self.b, "max_iterations": self.max_iterations, "voxel_m": self.voxel_m,
                "min_segment_frames": self.min_segment_frames, "max_segment_frames": self.max_segment_frames,
                "max_turn_deg": round(float(np.rad2deg(self.max_turn)), 3), "max_pose_m": self.max_pose_m,
                "max_velocity_m_s": self.max_velocity_m_s, "blend_frames": self.blend_frames,
                "duration_weight": self.duration_weight, "facing_weight_m": self.facing_weight_m,
                "turn_radius_m": self.turn_radius_m, "facing_first_iterations": self.facing_first_iterations,
                "key_weight": self.key_weight, "extra_iterations": self.extra_iterations,
                "retime": self.retime, "clean": self.clean,
                "database": {"name": self.database.name, "takes": self.database.num_takes,
                             "frames": self.database.num_frames, "fps": self.fps}}

    def _check_far(self, keys: Sequence[Keyframe]) -> None:
        features = np.stack([self.index.features_of(np.asarray(key.pose, np.float64)[None])[0] for key in keys])
        distances, _ = self.index.query(features, 1)
        for i, d in enumerate(np.ravel(distances)):
            if d > FAR_KEY_M:
                warnings.warn(f"keyframe {i} (t={keys[i].time_s:g} s): the nearest database pose is {d:.2f} m away "
                              f"in E15 (> {FAR_KEY_M} m); its tree starts from poses unlike it", FarKeyframeWarning,
                              stacklevel=3)

    def synthesize(self, keys: Sequence[Keyframe]) -> KeyframeResult:
        """The motion through every key (module docstring); NoConnectionError naming the first pair without one."""
        keys = check_keyframes(keys)
        started = time.perf_counter()
        self._check_far(keys)
        parts, pairs, key_frames = [], [], [0]
        for i in range(len(keys) - 1):
            log.info(f"keys {i} → {i + 1} ({keys[i].time_s:g} s → {keys[i + 1].time_s:g} s)")
            pair = self.connect(keys[i], keys[i + 1])
            positions = pair.positions
            if self.retime:
                positions = resample(positions, int(round((keys[i + 1].time_s - keys[i].time_s) * self.fps)) + 1)
            parts.append(positions if i == 0 else positions[1:])
            key_frames.append(key_frames[-1] + len(positions) - 1)
            pairs.append(pair.figures)
        intermediate = np.concatenate(parts)
        searched = time.perf_counter()
        key_errors = [float(np.linalg.norm(intermediate[f] - np.asarray(k.pose), axis=-1).mean() * 100.0)
                      for f, k in zip(key_frames, keys)]
        pinned = intermediate.copy()
        for f, k in zip(key_frames, keys):
            pinned[f] = np.asarray(k.pose, np.float64)
        positions = pinned
        if self.clean:
            log.info(f"cleaning {len(pinned)} frames by motion texturing (keys pinned)")
            positions = self.texturer.apply(pinned, pinned=key_frames).positions
        done = time.perf_counter()
        for figures, error in zip(pairs, key_errors[1:]):
            figures["intermediate_key_error_cm"] = round(error, 3)
        settings = self.settings()
        settings["intermediate_first_key_error_cm"] = round(key_errors[0], 3)
        return KeyframeResult(positions, intermediate, key_frames, pairs, settings,
                              {"search": round(searched - started, 4), "clean": round(done - searched, 4),
                               "total": round(done - started, 4)})


def resample(positions: np.ndarray, frames: int) -> np.ndarray:
    """``(m, 21, 3)`` positions linearly resampled to ``frames`` frames over the same time span."""
    positions = np.asarray(positions, dtype=np.float64)
    if frames == len(positions):
        return positions
    if frames < 2 or len(positions) < 2:
        raise KeyframeError(f"cannot resample {len(positions)} frame(s) to {frames}")
    t = np.linspace(0.0, len(positions) - 1.0, frames)
    low = np.minimum(np.floor(t).astype(np.int64), len(positions) - 2)
    w = (t - low)[:, None, None]
    return (1 - w) * positions[low] + w * positions[low + 1]
