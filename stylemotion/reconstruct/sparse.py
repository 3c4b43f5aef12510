"""Full poses from a few markers (Krüger §2.5.2, after Chai & Hodgins 2005).

Per frame ``t`` of the marker tracks:

1. **Marker frame.** The body frame is built from the markers alone (the pelvis frame of the search's
   ``"3d"`` normalization needs the hips and chest, which six markers do not give): origin = the root
   marker's ground point (``Hips``; the markers' mean when there is none), y kept as height; yaw from the
   left−right vector summed over the left/right marker pairs (``Hand_L − Hand_R + Foot_L − Foot_R``),
   projected on the ground (:func:`marker_frames`). It is a function of the markers of one frame, computed
   the same way for the database's frames, so equal marker configurations give equal features. Without
   a left/right pair only the translation is taken out.
2. **k-NN.** Features in the chosen feature set, in the marker frame: for a set whose joints are all
   markers (``E15`` with the six default markers; ``E15x3``/``E15x5`` windows of them) the markers'
   coordinates — a :class:`~stylemotion.search.FrameIndex` over the database's marker-only features.
   For a set that needs joints the markers do not give (``E30``, ``E39``, ``pca*``) the query is the
   previously synthesized pose with the current markers put in (the thesis' "search around newly
   synthesized poses"; the first frame starts from the database's mean pose), iterated ``iterations``
   times per frame.
3. **Local linear model.** PCA of the k neighbours' full poses (63 marker-frame coordinates), keeping
   the components that explain ``variance`` of their spread. With ``weighted`` (default) each neighbour
   counts ``1 / (d + marker_sd)²`` (d its feature distance) in the mean and covariance — our addition: it
   makes a pose that is in the database come back exactly (the plain mean of k neighbours pulls it
   towards their average). ``k`` (default 128) was chosen on Bandai val takes (suite ``reconstruct``).
4. **Pose.** The coefficients ``c`` minimizing, with pose ``x = μ + Uᵀc`` in the marker frame,
   ``‖S x − m‖² / marker_sd² + prior_weight · Σ c_i² / σ_i² + ‖x − x_prev‖² / smooth_sd²``
   (S picks the markers, m their coordinates, σ_i² the PCA variances, x_prev the previous result in this
   frame's marker frame): one linear least-squares solve, then back to world with the marker frame.

Skin markers (:mod:`stylemotion.reconstruct.marker_set`): the markers are a set's virtual markers, put on
the database's motions as on the query, so features compare like with like; the local model of step 3 is the PCA
of the neighbours' poses *and* their markers (63 + 3m coordinates), the markers' coordinates are what step 4
fits. The marker frame of step 1 is built from the markers' segments' names (a wrist marker counts as Hand_L).

Subject and bones (docs/reconstruct.md): ``bones`` (20 bone lengths, metres: a calibration's skeleton, or the
database's scaled by :func:`subject_scale`) puts every database take on those bones first
(:func:`stylemotion.bones.retarget_positions`); ``hold_bones`` sets every output frame's bones to those lengths
(else to the result's own median lengths over its frames), the wrists and ankles kept where the model put them
(:func:`stylemotion.reconstruct.subject.hold_bone_lengths`: knees and elbows by two-bone IK).

Simplified against Chai & Hodgins: no per-frame optimization of joint angles (the pose is a point of
the neighbours' linear model in joint positions); bone lengths are held by placing the bones afterwards.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from stylemotion.reconstruct.marker_set import MarkerSet, joint_marker_set, virtual_markers
from stylemotion.reconstruct.markers import MarkerInputError, MarkerTracks, check_marker_names
from stylemotion.reconstruct.settings import JOINT_CENTRE_PRIOR_WEIGHT, SKIN_PRIOR_WEIGHT
from stylemotion.reconstruct.settings import ReconstructSettings as _C
from stylemotion.reconstruct.settings import SparseModelSettings as _M
from stylemotion.reconstruct.subject import Subject, database_on_subject, hold_bone_lengths
from stylemotion.search.database import MotionDatabase
from stylemotion.search.features import feature_spec, stack_window, window_offsets
from stylemotion.search.index import FrameIndex
from stylemotion.skeleton import JOINT_INDEX, NUM_JOINTS

#: Feature sets the reconstruction can search in (windows only over markers; no physics terms).
RECONSTRUCT_FEATURE_SETS = ("E15", "E30", "E39", "E15x3", "E15x5", "pca8", "pca16", "pca25")
_EPS = 1e-9
_LIMB_ENDS = ("Hand_L", "Hand_R", "Foot_L", "Foot_R")


def marker_frames(markers: np.ndarray, joints: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """The marker frame of each frame (module docstring, step 1).

    Args:
        markers: ``(..., m, 3)`` marker positions, metres, Y up.  joints: their names.

    Returns:
        Rotations ``(..., 3, 3)`` (columns: left, up, forward in world) and origins ``(..., 3)`` (metres);
        ``local = Rᵀ (p − origin)``.
    """
    markers = np.asarray(markers, dtype=np.float64)
    joints = list(joints)
    root = markers[..., joints.index("Hips"), :] if "Hips" in joints else markers.mean(axis=-2)
    origin = root * np.array([1.0, 0.0, 1.0])
    left = np.zeros(markers.shape[:-2] + (3,))
    for j, name in enumerate(joints):
        if name.endswith("_L") and name[:-2] + "_R" in joints:
            left += markers[..., j, :] - markers[..., joints.index(name[:-2] + "_R"), :]
    left[..., 1] = 0.0
    norm = np.linalg.norm(left, axis=-1, keepdims=True)
    left = np.where(norm > _EPS, left / np.maximum(norm, _EPS), np.array([1.0, 0.0, 0.0]))
    up = np.broadcast_to(np.array([0.0, 1.0, 0.0]), left.shape)
    forward = np.cross(left, up)
    return np.stack([left, up, forward], axis=-1), origin


def to_local(points: np.ndarray, rotation: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """World points ``(..., j, 3)`` → marker-frame coordinates with ``rotation (..., 3, 3)``, ``origin (..., 3)``."""
    return np.matmul(points - origin[..., None, :], rotation)  # local_k = Rᵀ (p_k − o), as rows: (p − o) R


def to_world(points: np.ndarray, rotation: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """Inverse of :func:`to_local`."""
    return np.matmul(points, np.swapaxes(rotation, -1, -2)) + origin[..., None, :]


@dataclass
class Reconstruction:
    """A reconstructed motion: ``positions`` ``(frames, 21, 3)`` metres in the markers' world frame, the
    ``settings``, ``timings`` (seconds) and per frame the nearest database frame (``nearest``, global index)."""

    positions: np.ndarray
    settings: dict
    timings: dict = field(default_factory=dict)
    nearest: np.ndarray | None = None

    @property
    def frames_per_second(self) -> float:
        total = self.timings.get("total", 0.0)
        return float(len(self.positions) / total) if total > 0 else float("inf")


def joint_errors_cm(positions: np.ndarray, truth: np.ndarray) -> dict:
    """Mean and max per-joint Euclidean error (cm) of ``positions`` against ``truth`` (both ``(frames, 21, 3)``
    metres), and the mean per joint name."""
    err = np.linalg.norm(np.asarray(positions, float) - np.asarray(truth, float), axis=-1) * 100.0
    from stylemotion.skeleton import CANONICAL_JOINTS

    return {"mean_cm": float(err.mean()), "max_cm": float(err.max()),
            "per_joint_mean_cm": {j: round(float(err[:, i].mean()), 3) for i, j in enumerate(CANONICAL_JOINTS)}}


def subject_scale(markers: np.ndarray, marker_set: MarkerSet, database: MotionDatabase) -> float:
    """The subject's size against the database's, from marker tracks ``(frames, m, 3)`` metres: the median over
    marker pairs of the ratio of their 95th-percentile distance in the tracks to the same on the database's
    virtual markers (pairs among the markers off the arms when there are two such, else all pairs)."""
    arms = ("Shoulder", "UpperArm", "LowerArm", "Hand")
    body = [i for i, s in enumerate(marker_set.segments) if not s.startswith(arms)]
    chosen = body if len(body) >= 2 else list(range(len(marker_set.markers)))
    pairs = [(a, b) for n, a in enumerate(chosen) for b in chosen[n + 1:]]
    if not pairs:
        return 1.0
    step = max(1, database.num_frames // 50_000)
    ours = np.asarray(markers, np.float64)
    theirs = virtual_markers(np.asarray(database.positions[::step], np.float64), marker_set)

    def p95(m: np.ndarray, a: int, b: int) -> float:
        return float(np.percentile(np.linalg.norm(m[:, a] - m[:, b], axis=-1), 95))

    ratios = [p95(ours, a, b) / max(p95(theirs, a, b), _EPS) for a, b in pairs]
    return float(np.median(ratios))


def database_on_bones(database: MotionDatabase, bones: np.ndarray) -> MotionDatabase:
    """``database`` with every take put on the bone lengths ``bones`` ``(20,)`` metres
    (:func:`stylemotion.reconstruct.subject.database_on_subject` with lengths only)."""
    return database_on_subject(database, Subject(np.asarray(bones, np.float64)))


class SparseReconstructor:
    """Reconstruction of full poses from the markers ``joints`` with the prior of ``database`` (module docstring).

    Args:
        database: the motion database (its fps is the markers' required rate).
        joints: marker names (joint centres) or a :class:`MarkerSet` (skin markers, marker-only feature sets).
        bones: ``(20,)`` metres, the subject's bone lengths, or a :class:`~stylemotion.reconstruct.subject.Subject`
            (lengths and rigid bone directions): the database is put on them first.
        hold_bones: every output frame's bones set to ``bones`` (else to the result's median bone lengths).
        features: one of :data:`RECONSTRUCT_FEATURE_SETS`.  k: neighbours per frame.
        variance: fraction of the neighbours' spread the local PCA keeps.  marker_sd: metres a marker may miss
            by.  smooth_sd: metres a joint may move between frames (in the marker frame).  prior_weight: weight
            of the Mahalanobis prior (None: by marker kind, as ``SparseModelSettings`` says).  iterations: k-NN
            searches per frame for pose-guided sets.  weighted: distance-weighted local model (module docstring,
            step 3).
        engine, workers: the k-NN engine (:class:`FrameIndex`).
    """

    def __init__(self, database: MotionDatabase, joints: Sequence[str] | MarkerSet, features: str = _C.features,
                 k: int = _C.k, variance: float = _M.variance, marker_sd: float = _M.marker_sd,
                 smooth_sd: float = _M.smooth_sd, prior_weight: float | None = _M.prior_weight,
                 iterations: int = _M.iterations, weighted: bool = _M.weighted, engine: str = "ckdtree",
                 workers: int = 1, bones: np.ndarray | Subject | None = None, hold_bones: bool = _M.hold_bones):
        if isinstance(joints, MarkerSet):
            self.marker_set = joints
            self.joints = joints.names
        else:
            self.joints = check_marker_names(joints)
            self.marker_set = joint_marker_set(self.joints)
        self.roles = self.marker_set.segments  # what the marker frame calls each marker
        self.skin = not self.marker_set.is_joint_centres
        if prior_weight is None:
            prior_weight = SKIN_PRIOR_WEIGHT if self.skin else JOINT_CENTRE_PRIOR_WEIGHT
        if features not in RECONSTRUCT_FEATURE_SETS:
            raise ValueError(f"features={features} cannot be used for reconstruction; valid: "
                             f"{list(RECONSTRUCT_FEATURE_SETS)}")
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 2 <= k <= database.num_frames:
            raise ValueError(f"k={k} must be a whole number from 2 to the database's {database.num_frames} frames")
        for key, value in (("variance", variance), ("marker_sd", marker_sd), ("smooth_sd", smooth_sd)):
            if not (isinstance(value, (int, float)) and 0 < value and np.isfinite(value)):
                raise ValueError(f"{key}={value} must be a positive number")
        if not 0 < variance <= 1:
            raise ValueError(f"variance={variance} must be in (0, 1]")
        if not (isinstance(prior_weight, (int, float)) and prior_weight >= 0):
            raise ValueError(f"prior_weight={prior_weight} must be a number ≥ 0")
        self.database, self.features, self.k = database, features, int(k)
        self.variance, self.marker_sd, self.smooth_sd = float(variance), float(marker_sd), float(smooth_sd)
        self.prior_weight, self.iterations = float(prior_weight), max(1, int(iterations))
        self.weighted = bool(weighted)
        self.marker_idx = [JOINT_INDEX[j] for j in self.roles]
        spec = feature_spec(features)
        self.spec = spec
        self.guided = spec.pca_components > 0 or not set(spec.joints) <= set(self.roles)
        if self.skin and self.guided:
            raise ValueError(f"features={features}: skin markers need a marker-only feature set (E15, E15x3, E15x5)")
        if self.guided and spec.samples > 1:
            raise ValueError(f"features={features}: a window over joints that are not markers "
                             f"({sorted(set(spec.joints) - set(self.joints))}) is not supported")
        self.feature_joints = [j for j in (spec.joints or ()) if j in JOINT_INDEX]
        self.subject = None
        if bones is not None:
            from stylemotion.bones import BONE_NAMES

            subject = bones if isinstance(bones, Subject) else Subject(np.asarray(bones, np.float64))
            lengths = np.asarray(subject.lengths, np.float64)
            if lengths.shape != (len(BONE_NAMES),) or not np.all(np.isfinite(lengths)) or np.any(lengths < 0):
                raise ValueError(f"bones must be {len(BONE_NAMES)} lengths ≥ 0 in metres, got shape {lengths.shape}")
            database = database_on_subject(database, subject)
            self.database, self.subject, bones = database, subject, lengths
        self.hold_bones = bool(hold_bones)
        self.bones = bones  # the subject's, or None: each result's own median bones
        positions = np.asarray(database.positions, np.float64)
        db_markers = virtual_markers(positions, self.marker_set)
        rotation, origin = marker_frames(db_markers, self.roles)
        self.local = to_local(positions, rotation, origin).reshape(-1, 3 * NUM_JOINTS)
        # the markers' own coordinates in the marker frame, beside the joints' (skin markers only: for joint
        # centres they are columns of ``local`` already)
        self.local_markers = to_local(db_markers, rotation, origin).reshape(len(positions), -1) if self.skin \
            else np.zeros((len(positions), 0))
        self.mean_pose = self.local.mean(axis=0)
        self._pca: np.ndarray | None = None
        data = self._database_features()
        name = f"reconstruct:{features}:{','.join(self.joints)}"
        self.index = FrameIndex(database, name, features=data, engine=engine, workers=workers)

    # -- features ---------------------------------------------------------------------------------

    def _pose_features(self, local: np.ndarray) -> np.ndarray:
        """``(n, 63)`` marker-frame poses → ``(n, d)`` features of a frame-based set."""
        if self.spec.pca_components:
            return (local - self.mean_pose) @ self._pca.T
        cols = np.concatenate([3 * JOINT_INDEX[j] + np.arange(3) for j in self.feature_joints])
        return local[:, cols]

    def _frame_marker_features(self) -> np.ndarray:
        """``(n, d)`` database features of a marker-only set: the feature joints' markers in the marker frame."""
        if not self.skin:
            return self._pose_features(self.local)
        picked = [self.roles.index(j) for j in self.feature_joints]
        cols = np.concatenate([3 * m + np.arange(3) for m in picked])
        return self.local_markers[:, cols]

    def _database_features(self) -> np.ndarray:
        if self.spec.pca_components:
            centred = self.local - self.mean_pose
            _, _, vt = np.linalg.svd(centred[:: max(1, len(centred) // 20000)], full_matrices=False)
            self._pca = vt[: self.spec.pca_components]
        frame_features = self._frame_marker_features()
        if self.spec.samples == 1:
            return frame_features
        offsets = window_offsets(self.spec.samples, self.database.fps)
        starts = self.database.take_start
        return np.concatenate([stack_window(frame_features[a:b], offsets) for a, b in zip(starts[:-1], starts[1:])])

    def marker_features(self, local_markers: np.ndarray) -> np.ndarray:
        """``(frames, m, 3)`` marker-frame markers → ``(frames, d)`` features of a marker-only set (windows
        over the track, its first frame repeated before it)."""
        picked = local_markers[:, [self.roles.index(j) for j in self.feature_joints]].reshape(len(local_markers), -1)
        if self.spec.samples == 1:
            return picked
        return stack_window(picked, window_offsets(self.spec.samples, self.database.fps))

    # -- the pose ---------------------------------------------------------------------------------

    def solve(self, neighbours: np.ndarray, distances: np.ndarray, markers_local: np.ndarray,
              previous: np.ndarray | None) -> np.ndarray:
        """The pose ``(63,)`` (marker frame) from the neighbours' global indices and feature distances ``(k,)``,
        this frame's markers ``(m, 3)`` in its marker frame and the previous result ``(63,)`` in the same frame
        (or None)."""
        poses = np.concatenate([self.local[neighbours], self.local_markers[neighbours]], axis=1)
        weights = np.ones(len(poses))
        if self.weighted:
            weights = 1.0 / (np.asarray(distances, np.float64) + self.marker_sd) ** 2
        weights /= weights.sum()
        mu = weights @ poses
        _, s, vt = np.linalg.svd(np.sqrt(weights)[:, None] * (poses - mu), full_matrices=False)
        var = s ** 2 * len(poses) / max(1, len(poses) - 1)
        n = 3 * NUM_JOINTS
        if var.sum() <= _EPS:
            return mu[:n]
        keep = int(np.searchsorted(np.cumsum(var) / var.sum(), self.variance - 1e-12) + 1)
        basis, var = vt[:keep], np.maximum(var[:keep], _EPS)
        if self.skin:
            cols = n + np.arange(3 * len(self.joints))
        else:
            cols = np.concatenate([3 * i + np.arange(3) for i in self.marker_idx])
        sb = basis[:, cols].T  # (3m, r)
        a = sb.T @ sb / self.marker_sd ** 2 + self.prior_weight * np.diag(1.0 / var)
        b = sb.T @ (markers_local.reshape(-1) - mu[cols]) / self.marker_sd ** 2
        if previous is not None:
            joints = basis[:, :n]  # the pose part of the basis (orthonormal rows when there are no marker columns)
            a += joints @ joints.T / self.smooth_sd ** 2
            b += joints @ (previous - mu[:n]) / self.smooth_sd ** 2
        return mu[:n] + basis[:, :n].T @ np.linalg.solve(a, b)

    def reconstruct(self, tracks: MarkerTracks | np.ndarray) -> Reconstruction:
        """Full poses for marker tracks (a :class:`MarkerTracks` of this reconstructor's joints, at the
        database's fps, or their ``(frames, m, 3)`` positions, metres) → :class:`Reconstruction`."""
        started = time.perf_counter()
        markers = self._check_tracks(tracks)
        rotation, origin = marker_frames(markers, self.roles)
        local_markers = to_local(markers, rotation, origin)
        knn_s = 0.0
        nearest = np.empty(len(markers), dtype=np.int64)
        if not self.guided:
            t0 = time.perf_counter()
            distance_table, neighbour_table = self.index.query(self.marker_features(local_markers), self.k)
            knn_s += time.perf_counter() - t0
        out = np.empty((len(markers), 3 * NUM_JOINTS))
        previous_world: np.ndarray | None = None
        for t in range(len(markers)):
            prev_local = None
            if previous_world is not None:
                prev_local = to_local(previous_world, rotation[t], origin[t]).reshape(-1)
            if self.guided:
                guess = self.mean_pose.copy() if prev_local is None else prev_local.copy()
                for _ in range(self.iterations):
                    guess.reshape(NUM_JOINTS, 3)[self.marker_idx] = local_markers[t]
                    t0 = time.perf_counter()
                    distances, neighbours = self.index.query(self._pose_features(guess[None])[0], self.k)
                    knn_s += time.perf_counter() - t0
                    guess = self.solve(neighbours, distances, local_markers[t], prev_local)
                pose = guess
            else:
                neighbours = neighbour_table[t]
                pose = self.solve(neighbours, distance_table[t], local_markers[t], prev_local)
            nearest[t] = neighbours[0]
            out[t] = pose
            previous_world = to_world(pose.reshape(NUM_JOINTS, 3), rotation[t], origin[t])
        positions = to_world(out.reshape(-1, NUM_JOINTS, 3), rotation, origin)
        if self.hold_bones:
            positions = self.held(positions, markers)
        total = time.perf_counter() - started
        return Reconstruction(positions, self.settings(), {"knn": knn_s, "total": total}, nearest)

    def held(self, positions: np.ndarray, markers: np.ndarray) -> np.ndarray:
        """The model's poses ``(frames, 21, 3)`` on the subject's bones (module docstring), moved onto the markers
        ``(frames, m, 3)``: the whole body by the root marker's miss, each limb end by its marker's remaining miss
        (the misses measured on the set's virtual markers of the poses)."""
        from stylemotion.bones import median_bone_lengths

        miss = markers - virtual_markers(positions, self.marker_set)  # (frames, m, 3)
        if "Hips" in self.roles:
            root = miss[:, self.roles.index("Hips")]
            positions = positions + root[:, None]
            miss = miss - root[:, None]
        ends = {seg: positions[:, JOINT_INDEX[seg]] + miss[:, m] for m, seg in enumerate(self.roles)
                if seg in _LIMB_ENDS}
        lengths = median_bone_lengths(positions) if self.bones is None else self.bones
        return hold_bone_lengths(positions, lengths, ends)

    def nearest_neighbour(self, tracks: MarkerTracks | np.ndarray) -> np.ndarray:
        """Baseline: each frame's nearest database pose (k = 1 in the same features) placed with the markers'
        frame → ``(frames, 21, 3)`` metres."""
        markers = self._check_tracks(tracks)
        rotation, origin = marker_frames(markers, self.roles)
        local_markers = to_local(markers, rotation, origin)
        if self.guided:
            raise ValueError("the nearest-neighbour baseline needs a marker-only feature set (e.g. E15)")
        _, nearest = self.index.query(self.marker_features(local_markers), 1)
        return to_world(self.local[nearest[:, 0]].reshape(-1, NUM_JOINTS, 3), rotation, origin)

    def settings(self) -> dict:
        """The settings as JSON-ready values."""
        return {"markers": list(self.joints), "features": self.features, "k": self.k, "variance": self.variance,
                "marker_sd_m": self.marker_sd, "smooth_sd_m": self.smooth_sd, "prior_weight": self.prior_weight,
                "iterations": self.iterations, "weighted": self.weighted,
                "search": "pose-guided" if self.guided else "markers",
                "marker_set": {"name": self.marker_set.name, "markers": self.marker_set.describe()},
                "hold_bones": self.hold_bones,
                "subject": None if self.subject is None else self.subject.describe(),
                "database": {"name": self.database.name, "takes": self.database.num_takes,
                             "frames": self.database.num_frames, "fps": self.database.fps}}

    def _check_tracks(self, tracks: MarkerTracks | np.ndarray) -> np.ndarray:
        if isinstance(tracks, MarkerTracks):
            if tuple(tracks.joints) != self.joints:
                raise MarkerInputError(f"{tracks.source}: markers {list(tracks.joints)} are not the reconstructor's "
                                       f"{list(self.joints)}")
            if abs(tracks.fps - self.database.fps) > 1e-6:
                raise MarkerInputError(f"{tracks.source}: markers at {tracks.fps:g} fps, the database at "
                                       f"{self.database.fps:g} fps; convert them to its rate")
            tracks = tracks.positions
        markers = np.asarray(tracks, dtype=np.float64)
        if markers.ndim != 3 or markers.shape[1:] != (len(self.joints), 3) or len(markers) < 1:
            raise MarkerInputError(f"marker positions must be (frames ≥ 1, {len(self.joints)}, 3), got {markers.shape}")
        if not np.all(np.isfinite(markers)):
            frame, m = np.argwhere(~np.isfinite(markers).all(axis=-1))[0]
            raise MarkerInputError(f"marker {self.joints[m]} is not finite at frame {frame}; fill gaps first "
                                   f"(stylemotion.reconstruct.markers.fill_gaps)")
        return markers


def reconstruct(tracks: MarkerTracks, database: MotionDatabase, **settings) -> Reconstruction:
    """:class:`SparseReconstructor` for ``tracks``' markers, applied to them."""
    return SparseReconstructor(database, tracks.joints, **settings).reconstruct(tracks)
