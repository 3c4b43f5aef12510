"""Trajectory following: a graph walk whose every step is a latent code optimized towards the path
(thesis §4.5.1–4.5.2 for the targets, §5.4.4 and Fig. 5.7 for the latent search).

For each step, with the root at ``(p₀, θ₀)`` (ground position, heading) where the previous step ended:

1. **Target.** ``p₀`` is projected onto the path (arc length ``s₀``). With ``r`` metres of path
   left and a typical step length ``ℓ`` of the step's primitive (:class:`~.graph.StepProfile`),
   the walk needs ``n = round(r / ℓ)`` more steps; the target is the path point at ``s₀ + r / n``
   and the path's heading there. Steps are thus spaced by the primitive's typical length, and
   the last one lands on the end of the path. The walk ends when ``n`` is 0.
2. **Cost** of a latent ``z`` (all terms dimensionless)::

       E(z) = ‖p(z) − p*‖² / σ_p² + wrap(θ(z) − θ*)² / σ_θ²            target: the step's end
            + λ_prior · ½‖z‖²                                          −log p(z) up to a constant
            + mean_j ‖pose₀(z) − pose_prev‖² / σ_pose²                 continuity: last pose …
            + (v̄(z) − v̄_prev)² / σ_v²                                  … and average speed

   where ``p(z), θ(z)`` are the root position and heading at the clip's end, placed at
   ``(p₀, θ₀)``; ``pose₀`` the first frame's root-local joints (63 values, metres) and ``v̄`` the
   mean root ground speed (m/s). They come from decoding ``z`` (VAE decoder → autoencoder decoder
   → time-normalized frames played back over the decoded duration) and integrating the root with
   :func:`stylemotion.representation.integrate_root` — all in torch, so ``E`` is differentiable.
3. **Search.** ``K`` codes drawn from the prior (a seeded generator: another seed, another walk);
   the cheapest is refined by Adam on ``z`` for a fixed number of iterations.
   A primitive may bring its own search (``search_step``, the Morphable Graph's MAP of eq. 4.9); it also
   gets the next steps' targets (:data:`LOOKAHEAD_TARGETS`) to choose among its variants by looking ahead.
4. The chosen code is decoded at the output frame rate and appended to the motion
   (:mod:`.stitching`); the root's new ``(p₀, θ₀)`` is read from the stitched motion itself.

A path turning more sharply than any step of the models can (measured per primitive from prior
samples) gets a warning naming where; the walk then does the best it can reach.
"""

from __future__ import annotations

import logging
import math
import time
import warnings
from dataclasses import dataclass, field, replace

import numpy as np
import torch

from stylemotion.geometry import wrap_angle_torch
from stylemotion.representation import JOINT_DIMS, VELOCITY_DIMS, frames_to_positions, integrate_root
from stylemotion.skeleton import NUM_JOINTS
from stylemotion.synthesis.graph import MotionGraph
from stylemotion.synthesis.path import GroundPath, PathError
from stylemotion.synthesis.settings import FollowSettings
from stylemotion.synthesis.stitching import append_clip

log = logging.getLogger(__name__)
#: Targets of the steps after the current one handed to a step search (a graph walk's look-ahead, e.g. the
#: Morphable Graph's §4.5.1; the VAE search ignores them), at the same spacing along the path.
LOOKAHEAD_TARGETS = 4


class SharpTurnWarning(UserWarning):
    """The path turns more sharply than any trained step can; the walk follows it as closely as it can."""


@dataclass
class StepRecord:
    """One step of the walk (JSON-friendly).

    Attributes:
        primitive: e.g. ``leftStance``.
        start_frame: index in the motion of its first (key)frame.
        target_xz, target_yaw: where it was asked to end (metres, radians).
        end_xz, end_yaw: where it ended in the stitched motion.
        duration_s: its decoded duration, seconds.
        cost_best_candidate, cost_final: ``E`` before and after refining ``z``.
        terms: the final cost's terms.
        latent: the chosen ``z``.
        variant: which of the primitive's variants took the step (Morphable Graph turn variants; else empty).
    """

    primitive: str
    start_frame: int
    target_xz: list[float]
    target_yaw: float
    end_xz: list[float]
    end_yaw: float
    duration_s: float
    cost_best_candidate: float
    cost_final: float
    terms: dict[str, float]
    latent: list[float]
    variant: str = ""


@dataclass
class SynthesizedMotion:
    """A walk along a path.

    Attributes:
        frames: ``(frames, 66)`` float32 stitched frames at ``fps``.
        positions: ``(frames, 21, 3)`` float32 global positions, metres, Y up.
        fps: frames per second.
        junctions: frame indices where one clip hands over to the next.
        steps: one :class:`StepRecord` per clip.
        path: the followed path.
        style: the graph's style.
        seconds: wall-clock time of the synthesis, seconds.
        warnings: messages about the path (e.g. turns sharper than any step).
    """

    frames: np.ndarray
    positions: np.ndarray
    fps: float
    junctions: list[int]
    steps: list[StepRecord]
    path: GroundPath
    style: str
    seconds: float
    warnings: list[str] = field(default_factory=list)

    @property
    def root_xz(self) -> np.ndarray:
        """``(frames, 2)`` the root's ground track, metres."""
        return self.positions[:, 0, [0, 2]].astype(np.float64)


@dataclass
class _StepGoal:
    start_xz: torch.Tensor   # (2,)
    start_yaw: torch.Tensor  # ()
    target_xz: torch.Tensor  # (2,)
    target_yaw: torch.Tensor  # ()
    previous_pose: torch.Tensor | None  # (63,) root-local joints of the previous clip's last frame
    previous_speed: torch.Tensor | None  # () its mean ground speed, m/s
    ahead: list[tuple[np.ndarray, float]] = field(default_factory=list)  # the next steps' (target_xz, target_yaw)


def step_cost(model, z: torch.Tensor, goal: _StepGoal, settings: FollowSettings
              ) -> tuple[torch.Tensor, dict[str, torch.Tensor]]:
    """``E(z)`` of the module doc for codes ``z`` ``(K, latent)`` → ``(K,)`` and its terms ``(K,)`` each."""
    features, duration = model.denormalize(model.net.decode(z))
    frames = model.autoencoder.decode(features, model.timeline_frames)  # (K, L, 66) time-normalized
    playback = (frames.shape[-2] - 1) / duration[:, None]  # frames per second of each clip
    root, yaw = integrate_root(frames, playback, goal.start_xz, goal.start_yaw)
    terms = {
        "position": ((root[:, -1] - goal.target_xz) ** 2).sum(-1) / settings.position_scale_m ** 2,
        "heading": wrap_angle_torch(yaw[:, -1] - goal.target_yaw) ** 2 / settings.heading_scale_rad ** 2,
        "prior": settings.prior_weight * 0.5 * (z ** 2).sum(-1),
    }
    if goal.previous_pose is not None:
        first = frames[:, 0, JOINT_DIMS].unflatten(-1, (NUM_JOINTS, 3))
        gap = ((first - goal.previous_pose.view(NUM_JOINTS, 3)) ** 2).sum(-1).mean(-1)
        terms["pose"] = gap / settings.pose_scale_m ** 2
        speed = frames[:, :-1, VELOCITY_DIMS].norm(dim=-1).mean(-1)
        terms["speed"] = (speed - goal.previous_speed) ** 2 / settings.speed_scale_mps ** 2
    return sum(terms.values()), terms


def _search(model, goal: _StepGoal, settings: FollowSettings, generator: torch.Generator
            ) -> tuple[torch.Tensor, float, float, dict[str, float]]:
    """Best-of-K prior codes, refined by Adam: ``(z (latent,), best candidate cost, final cost, terms)``."""
    z = torch.randn(settings.candidates, model.hparams.latent_dim, generator=generator)
    with torch.no_grad():
        cost, _ = step_cost(model, z, goal, settings)
    best = int(cost.argmin())
    start_cost = float(cost[best])
    z = z[best:best + 1].clone().requires_grad_(True)
    if settings.iterations:
        optimizer = torch.optim.Adam([z], lr=settings.lr)
        kept, kept_cost = z.detach().clone(), start_cost
        for _ in range(settings.iterations):
            optimizer.zero_grad()
            cost, _ = step_cost(model, z, goal, settings)
            value = float(cost.detach())
            if value < kept_cost:  # keep the best code seen (Adam may overshoot)
                kept, kept_cost = z.detach().clone(), value
            cost.sum().backward()
            optimizer.step()
        z = kept
    with torch.no_grad():
        cost, terms = step_cost(model, z.detach(), goal, settings)
    return z.detach()[0], start_cost, float(cost[0]), {k: float(v[0]) for k, v in terms.items()}


def _end_state(frames: np.ndarray, fps: float, start_xz: np.ndarray, start_yaw: float) -> tuple[np.ndarray, float]:
    root, yaw = integrate_root(torch.from_numpy(frames), fps, torch.from_numpy(start_xz), start_yaw)
    return root[-1].numpy(), float(yaw[-1])


def _append_decoded(motion: np.ndarray | None, decoded, blend_frames: int, fps: float, place_xz: np.ndarray,
                    place_yaw: float) -> tuple[np.ndarray, int, int, float, np.ndarray, float]:
    """Append one decoded clip (a batch of one) to ``motion`` ``(frames, 66)`` (or start it), the walk's root at
    ``(place_xz, place_yaw)`` before it. Returns the motion, the clip's first frame in it, the junction, the clip's
    mean ground speed (m/s) and where the root ends ``(xz, yaw)``."""
    clip = decoded.frames[0, : int(decoded.num_frames[0])].numpy().astype(np.float64)
    before = 0 if motion is None else len(motion) - 1
    motion, junction = append_clip(motion, clip, blend_frames)
    placed = motion[before:]
    speed = float(np.linalg.norm(placed[:-1, VELOCITY_DIMS], axis=-1).mean())
    end_xz, end_yaw = _end_state(placed, fps, place_xz, place_yaw)
    return motion, before, junction, speed, end_xz, end_yaw


def restitch(walk: SynthesizedMotion, decoders: list, latents: list[np.ndarray], settings: FollowSettings,
             start_yaw: float | None = None) -> SynthesizedMotion:
    """``walk`` with its steps' codes replaced by ``latents`` (one ``(d_i,)`` per step), each decoded by
    ``decoders[i]`` (``(1, d_i)`` codes → motion samples) and stitched as :func:`follow_path` stitches: the same
    primitives, targets and path, new clips, junctions and step ends (each step's costs are kept as searched)."""
    if len(decoders) != len(walk.steps) or len(latents) != len(walk.steps):
        raise ValueError(f"restitch needs one decoder and one code per step ({len(walk.steps)}), got "
                         f"{len(decoders)} and {len(latents)}")
    began = time.perf_counter()
    heading = float(walk.path.heading_at(0.0)) if start_yaw is None else float(start_yaw)
    start_xz = walk.path.start
    place_xz, place_yaw = start_xz.copy(), heading
    motion, junctions, steps = None, [], []
    for record, decode, latent in zip(walk.steps, decoders, latents):
        code = torch.from_numpy(np.array(latent))  # its own precision (the Morphable Graph's codes: float64)
        decoded = decode(code[None])
        motion, before, junction, _, place_xz, place_yaw = _append_decoded(
            motion, decoded, settings.blend_frames, walk.fps, place_xz, place_yaw)
        if steps:
            junctions.append(junction)
        steps.append(replace(record, start_frame=before, end_xz=[float(v) for v in place_xz],
                             end_yaw=float(place_yaw), duration_s=float(decoded.duration_s[0]),
                             latent=[float(v) for v in code]))
    positions = frames_to_positions(motion, walk.fps, start_xz, heading)
    return replace(walk, frames=motion.astype(np.float32), positions=positions.astype(np.float32),
                   junctions=junctions, steps=steps, seconds=walk.seconds + time.perf_counter() - began)


def _path_target(path: GroundPath, s: float) -> tuple[np.ndarray, float]:
    """The path's point (m) and heading (rad) ``s`` metres along it."""
    return path.point_at(s), float(path.heading_at(min(s, path.length - 1e-9)))


def check_turns(graph: MotionGraph, path: GroundPath) -> list[str]:
    """Warnings for stretches of ``path`` that turn more within one step length than any step can."""
    stances = [graph.profiles[p] for p in ("leftStance", "rightStance")]
    step_m = float(np.mean([p.length_m for p in stances]))
    reach = max(p.turn_rad for p in stances)
    turn = path.turn_per_length(step_m)
    worst = int(turn.argmax())
    if turn[worst] <= reach:
        return []
    message = (f"the path turns {math.degrees(turn[worst]):.0f}° within one step ({step_m:.2f} m) at "
               f"{path.arc[worst]:.2f} m along it; the sharpest step of the {graph.style} models turns "
               f"{math.degrees(reach):.0f}°: following it as closely as the steps reach")
    warnings.warn(message, SharpTurnWarning, stacklevel=3)
    return [message]


def follow_path(graph: MotionGraph, path: GroundPath, seed: int = 0, settings: FollowSettings | None = None,
                start_yaw: float | None = None) -> SynthesizedMotion:
    """Walk along ``path`` with the models of ``graph`` (see the module doc).

    Args:
        graph: the motion graph (its step profiles are measured here if missing).
        path: the ground path; the walk starts at its first point.
        seed: seeds the prior candidates (same seed, same walk).
        settings: :class:`FollowSettings`.
        start_yaw: initial heading, radians (default: the path's direction at its start).

    Returns:
        :class:`SynthesizedMotion`.
    """
    settings = settings or FollowSettings()
    began = time.perf_counter()
    if not graph.profiles:
        graph.profile(seed=0)
    notes = check_turns(graph, path)
    fps = graph.fps
    generator = torch.Generator().manual_seed(int(seed))
    start_xz = path.start
    heading = float(path.heading_at(0.0)) if start_yaw is None else float(start_yaw)
    place_xz, place_yaw = start_xz.copy(), heading
    motion: np.ndarray | None = None
    junctions: list[int] = []
    steps: list[StepRecord] = []
    primitive = graph.first(settings.first_foot)
    previous_speed: float | None = None
    while len(steps) < settings.max_steps:
        s0, _ = path.project(place_xz)
        remaining = path.length - float(s0)
        needed = int(round(remaining / graph.profiles[primitive].length_m))
        if needed < 1:
            break
        if needed == 1 and steps and not primitive.startswith("end"):
            primitive = graph.next(steps[-1].primitive, last=True)  # the last step: end primitive if modelled
        spacing = remaining / needed
        target_xz, target_yaw = _path_target(path, float(s0) + spacing)
        ahead = [_path_target(path, float(s0) + k * spacing) for k in range(2, min(needed, LOOKAHEAD_TARGETS + 1) + 1)]
        goal = _StepGoal(
            start_xz=torch.tensor(place_xz, dtype=torch.float32), start_yaw=torch.tensor(place_yaw),
            target_xz=torch.tensor(target_xz, dtype=torch.float32), target_yaw=torch.tensor(target_yaw),
            previous_pose=None if motion is None else torch.tensor(motion[-1, JOINT_DIMS], dtype=torch.float32),
            previous_speed=None if previous_speed is None else torch.tensor(previous_speed), ahead=ahead)
        model = graph.models[primitive]
        own_search = getattr(model, "search_step", None)  # e.g. a Morphable Graph primitive's MAP (eq. 4.9)
        z, start_cost, final_cost, terms = (own_search(goal, settings, generator) if own_search
                                            else _search(model, goal, settings, generator))
        decoded = model.decode_latent(z[None])
        motion, before, junction, previous_speed, place_xz, place_yaw = _append_decoded(
            motion, decoded, settings.blend_frames, fps, place_xz, place_yaw)
        if steps:
            junctions.append(junction)
        steps.append(StepRecord(
            primitive=primitive, start_frame=before, target_xz=[float(v) for v in target_xz],
            target_yaw=float(target_yaw), end_xz=[float(v) for v in place_xz], end_yaw=float(place_yaw),
            duration_s=float(decoded.duration_s[0]), cost_best_candidate=start_cost, cost_final=final_cost,
            terms=terms, latent=[float(v) for v in z], variant=str(getattr(model, "last_variant", ""))))
        log.debug("step %d %s: cost %.2f → %.2f, end %s", len(steps), primitive, start_cost, final_cost, place_xz)
        if primitive.startswith("end"):
            break
        primitive = graph.next(primitive)
    else:
        notes.append(f"stopped after max_steps={settings.max_steps} steps before the end of the path")
    if motion is None:
        raise PathError(f"the path ({path.length:.2f} m) is shorter than half a step "
                        f"({graph.profiles[primitive].length_m:.2f} m): nothing to walk; give a longer path")
    positions = frames_to_positions(motion, fps, start_xz, heading)
    return SynthesizedMotion(frames=motion.astype(np.float32), positions=positions.astype(np.float32), fps=fps,
                             junctions=junctions, steps=steps, path=path, style=graph.style,
                             seconds=time.perf_counter() - began, warnings=notes)
