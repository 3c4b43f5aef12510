"""Frame distance measures the thesis compares its feature sets against (Krüger, *Synthesizing Human Motions*, §2.3.1).

Every measure compares two frames (or two windows of frames) and is vectorized over pairs; the suite
``distances`` (benchmarks/distances.md) ranks them against each other and against the feature sets of
:mod:`stylemotion.search.features` as the thesis' Figs. 2.3–2.7 do.

* ``D_quat``: joint rotations as unit quaternions; per joint the geodesic angle ``2·acos|⟨q, q'⟩|`` (so
  ``q`` and ``−q`` are the same rotation), the distance the root of the summed squared angles, radians.
* ``D_euler``: the same rotations as Euler angles in the BVH channel order the project exports
  (:data:`stylemotion.io.export.ROTATION_ORDER`); Euclidean distance of the angle differences, each wrapped to
  ``[−π, π)``, radians.
* ``D_lee``, ``D_wb``: weighted body-part distances ``sqrt(Σ_j w_j θ_j²)`` on the quaternion angles — Lee et
  al. (2002)'s 0/1 weights (shoulders, elbows, hips, knees, pelvis, spine) and Wang & Bodenheimer's joints
  (hips, knees, shoulders, elbows), as the thesis lists them (:data:`BODY_PART_WEIGHTS`).
* ``D_pc<n>``: Kovar & Gleicher's point-cloud distance over a window of ``n`` poses: the least summed squared
  distance between the two clouds of global joint positions over every rotation about the vertical and
  translation in the ground plane, in closed form (:func:`point_cloud_distance`), m².
* ``F_pva20``: Arikan et al.'s pose/velocity/acceleration set — the body-frame positions, velocities and
  accelerations of all joints, reduced by a PCA to 20 dimensions (:func:`fit_pva`), Euclidean.

Rotations come from positions through the project's IK (:func:`stylemotion.io.export.positions_to_motion`, the
rotations a BVH export writes): a take holds canonical positions only. The root's rotation enters with its
yaw (the turn about the vertical) taken out (:func:`joint_rotations`), as the thesis normalizes the root.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from stylemotion.search.features import (
    FittedPCA,
    _per_frame_difference,
    _second_difference,
    body_frame_positions,
)
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX, NUM_JOINTS, checked_positions

#: Rotation measures and their joint weights (canonical order); a joint's rotation is the one that turns its
#: bone(s) to its children, so "hip" is ``UpperLeg``, "knee" ``LowerLeg``, "shoulder" ``UpperArm`` (the
#: glenohumeral joint; our ``Shoulder_*`` are the clavicles), "elbow" ``LowerArm``, "pelvis" ``Hips``.
_LEE = ("Hips", "Spine", "Chest", "UpperArm_L", "UpperArm_R", "LowerArm_L", "LowerArm_R",
        "UpperLeg_L", "UpperLeg_R", "LowerLeg_L", "LowerLeg_R")
_WB = ("UpperArm_L", "UpperArm_R", "LowerArm_L", "LowerArm_R", "UpperLeg_L", "UpperLeg_R",
       "LowerLeg_L", "LowerLeg_R")


def _weights(joints: Sequence[str]) -> np.ndarray:
    w = np.zeros(NUM_JOINTS)
    w[[JOINT_INDEX[j] for j in joints]] = 1.0
    return w


#: ``(21,)`` joint weights of the weighted body-part distances. ``wb`` weighs Wang & Bodenheimer's joints
#: equally: the thesis names the joints, not the optimized values.
BODY_PART_WEIGHTS: dict[str, np.ndarray] = {"lee": _weights(_LEE), "wb": _weights(_WB)}
#: Windows of the point-cloud distances, frames at 30 fps (the thesis' D_pc1, D_pc11).
POINT_CLOUD_WINDOWS_30FPS = (1, 11)
#: Components of the pose/velocity/acceleration PCA (Arikan et al.'s F_pca^pva20).
PVA_COMPONENTS = 20


# ---------------------------------------------------------------------------------------------
# Rotations


def joint_rotations(positions: np.ndarray, fps: float) -> np.ndarray:
    """Local joint rotations of a take, from its positions by the project's IK.

    Args:
        positions: ``(frames, 21, 3)`` canonical positions, metres, Y up.
        fps: frames per second.

    Returns:
        ``(frames, 21, 4)`` unit quaternions (x, y, z, w): every joint's rotation relative to its parent; the
        root's (Hips) with its yaw taken out (``R_y(−yaw)·R``, yaw the heading of the root's +Z axis), so that
        turning the whole motion about the vertical leaves every value unchanged.
    """
    from stylemotion.io.export import positions_to_motion

    quats = positions_to_motion(checked_positions(positions), fps).rotations.copy()
    root = Rotation.from_quat(quats[:, 0])
    forward = root.apply([0.0, 0.0, 1.0])
    yaw = np.arctan2(forward[:, 0], forward[:, 2])
    quats[:, 0] = (Rotation.from_rotvec(np.outer(-yaw, [0.0, 1.0, 0.0])) * root).as_quat()
    return quats


def euler_angles(quats: np.ndarray) -> np.ndarray:
    """``(..., 4)`` quaternions (x, y, z, w) → ``(..., 3)`` intrinsic Euler angles in the export's channel
    order (:data:`stylemotion.io.export.ROTATION_ORDER`), radians."""
    from stylemotion.io.export import ROTATION_ORDER

    flat = np.asarray(quats, dtype=np.float64).reshape(-1, 4)
    angles = Rotation.from_quat(flat).as_euler(ROTATION_ORDER.upper())
    return angles.reshape(*np.shape(quats)[:-1], 3)


def quaternion_angles(qa: np.ndarray, qb: np.ndarray) -> np.ndarray:
    """Geodesic angles ``(..., joints)`` between unit quaternions ``(..., joints, 4)`` (broadcast), radians in
    ``[0, π]``; ``q`` and ``−q`` are at angle 0."""
    dot = np.abs(np.sum(np.asarray(qa) * np.asarray(qb), axis=-1))
    return 2.0 * np.arccos(np.clip(dot, 0.0, 1.0))


def quaternion_distance(qa: np.ndarray, qb: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """``D_quat`` (``weights`` None) or a weighted body-part distance: ``sqrt(Σ_j w_j θ_j²)``, radians.

    Args:
        qa, qb: ``(..., joints, 4)`` unit quaternions (x, y, z, w), broadcast against each other.
        weights: ``(joints,)`` non-negative weights (e.g. :data:`BODY_PART_WEIGHTS`), or None for all 1.

    Returns:
        ``(...)`` distances.
    """
    theta2 = quaternion_angles(qa, qb) ** 2
    if weights is not None:
        theta2 = theta2 * np.asarray(weights, dtype=np.float64)
    return np.sqrt(np.sum(theta2, axis=-1))


def euler_distance(ea: np.ndarray, eb: np.ndarray) -> np.ndarray:
    """``D_euler``: Euclidean distance of Euler angles ``(..., joints, 3)`` (broadcast) with each difference
    wrapped to ``[−π, π)``; ``(...)`` radians."""
    diff = np.mod(np.asarray(ea) - np.asarray(eb) + np.pi, 2.0 * np.pi) - np.pi
    return np.sqrt(np.sum(diff ** 2, axis=(-2, -1)))


# ---------------------------------------------------------------------------------------------
# Point clouds


def point_cloud_window(frames_30fps: int, fps: float) -> int:
    """A window of ``frames_30fps`` frames at 30 fps in frames at ``fps`` (odd, ≥ 1, centred on the frame)."""
    half = int(round((frames_30fps - 1) / 2 * fps / 30.0))
    return 2 * half + 1


def point_clouds(positions: np.ndarray, frames: np.ndarray, window: int) -> np.ndarray:
    """The clouds of the windows centred on ``frames`` of one take.

    Args:
        positions: ``(n, 21, 3)`` global positions of one take, metres.
        frames: ``(m,)`` frame indices.
        window: odd number of poses per window; frames past the take's ends clamp to its first/last.

    Returns:
        ``(m, window·21, 3)`` points, metres.
    """
    if window < 1 or window % 2 == 0:
        raise ValueError(f"point-cloud window must be a positive odd number of frames, got {window}")
    half = window // 2
    rows = np.clip(np.asarray(frames)[:, None] + np.arange(-half, half + 1)[None, :], 0, len(positions) - 1)
    return np.asarray(positions, dtype=np.float64)[rows].reshape(len(rows), -1, 3)


def point_cloud_distance(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Kovar & Gleicher's point-cloud distance of every cloud of ``a`` to every cloud of ``b``.

    ``min over θ, x0, z0 of Σ_i |p_i − (R_y(θ) p'_i + (x0, 0, z0))|²`` with equal weights, in closed form:
    after centring both clouds in the ground plane, ``Σ|p|² + Σ|p'|² − 2 Σ y y' − 2·sqrt(c² + s²)`` with
    ``c = Σ (x x' + z z')`` and ``s = Σ (x z' − z x')`` (the best turn of ``p'`` has ``cos θ ∝ c``, ``sin θ ∝ s``).

    Args:
        a: ``(n, P, 3)`` clouds, metres, Y up.  b: ``(m, P, 3)`` clouds with the same points in the same order.

    Returns:
        ``(n, m)`` summed squared distances, m² (≥ 0).
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if a.ndim != 3 or b.ndim != 3 or a.shape[1:] != b.shape[1:] or a.shape[2] != 3:
        raise ValueError(f"point clouds must be (n, P, 3) and (m, P, 3) with the same P, got {a.shape}, {b.shape}")
    return aligned_distance(centred_clouds(a), centred_clouds(b))


def centred_clouds(clouds: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(n, P, 3)`` clouds centred in the ground plane, as ``x, y, z`` ``(n, P)`` each and ``(n,)`` squared norms
    (what :func:`aligned_distance` takes; computed once for a database)."""
    centred = clouds - clouds.mean(axis=1, keepdims=True) * np.array([1.0, 0.0, 1.0])
    x, y, z = (np.ascontiguousarray(centred[..., i]) for i in range(3))
    return x, y, z, np.sum(centred ** 2, axis=(1, 2))


def aligned_distance(a: tuple[np.ndarray, ...], b: tuple[np.ndarray, ...]) -> np.ndarray:
    """The closed form of :func:`point_cloud_distance` on :func:`centred_clouds` ``a`` (n) and ``b`` (m):
    ``(n, m)`` m²."""
    ax, ay, az, sq_a = a
    bx, by, bz, sq_b = b
    c = ax @ bx.T + az @ bz.T
    s = ax @ bz.T - az @ bx.T
    d = sq_a[:, None] + sq_b[None, :] - 2.0 * (ay @ by.T) - 2.0 * np.hypot(c, s)
    return np.maximum(d, 0.0)


# ---------------------------------------------------------------------------------------------
# Pose, velocity, acceleration


def pva_frames(positions: np.ndarray, fps: float) -> np.ndarray:
    """Arikan et al.'s per-frame pose/velocity/acceleration vector of one take: ``(frames, 189)`` — the 21
    body-frame joint positions (m), their velocities (m/s) and accelerations (m/s²), unscaled (the thesis notes
    the set is dominated by the accelerations' variance)."""
    local = body_frame_positions(positions, fps, "3d").reshape(len(positions), 3 * NUM_JOINTS)
    return np.concatenate([local, _per_frame_difference(local) * fps, _second_difference(local) * fps ** 2], axis=1)


def fit_pva(takes: Sequence[np.ndarray], fps: float, n_components: int = PVA_COMPONENTS) -> FittedPCA:
    """A PCA (scikit-learn) of :func:`pva_frames` over every frame of ``takes`` (each ``(frames, 21, 3)``).
    The returned :class:`~stylemotion.search.features.FittedPCA` transforms ``(frames, 189)`` rows."""
    from sklearn.decomposition import PCA

    data = np.concatenate([pva_frames(p, fps) for p in takes])
    if data.shape[0] < n_components:
        raise ValueError(f"a {n_components}-component PCA needs at least {n_components} frames, got {data.shape[0]}")
    pca = PCA(n_components=n_components, random_state=0).fit(data)
    return FittedPCA(pca.mean_.copy(), pca.components_.copy(), pca.explained_variance_.copy(), "3d")


def rotation_joint_names() -> tuple[str, ...]:
    """Joint order of the rotation measures (the canonical order)."""
    return tuple(CANONICAL_JOINTS)


# ---------------------------------------------------------------------------------------------
# Every measure over the frames of a set of takes


def measure_names(feature_sets: Sequence[str]) -> list[str]:
    """The measures of :class:`FrameMeasures`: the §2.3.1 distances, then ``feature_sets``."""
    return ["D_quat", "D_euler", "D_lee", "D_wb", *(f"D_pc{n}" for n in POINT_CLOUD_WINDOWS_30FPS), "F_pva20",
            *feature_sets]


class FrameMeasures:
    """Every measure's per-frame representation of the frames of ``takes`` (concatenated in order).

    Args:
        takes: ``(frames_i, 21, 3)`` canonical positions per take, metres, Y up.
        fps: their frame rate.
        feature_sets: names of :data:`stylemotion.search.features.FEATURE_SETS` (computed by
            :func:`~stylemotion.search.features.compute_features`, the search's own transform).
        fitted: ``{name: FittedPCA}`` for the ``pca*`` sets and ``"F_pva20"`` (fitted on other takes).
    """

    def __init__(self, takes: Sequence[np.ndarray], fps: float, feature_sets: Sequence[str],
                 fitted: dict[str, FittedPCA]):
        from stylemotion.search.features import compute_features

        self.names = measure_names(feature_sets)
        self.take_id = np.concatenate([np.full(len(p), i) for i, p in enumerate(takes)])
        quats = np.concatenate([joint_rotations(p, fps) for p in takes])
        self.quats = quats
        self.euler = euler_angles(quats)
        self.windows = {f"D_pc{n}": point_cloud_window(n, fps) for n in POINT_CLOUD_WINDOWS_30FPS}
        self.clouds = {name: centred_clouds(np.concatenate([point_clouds(p, np.arange(len(p)), w) for p in takes]))
                       for name, w in self.windows.items()}
        self._angles: tuple[bytes, np.ndarray] | None = None
        vectors = {"F_pva20": fitted["F_pva20"].transform(np.concatenate([pva_frames(p, fps) for p in takes]))}
        for name in feature_sets:
            vectors[name] = np.concatenate([compute_features(name, p, fps, fitted.get(name), allow_short=True)
                                            for p in takes]).astype(np.float64)
        self.vectors = vectors
        self.sq_norms = {name: np.sum(v ** 2, axis=1) for name, v in vectors.items()}

    @property
    def num_frames(self) -> int:
        return int(self.take_id.shape[0])

    def distances(self, name: str, rows: np.ndarray, columns: np.ndarray | None = None) -> np.ndarray:
        """``(len(rows), len(columns))`` distances of measure ``name`` from the frames ``rows`` to the frames
        ``columns`` (default every frame): radians for the rotation measures, m² for the point clouds, feature
        units for the sets."""
        cols = np.arange(self.num_frames) if columns is None else np.asarray(columns)
        if name in ("D_quat", "D_lee", "D_wb"):
            theta2 = self._squared_angles(rows, cols)
            return np.sqrt(theta2.sum(-1) if name == "D_quat" else theta2 @ BODY_PART_WEIGHTS[name[2:].lower()])
        if name == "D_euler":
            return euler_distance(self.euler[rows][:, None], self.euler[cols][None])
        if name in self.clouds:
            cloud = self.clouds[name]
            return aligned_distance(tuple(part[rows] for part in cloud), tuple(part[cols] for part in cloud))
        v = self.vectors[name]
        sq = self.sq_norms[name][rows][:, None] + self.sq_norms[name][cols][None] - 2.0 * (v[rows] @ v[cols].T)
        return np.sqrt(np.maximum(sq, 0.0))


    def _squared_angles(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        """``(len(rows), len(cols), 21)`` squared quaternion angles, kept for the last ``rows`` and ``cols`` (the
        three rotation measures share them)."""
        key = np.asarray(rows).tobytes() + b"|" + np.asarray(cols).tobytes()
        if self._angles is None or self._angles[0] != key:
            a, b = self.quats[rows], self.quats[cols]
            dot = np.stack([a[:, j] @ b[:, j].T for j in range(a.shape[1])], axis=-1)
            self._angles = (key, (2.0 * np.arccos(np.clip(np.abs(dot), 0.0, 1.0))) ** 2)
        return self._angles[1]


def spearman_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Spearman's ρ of each row of ``a`` with the same row of ``b`` (``(n, m)`` each; ties share their mean
    rank): ``(n,)``, NaN where a row's ranks are constant."""
    from scipy.stats import rankdata

    ra = rankdata(a, axis=1)
    rb = rankdata(b, axis=1)
    ra -= ra.mean(axis=1, keepdims=True)
    rb -= rb.mean(axis=1, keepdims=True)
    denom = np.sqrt(np.sum(ra ** 2, axis=1) * np.sum(rb ** 2, axis=1))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(denom > 0, np.sum(ra * rb, axis=1) / np.where(denom > 0, denom, 1.0), np.nan)


def neighbour_correlations(dist: dict[str, np.ndarray], excluded: np.ndarray, ks: Sequence[int],
                           rows: Sequence[str] | None = None) -> dict[str, dict[int, dict[str, np.ndarray]]]:
    """The thesis' asymmetric rank correlations: per query, its ``k`` nearest frames under measure A (a row),
    and Spearman's ρ between those frames' distances under A and under every measure B.

    Args:
        dist: measure → ``(queries, frames)`` distances over the same pairs.
        excluded: ``(queries, frames)`` True where a frame may not be a neighbour (e.g. the query's own take).
        ks: numbers of nearest neighbours.
        rows: the measures A (default all).

    Returns:
        ``{A: {k: {B: (queries,) ρ}}}``.
    """
    out: dict[str, dict[int, dict[str, np.ndarray]]] = {}
    for a in rows or list(dist):
        masked = np.where(excluded, np.inf, dist[a])
        top = min(max(ks), masked.shape[1])
        part = np.argpartition(masked, top - 1, axis=1)[:, :top] if top < masked.shape[1] else \
            np.tile(np.arange(masked.shape[1]), (masked.shape[0], 1))
        order = np.take_along_axis(part, np.argsort(np.take_along_axis(masked, part, 1), axis=1, kind="stable"), 1)
        out[a] = {}
        for k in ks:
            near = order[:, :k]
            out[a][k] = {b: spearman_rows(np.take_along_axis(dist[a], near, 1), np.take_along_axis(d, near, 1))
                         for b, d in dist.items()}
    return out


def nearest_label_precision(dist: np.ndarray, excluded: np.ndarray, labels: np.ndarray, query_labels: np.ndarray,
                            n: int = 10) -> np.ndarray:
    """Share of each query's ``n`` nearest frames (``dist`` ``(queries, frames)``, ``excluded`` frames left out)
    whose label equals the query's (:func:`stylemotion.search.evaluation.precision_at` per query): ``(queries,)``."""
    from stylemotion.search.evaluation import precision_at

    masked = np.where(excluded, np.inf, dist)
    near = np.argpartition(masked, n, axis=1)[:, :n]
    return np.array([precision_at(labels[row], wanted, n) for row, wanted in zip(near, query_labels, strict=True)])


# ---------------------------------------------------------------------------------------------
# Motion segments: DTW-induced distances (the thesis' Fig. 2.4)


def dtw_costs(cost: np.ndarray) -> np.ndarray:
    """Global DTW of many pairs of sequences at once: ``cost`` ``(pairs, m, n)`` frame distances → ``(pairs,)``
    accumulated costs of the cheapest path from ``(0, 0)`` to ``(m−1, n−1)`` with steps (1, 0), (0, 1), (1, 1)
    (the thesis' "accumulated pose distances along the warping path")."""
    cost = np.asarray(cost, dtype=np.float64)
    if cost.ndim != 3 or 0 in cost.shape[1:]:
        raise ValueError(f"cost must be (pairs, m, n) with m, n ≥ 1, got {cost.shape}")
    cells = np.ascontiguousarray(cost.transpose(1, 2, 0))  # (m, n, pairs): each cell's pairs side by side
    row = np.cumsum(cells[0], axis=0)
    for i in range(1, cells.shape[0]):
        new = np.empty_like(row)
        new[0] = row[0] + cells[i, 0]
        best_prev = np.minimum(row[1:], row[:-1])  # from (i−1, j) and (i−1, j−1)
        for j in range(1, cells.shape[1]):
            new[j] = cells[i, j] + np.minimum(best_prev[j - 1], new[j - 1])
        row = new
    return row[-1]


def clip_distances(measures: FrameMeasures, clip_frames: int, stride: int = 1,
                   chunk: int = 100) -> dict[str, np.ndarray]:
    """DTW distances between the clips of ``measures`` under every measure.

    Args:
        measures: built over clips of ``clip_frames`` frames each (every "take" one clip).
        clip_frames: frames per clip.
        stride: align every ``stride``-th frame of each clip (the measures themselves see every frame: windows
            and velocities keep their full-rate meaning).
        chunk: rows of frame distances computed at once (memory).

    Returns:
        ``{measure: (clips, clips)}`` accumulated DTW costs in the measure's units.
    """
    n = measures.num_frames
    if n % clip_frames or np.any(np.bincount(measures.take_id) != clip_frames):
        raise ValueError(f"every clip must hold {clip_frames} frames")
    clips = n // clip_frames
    kept = np.arange(0, clip_frames, stride)
    frames = (np.arange(clips)[:, None] * clip_frames + kept[None, :]).ravel()
    m = len(kept)
    out = {}
    for name in measures.names:
        frame = np.concatenate([measures.distances(name, frames[lo:lo + chunk], frames)
                                for lo in range(0, len(frames), chunk)])
        blocks = frame.reshape(clips, m, clips, m).transpose(0, 2, 1, 3)
        out[name] = dtw_costs(blocks.reshape(clips * clips, m, m)).reshape(clips, clips)
    return out
