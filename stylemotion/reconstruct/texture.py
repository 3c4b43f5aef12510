"""Motion texturing and completion with the motion database (Krüger §4.2).

Input: a coarse, partial or low-quality motion ``(frames, 21, 3)`` metres at the database's fps.

* ``mode="complete"``: only ``joints`` are trusted (default :data:`LEG_JOINTS`, hips and legs); the other
  joints are synthesized (NaN allowed there). Trusted joints are kept exactly (E_control with infinite weight).
* ``mode="texture"``: every joint is trusted only coarsely (a keyframed motion splined between keys, an
  over-smoothed motion); E_control is weak on all joints so the retrieved detail comes back.

Steps:

1. **Body frame.** :func:`~stylemotion.reconstruct.sparse.marker_frames` of the trusted joints (origin under the
   hips, yaw from the left/right pairs), computed the same way for every database frame.
2. **Retrieval.** Features = the trusted joints in that frame, stacked over ``samples`` frames of the last
   ``feature_seconds`` (:func:`~stylemotion.search.features.stack_window`), in a
   :class:`~stylemotion.search.FrameIndex`; the ``k`` nearest frames per query frame feed the online lazy
   neighbourhood graph (:class:`~stylemotion.search.lng.OnlineLNG`, §2.7, pushed frame by frame as §4.2 does,
   window ``lng_window`` frames, per-node normalized costs). Per frame the ``top`` best non-overlapping
   segments ending at it give the prior poses ``y_i`` (their last frame), with velocities ``ν_i`` and
   accelerations ``α_i`` stored in each database frame's own body frame; segment ``i`` weighs
   ``1 / (cost_i + distance_sd)²`` (cost = mean feature distance along it, metres). A frame without a segment
   falls back to its k-NN with their distances.
3. **Synthesis (eq. 4.7).** With the weighted means ``ȳ_t, ν̄_t, ᾱ_t`` (kernel regression: ``Σ_i w_i‖y_i − x‖²``
   is ``‖x − ȳ‖²`` up to a constant) placed in the query's body frame — in complete mode the prior pose is
   shifted so that its hips meet the trusted hips (root-relative) — minimize over all frames at once
   ``pose·Σ_t‖x_t − ȳ_t‖² + motion·Σ_t‖(x_{t+1} − x_{t−1})/2 − ν̄_t‖² + smooth·Σ_t‖x_{t+1} − 2x_t + x_{t−1} − ᾱ_t‖²
   + control·Σ_t‖x_t − q_t‖²``: a sparse linear least-squares problem in the frames whose normal equations
   (pentadiagonal, one per control weight) are factorized once and solved for every joint and axis.
4. **Clean-up.** :func:`stylemotion.synthesis.cleanup.clean_foot_skating`; in complete mode it only changes
   joints that are not trusted.

Simplified against §4.2: no gradient descent and hence no multiscale schedule, frame scheduler or interleaving
(the thesis needs them to make gradient steps over whole sequences tractable; the quadratic energy here is
solved exactly in one sparse solve, which is what the schedule converges to); no per-joint weights
(Table 4.5: with a diagonal energy they only rescale each joint's prior against its own control term); the pose
lives in joint positions, bone lengths are not enforced.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from stylemotion.io.errors import UserInputError
from stylemotion.reconstruct.markers import check_joint_names
from stylemotion.reconstruct.settings import TextureModelSettings as _M
from stylemotion.reconstruct.settings import TextureSettings as _C
from stylemotion.reconstruct.sparse import marker_frames, to_local, to_world
from stylemotion.search.database import MotionDatabase
from stylemotion.search.features import stack_window, window_offsets
from stylemotion.search.index import FrameIndex
from stylemotion.search.lng import OnlineLNG
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX, NUM_JOINTS

#: The trusted joints of completion by default: hips and legs.
LEG_JOINTS = ("Hips", "UpperLeg_L", "LowerLeg_L", "Foot_L", "Toes_L", "UpperLeg_R", "LowerLeg_R", "Foot_R", "Toes_R")
MODES = ("complete", "texture")
#: Fewest frames a motion needs (velocity and acceleration terms).
MIN_FRAMES = 3
#: Default energy weights per mode (pose, motion, smooth, control); control is infinite in complete mode.
DEFAULT_WEIGHTS = {"complete": {"pose": 1.0, "motion": 4.0, "smooth": 4.0, "control": np.inf},
                   "texture": {"pose": 0.05, "motion": 10.0, "smooth": 40.0, "control": 4.0}}


class TextureInputError(UserInputError, ValueError):
    """A motion, joint, mode or setting that cannot be used; the message names the value."""


@dataclass
class TextureResult:
    """A textured / completed motion.

    Attributes:
        positions: ``(frames, 21, 3)`` metres in the input's world frame (after clean-up).
        raw: the same before the foot-skating clean-up.
        nearest_neighbour: the baseline: per frame the nearest database pose in the same features, placed in
            the input's body frame (trusted joints from the input in complete mode).
        nearest: ``(frames,)`` global database frame of the best segment at each frame.
        settings, timings: JSON-ready settings and seconds.
    """

    positions: np.ndarray
    raw: np.ndarray
    nearest_neighbour: np.ndarray
    nearest: np.ndarray
    settings: dict
    timings: dict = field(default_factory=dict)


def check_joints(joints: Sequence[str]) -> tuple[str, ...]:
    """The trusted joints as a tuple; TextureInputError naming an unknown or repeated one, or none."""
    return check_joint_names(joints, "joint", TextureInputError,
                             "joints=[] is empty; name the trusted canonical joints")


def _per_take_derivatives(positions: np.ndarray, take_start: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Velocities (central differences, m/frame) and accelerations (second differences, m/frame²) of
    ``(n, 21, 3)`` positions within each take (edges: one-sided velocity, the neighbouring acceleration)."""
    vel, acc = np.zeros_like(positions), np.zeros_like(positions)
    for a, b in zip(take_start[:-1], take_start[1:]):
        p = positions[a:b]
        if len(p) < 2:
            continue
        vel[a:b] = np.gradient(p, axis=0)
        if len(p) >= 3:
            inner = p[2:] - 2 * p[1:-1] + p[:-2]
            acc[a:b] = np.concatenate([inner[:1], inner, inner[-1:]])
    return vel, acc


def _difference_operators(frames: int) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Central first difference ``(frames−2, frames)`` (halved) and second difference of the inner frames."""
    rows = np.arange(frames - 2)
    first = sp.csr_matrix((np.concatenate([np.full(frames - 2, -0.5), np.full(frames - 2, 0.5)]),
                           (np.concatenate([rows, rows]), np.concatenate([rows, rows + 2]))), (frames - 2, frames))
    second = sp.csr_matrix((np.concatenate([np.ones(frames - 2), np.full(frames - 2, -2.0), np.ones(frames - 2)]),
                            (np.concatenate([rows, rows, rows]), np.concatenate([rows, rows + 1, rows + 2]))),
                           (frames - 2, frames))
    return first, second


#: Weight of a pinned frame's control term relative to the energy's largest weight (a hard constraint in effect).
PIN_WEIGHT = 1e8


def solve_energy(pose: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray, control: np.ndarray,
                 control_weight: np.ndarray, weights: dict, pinned: Sequence[int] = ()) -> np.ndarray:
    """Minimize eq. 4.7 (module docstring, step 3) for independent channels.

    Args:
        pose, velocity, acceleration: ``(frames, c)`` targets (metres, m/frame, m/frame²) per channel.
        control: ``(frames, c)`` the input.  control_weight: ``(c,)`` E_control weight per channel; ``inf`` keeps
            the input.  weights: ``pose``, ``motion``, ``smooth``.  pinned: frames where every channel keeps
            the input (the keyframes of a dynamic motion graph, §4.3.4).

    Returns:
        ``(frames, c)`` the minimizer.
    """
    frames = len(pose)
    out = np.array(control, dtype=np.float64)
    first, second = _difference_operators(frames)
    base = weights["motion"] * (first.T @ first) + weights["smooth"] * (second.T @ second)
    rhs_base = (weights["pose"] * pose + weights["motion"] * (first.T @ velocity[1:-1])
                + weights["smooth"] * (second.T @ acceleration[1:-1]))
    pin = np.zeros(frames)
    pin[np.asarray(pinned, dtype=np.int64)] = PIN_WEIGHT * max(weights["pose"], weights["motion"], weights["smooth"],
                                                               1.0)
    for lam in np.unique(control_weight[np.isfinite(control_weight)]):
        cols = np.flatnonzero(control_weight == lam)
        diagonal = weights["pose"] + lam + pin
        matrix = (base + sp.diags(diagonal)).tocsc()
        rhs = rhs_base[:, cols] + (lam + pin)[:, None] * control[:, cols]
        out[:, cols] = splu(matrix).solve(np.ascontiguousarray(rhs))
    out[np.asarray(pinned, dtype=np.int64)] = control[np.asarray(pinned, dtype=np.int64)]
    return out


class MotionTexturer:
    """Completion (``mode="complete"``) or texturing (``mode="texture"``) with the prior of ``database``.

    Args:
        database: the motion database (its fps is the motion's required rate; a style's takes only for a
            style transfer).
        mode: ``"complete"`` or ``"texture"``.  joints: trusted joints (default: :data:`LEG_JOINTS` for
            completion, every joint for texturing).  k: nearest frames per query frame fed to the LNG.
        top: segments per frame in the prior.  lng_window: frames of the online LNG's window.
        samples, feature_seconds: the feature window.  distance_sd: metres added to a segment's mean feature
            distance in its weight.  weights: ``pose``, ``motion``, ``smooth``, ``control`` (defaults
            :data:`DEFAULT_WEIGHTS`).  cleanup: the foot-skating clean-up at the end.
    """

    def __init__(self, database: MotionDatabase, mode: str = _C.mode, joints: Sequence[str] | None = None,
                 k: int = _C.k, top: int = _M.top, lng_window: int = _M.lng_window, samples: int = _M.samples,
                 feature_seconds: float = _M.feature_seconds, distance_sd: float = _M.distance_sd,
                 weights: dict | None = None, cleanup: bool = _M.cleanup):
        if mode not in MODES:
            raise TextureInputError(f"mode={mode} is not one of {list(MODES)}")
        default = LEG_JOINTS if mode == "complete" else CANONICAL_JOINTS
        self.mode, self.joints = mode, check_joints(default if joints is None else joints)
        if mode == "complete" and "Hips" not in self.joints:
            raise TextureInputError(f"joints={list(self.joints)}: completion needs the Hips among the trusted joints")
        for key, value, low in (("k", k, 1), ("top", top, 1), ("lng_window", lng_window, 1), ("samples", samples, 1)):
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low:
                raise TextureInputError(f"{key}={value} must be a whole number ≥ {low}")
        if not 1 <= k <= database.num_frames:
            raise TextureInputError(f"k={k} must be from 1 to the database's {database.num_frames} frames")
        for key, value in (("feature_seconds", feature_seconds), ("distance_sd", distance_sd)):
            if not (isinstance(value, (int, float)) and np.isfinite(value) and value > 0):
                raise TextureInputError(f"{key}={value} must be a positive number")
        merged = {**DEFAULT_WEIGHTS[mode], **dict(weights or {})}
        unknown = sorted(set(merged) - {"pose", "motion", "smooth", "control"})
        if unknown:
            raise TextureInputError(f"weights: unknown term(s) {unknown}; valid: pose, motion, smooth, control")
        for key, value in merged.items():
            if not (isinstance(value, (int, float)) and value >= 0) or (key != "control" and not np.isfinite(value)):
                raise TextureInputError(f"weights.{key}={value} must be a number ≥ 0")
        if merged["pose"] + merged["control"] <= 0:
            raise TextureInputError("weights.pose and weights.control cannot both be 0")
        self.database, self.k, self.top, self.lng_window = database, int(k), int(top), int(lng_window)
        self.samples, self.feature_seconds, self.distance_sd = int(samples), float(feature_seconds), float(distance_sd)
        self.weights = {key: float(v) for key, v in merged.items()}
        self.cleanup = bool(cleanup)
        self.trusted_idx = [JOINT_INDEX[j] for j in self.joints]
        self.offsets = window_offsets(self.samples, database.fps, self.feature_seconds)
        world = np.asarray(database.positions, np.float64)
        rotation, origin = marker_frames(world[:, self.trusted_idx], self.joints)
        self.local = to_local(world, rotation, origin)
        vel, acc = _per_take_derivatives(world, database.take_start)
        self.local_vel = np.einsum("nji,nkj->nki", rotation, vel)
        self.local_acc = np.einsum("nji,nkj->nki", rotation, acc)
        frame_features = self.local[:, self.trusted_idx].reshape(len(world), -1)
        starts = database.take_start
        features = np.concatenate([stack_window(frame_features[a:b], self.offsets)
                                   for a, b in zip(starts[:-1], starts[1:])])
        self.index = FrameIndex(database, f"texture:{mode}:{','.join(self.joints)}", features=features)

    def settings(self) -> dict:
        """The settings as JSON-ready values."""
        return {"mode": self.mode, "joints": list(self.joints), "k": self.k, "top": self.top,
                "lng_window": self.lng_window, "retrieval": "OnlineLNG per frame", "samples": self.samples,
                "feature_seconds": self.feature_seconds, "distance_sd_m": self.distance_sd,
                "weights": {key: (None if not np.isfinite(v) else v) for key, v in self.weights.items()},
                "cleanup": self.cleanup,
                "database": {"name": self.database.name, "takes": self.database.num_takes,
                             "frames": self.database.num_frames, "fps": self.database.fps}}

    def _check_motion(self, motion: np.ndarray) -> np.ndarray:
        p = np.asarray(motion, dtype=np.float64)
        if p.ndim != 3 or p.shape[1:] != (NUM_JOINTS, 3):
            raise TextureInputError(f"the motion must be (frames, {NUM_JOINTS}, 3) metres, got {p.shape}")
        if len(p) < MIN_FRAMES:
            raise TextureInputError(f"the motion has {len(p)} frame(s); {self.mode} needs at least {MIN_FRAMES}")
        bad = ~np.isfinite(p[:, self.trusted_idx]).all(axis=-1)
        if bad.any():
            frame, j = np.argwhere(bad)[0]
            raise TextureInputError(f"trusted joint {self.joints[j]} is not finite at frame {frame}")
        return p

    def _prior(self, distances: np.ndarray, neighbours: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Per frame the prior's database frames ``(frames, top)`` (-1 = none) and normalized weights."""
        frames = len(neighbours)
        chosen = np.full((frames, self.top), -1, dtype=np.int64)
        weights = np.zeros((frames, self.top))
        lng = OnlineLNG(self.lng_window, self.database.take_bounds, normalize="length")
        for t in range(frames):
            lng.push(neighbours[t], distances[t])
            matches = lng.matches(top=self.top)
            if matches:
                chosen[t, :len(matches)] = [m.end for m in matches]
                weights[t, :len(matches)] = [1.0 / (m.cost + self.distance_sd) ** 2 for m in matches]
            else:
                n = min(self.top, len(neighbours[t]))
                chosen[t, :n] = neighbours[t, :n]
                weights[t, :n] = 1.0 / (distances[t, :n] + self.distance_sd) ** 2
        return chosen, weights / weights.sum(axis=1, keepdims=True)

    def apply(self, motion: np.ndarray, pinned: Sequence[int] = ()) -> TextureResult:
        """Complete or texture ``motion`` ``(frames, 21, 3)`` metres (at the database's fps; in complete mode the
        untrusted joints may be NaN) → :class:`TextureResult`. ``pinned``: frames kept exactly as given (every
        joint; they must be complete), e.g. keyframes."""
        started = time.perf_counter()
        query = self._check_motion(motion)
        frames = len(query)
        pinned = np.unique(np.asarray(pinned, dtype=np.int64))
        if pinned.size and (pinned.min() < 0 or pinned.max() >= frames):
            raise TextureInputError(f"pinned frame {int(pinned.max() if pinned.max() >= frames else pinned.min())} "
                                    f"is outside the motion's {frames} frames")
        if pinned.size and not np.isfinite(query[pinned]).all():
            raise TextureInputError(f"pinned frame {int(pinned[~np.isfinite(query[pinned]).all(axis=(1, 2))][0])} "
                                    f"has joints that are not finite")
        rotation, origin = marker_frames(query[:, self.trusted_idx], self.joints)
        q_local = to_local(np.nan_to_num(query), rotation, origin)
        features = stack_window(q_local[:, self.trusted_idx].reshape(frames, -1), self.offsets)
        distances, neighbours = self.index.query(features, self.k)
        t_knn = time.perf_counter()
        chosen, w = self._prior(distances, neighbours)
        t_lng = time.perf_counter()
        picked = np.maximum(chosen, 0)
        pose = np.einsum("tk,tkjc->tjc", w, self.local[picked])
        vel = np.einsum("tk,tkjc->tjc", w, self.local_vel[picked])
        acc = np.einsum("tk,tkjc->tjc", w, self.local_acc[picked])
        baseline_local = self.local[neighbours[:, 0]].copy()
        if self.mode == "complete":
            hips = JOINT_INDEX["Hips"]
            pose += (q_local[:, hips] - pose[:, hips])[:, None]
            baseline_local += (q_local[:, hips] - baseline_local[:, hips])[:, None]
        pose_w = to_world(pose, rotation, origin)
        vel_w = np.einsum("tij,tkj->tki", rotation, vel)
        acc_w = np.einsum("tij,tkj->tki", rotation, acc)
        control_weight = np.zeros(NUM_JOINTS)
        control_weight[self.trusted_idx] = self.weights["control"]
        control = np.where(np.isfinite(query), query, pose_w)
        raw = solve_energy(pose_w.reshape(frames, -1), vel_w.reshape(frames, -1), acc_w.reshape(frames, -1),
                           control.reshape(frames, -1), np.repeat(control_weight, 3), self.weights, pinned)
        raw = raw.reshape(frames, NUM_JOINTS, 3)
        baseline = to_world(baseline_local, rotation, origin)
        if self.mode == "complete":
            baseline[:, self.trusted_idx] = query[:, self.trusted_idx]
            raw[:, self.trusted_idx] = query[:, self.trusted_idx]
        positions = raw
        if self.cleanup:
            from stylemotion.synthesis.cleanup import clean_foot_skating

            positions = clean_foot_skating(raw, self.database.fps)
            if self.mode == "complete":
                positions[:, self.trusted_idx] = query[:, self.trusted_idx]
            positions[pinned] = query[pinned]
        done = time.perf_counter()
        timings = {"knn": t_knn - started, "lng": t_lng - t_knn, "solve": done - t_lng, "total": done - started}
        return TextureResult(positions, raw, baseline, chosen[:, 0], self.settings(), timings)


def texture_motion(motion: np.ndarray, database: MotionDatabase, mode: str = "complete", **settings) -> TextureResult:
    """:class:`MotionTexturer` with ``settings`` applied to ``motion`` ``(frames, 21, 3)`` metres."""
    return MotionTexturer(database, mode, **settings).apply(motion)


def key_spline(positions: np.ndarray, every: int = 3) -> np.ndarray:
    """The keyframed version of a motion: keys every ``every`` frames (and the last frame), joined by a cubic
    spline per joint coordinate → ``(frames, 21, 3)`` (the texturing benchmark's coarse input)."""
    from scipy.interpolate import CubicSpline

    p = np.asarray(positions, dtype=np.float64)
    if isinstance(every, bool) or not isinstance(every, (int, np.integer)) or every < 1:
        raise TextureInputError(f"every={every} must be a whole number ≥ 1")
    keys = np.unique(np.concatenate([np.arange(0, len(p), every), [len(p) - 1]]))
    if len(keys) < 2:
        raise TextureInputError(f"the motion has {len(p)} frame(s); a spline needs at least 2 keys")
    return CubicSpline(keys, p[keys], axis=0)(np.arange(len(p)))
