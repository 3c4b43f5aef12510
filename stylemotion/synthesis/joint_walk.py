"""All steps of a Morphable Graph walk optimized together (Du, Algorithm 1, line 9).

The graph walk (Algorithm 1, lines 2–8; :func:`~.controller.follow_path`) optimizes each step's code alone, from
where the previous step ended: a step that lands short cannot be helped by its successors, and each transition is
met only from the side of the later step. Line 9 then optimizes the codes ``s_1 … s_n`` of the whole walk at once,
each step keeping its primitive (variant) and its target. The objective sums the path follower's step terms
(:class:`~.settings.FollowSettings` scales) over the steps, with the walk as it is stitched::

    Σ_i  ‖p_i − p*_i‖² / σ_p² + wrap(θ_i − θ*_i)² / σ_θ²                    each step's target (position, heading)
       + ‖pose₀(s_i) − pose_end(i − 1)‖² / (21 σ_pose²) + (v̄_i − v̄_{i−1})² / σ_v²   transition (i ≥ 2)
       + λ ‖L_k⁻¹ (s_i − μ_k)‖²                                              prior (the component of the walk's code)

``p_i, θ_i``: where step ``i`` ends **in the stitched walk**: each code is decoded to its 66-dim frames, blended into
the previous clip's last frame over ``follow.blend_frames`` (:func:`~.stitching.blend_into`, as
:func:`~.stitching.append_clip` does) and integrated from where the previous step ended
(:func:`stylemotion.representation.integrate_root`). The blend moves a step's end by 1–2 cm and 0.01–0.02 rad, which
over a dozen steps outweighs what the optimization gains, so it is modelled, not ignored. ``pose₀``: the clip's first
frame's root-local joints, ``pose_end``: the previous blended clip's last frame's (63 values each, as the graph walk's
transition term); ``v̄``: a blended clip's mean root ground speed (m/s). The terms are those of one step's search
(:func:`stylemotion.morphable.synthesis._step_residuals`), so only the coupling is new.

Levenberg–Marquardt (scipy) minimizes it from the walk's codes, with a Jacobian by finite differences: a change of
step ``i``'s code changes its own clip and, through the blend, the next one; the later steps move rigidly with it. The
result is kept only if its objective is lower than the walk's.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import torch
from scipy.optimize import least_squares

from stylemotion.geometry import rotate_yaw_xz, wrap_angle
from stylemotion.representation import JOINT_DIMS, VELOCITY_DIMS, YAW_RATE_DIM, integrate_root
from stylemotion.skeleton import NUM_JOINTS
from stylemotion.synthesis.settings import FollowSettings
from stylemotion.synthesis.stitching import blend_weights

#: Finite-difference step of the Jacobian, latent units (the codes are O(1)).
DIFFERENCE_STEP = 1e-6


@dataclass(frozen=True)
class JointStep:
    """One step of a walk: its primitive's ``model`` (a :class:`~stylemotion.morphable.model.MorphableModel`), its
    ``latent`` ``(d,)`` from the walk, and its target ``target_xz`` ``(2,)`` metres and ``target_yaw`` radians."""

    model: object
    latent: np.ndarray
    target_xz: np.ndarray
    target_yaw: float


@dataclass
class JointResult:
    """The jointly optimized codes (one ``(d_i,)`` array per step) and the objective ``½‖r‖²`` before and after
    (``cost`` equals ``start_cost`` and ``latents`` the walk's codes when LM found nothing lower)."""

    latents: list[np.ndarray]
    start_cost: float
    cost: float
    evaluations: int
    improved: bool


@dataclass
class _Clips:
    """Decoded clips of one step for ``m`` codes: ``frames`` ``(m, L, 66)`` float64 (zero-padded), ``counts``
    ``(m,)`` frames each."""

    frames: np.ndarray
    counts: np.ndarray


def _decode(model, codes: np.ndarray) -> _Clips:
    decoded = model.decode_latent(np.asarray(codes, dtype=np.float64))
    return _Clips(decoded.frames.numpy().astype(np.float64), decoded.num_frames.numpy().astype(int))


def _placed(clips: _Clips, previous_last: np.ndarray | None, blend_frames: int, fps: float) -> dict[str, np.ndarray]:
    """What ``m`` clips do once blended into ``previous_last`` ``(m, 66)`` (None: the walk's first clip):
    ``displacement`` ``(m, 2)`` metres and ``turn`` ``(m,)`` radians in the facing where the clip starts, ``last``
    ``(m, 66)`` the blended last frame, ``speed`` ``(m,)`` mean ground speed (m/s), ``gap`` ``(m, 63)`` first pose
    minus the previous last pose (absent for the first clip)."""
    frames, counts = clips.frames, clips.counts
    m = len(frames)
    rows = np.arange(m)
    out: dict[str, np.ndarray] = {}
    if previous_last is not None:
        delta = previous_last - frames[:, 0]
        out["gap"] = -delta[:, JOINT_DIMS]
        weights = np.zeros(frames.shape[:2])
        for i, count in enumerate(counts):
            n = min(int(blend_frames), int(count))
            weights[i, :n] = blend_weights(n)
        frames = frames + weights[..., None] * delta[:, None, :]
    moving = np.arange(frames.shape[1])[None, :] < (counts[:, None] - 1)  # frames whose velocities are integrated
    masked = frames.copy()
    masked[..., VELOCITY_DIMS] *= moving[..., None]
    masked[..., YAW_RATE_DIM] *= moving
    root, yaw = integrate_root(torch.from_numpy(masked), fps)
    out["displacement"] = root[:, -1].numpy()
    out["turn"] = yaw[:, -1].numpy()
    out["last"] = frames[rows, counts - 1]
    speeds = np.linalg.norm(frames[..., VELOCITY_DIMS], axis=-1)
    out["speed"] = (speeds * moving).sum(-1) / np.maximum(counts - 1, 1)
    return out


class _Walk:
    """The joint residuals of a walk's steps (module doc)."""

    def __init__(self, steps: Sequence[JointStep], start_xz: np.ndarray, start_yaw: float, follow: FollowSettings):
        self.steps = list(steps)
        self.start_xz = np.asarray(start_xz, dtype=np.float64)
        self.start_yaw = float(start_yaw)
        self.follow = follow
        self.fps = float(self.steps[0].model.fps)
        self.sizes = [int(np.asarray(s.latent).size) for s in self.steps]
        self.offsets = np.concatenate([[0], np.cumsum(self.sizes)]).astype(int)
        scale = np.sqrt(follow.prior_weight)
        self.priors = []
        for s in self.steps:
            gmm = s.model.gmm
            k = int(np.argmax(gmm.component_log_prob(np.asarray(s.latent, dtype=np.float64)[None])))
            self.priors.append((scale * np.linalg.inv(np.linalg.cholesky(gmm.covariances[k])), gmm.means[k]))

    def split(self, x: np.ndarray) -> list[np.ndarray]:
        return [x[self.offsets[i]:self.offsets[i + 1]] for i in range(len(self.steps))]

    def place(self, clips: _Clips, previous_last: np.ndarray | None) -> dict[str, np.ndarray]:
        return _placed(clips, previous_last, self.follow.blend_frames, self.fps)

    def states(self, codes: list[np.ndarray]) -> tuple[list[_Clips], list[dict[str, np.ndarray]]]:
        """Each step's clips and placed state for one code per step."""
        clips, states, last = [], [], None
        for i, code in enumerate(codes):
            clips.append(_decode(self.steps[i].model, code[None]))
            states.append(self.place(clips[-1], last))
            last = states[-1]["last"]
        return clips, states

    def residuals(self, states: list[dict[str, np.ndarray]], codes: list[np.ndarray]) -> np.ndarray:
        """``(m, r)`` residuals of ``m`` variants of the walk: ``states[i][key]`` ``(m, …)``, ``codes[i]``
        ``(m, d_i)``."""
        f = self.follow
        m = len(codes[0])
        place = np.broadcast_to(self.start_xz, (m, 2))
        yaw = np.full(m, self.start_yaw)
        parts = []
        for i, (step, state) in enumerate(zip(self.steps, states)):
            place = place + rotate_yaw_xz(state["displacement"], yaw)
            yaw = yaw + state["turn"]
            parts.append((place - step.target_xz) / f.position_scale_m)
            parts.append(wrap_angle(yaw - step.target_yaw)[:, None] / f.heading_scale_rad)
            if i:
                parts.append(state["gap"] / (f.pose_scale_m * np.sqrt(NUM_JOINTS)))
                parts.append((state["speed"] - states[i - 1]["speed"])[:, None] / f.speed_scale_mps)
            inverse_chol, mean = self.priors[i]
            parts.append((codes[i] - mean) @ inverse_chol.T)
        return np.concatenate(parts, axis=1)

    def function(self, x: np.ndarray) -> np.ndarray:
        codes = [c[None] for c in self.split(x)]
        return self.residuals(self.states([c[0] for c in codes])[1], codes)[0]

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        codes = [c[None] for c in self.split(x)]
        clips, base = self.states([c[0] for c in codes])
        r0 = self.residuals(base, codes)[0]
        columns = []
        for i, d in enumerate(self.sizes):
            moved = codes[i] + DIFFERENCE_STEP * np.eye(d)
            states = [{k: np.repeat(v, d, axis=0) for k, v in b.items()} for b in base]
            previous = None if i == 0 else states[i - 1]["last"]
            states[i] = self.place(_decode(self.steps[i].model, moved), previous)
            for j in range(i + 1, len(self.steps)):  # the blend carries a change into the next clip (and on, while
                repeated = _Clips(np.repeat(clips[j].frames, d, axis=0), np.repeat(clips[j].counts, d))  # it changes
                states[j] = self.place(repeated, states[j - 1]["last"])  # a clip's last frame)
                if np.array_equal(states[j]["last"], np.repeat(base[j]["last"], d, axis=0)):
                    break
            batch_codes = [moved if j == i else np.repeat(c, d, axis=0) for j, c in enumerate(codes)]
            columns.append(((self.residuals(states, batch_codes) - r0) / DIFFERENCE_STEP).T)
        return np.concatenate(columns, axis=1)


def walk_objective(steps: Sequence[JointStep], start_xz: np.ndarray, start_yaw: float, follow: FollowSettings
                   ) -> tuple[float, np.ndarray]:
    """The joint objective ``½‖r‖²`` (module doc) of ``steps`` at their codes, and where each step ends ``(n, 3)``
    (x, z metres, yaw radians) in the stitched walk."""
    walk = _Walk(steps, start_xz, start_yaw, follow)
    codes = [np.asarray(s.latent, dtype=np.float64)[None] for s in steps]
    states = walk.states([c[0] for c in codes])[1]
    place, yaw, ends = walk.start_xz.copy(), walk.start_yaw, []
    for state in states:
        place = place + rotate_yaw_xz(state["displacement"][0], yaw)
        yaw = yaw + float(state["turn"][0])
        ends.append([place[0], place[1], yaw])
    return 0.5 * float((walk.residuals(states, codes)[0] ** 2).sum()), np.asarray(ends)


def optimize_steps(steps: Sequence[JointStep], start_xz: np.ndarray, start_yaw: float, follow: FollowSettings,
                   max_evaluations: int = 100) -> JointResult:
    """Algorithm 1, line 9: the codes of all ``steps`` optimized together (module doc), from the walk's codes.

    Args:
        steps: the walk's steps in order (≥ 1), all of one frame rate.
        start_xz, start_yaw: where the first step starts (metres, radians).
        follow: the path follower's scales, ``prior_weight`` and ``blend_frames``.
        max_evaluations: objective evaluations LM may spend (the Jacobians not counted).
    """
    if not steps:
        raise ValueError("optimize_steps needs at least one step")
    if max_evaluations < 1:
        raise ValueError(f"optimize_steps needs max_evaluations ≥ 1, got {max_evaluations}")
    walk = _Walk(steps, start_xz, start_yaw, follow)
    x0 = np.concatenate([np.asarray(s.latent, dtype=np.float64) for s in steps])
    start_cost = 0.5 * float((walk.function(x0) ** 2).sum())
    fit = least_squares(walk.function, x0, jac=walk.jacobian, method="lm", max_nfev=int(max_evaluations))
    cost = float(fit.cost)
    improved = cost < start_cost
    best = fit.x if improved else x0
    return JointResult([c.copy() for c in walk.split(best)], start_cost, min(cost, start_cost),
                       int(fit.nfev) + int(fit.njev or 0), improved)
