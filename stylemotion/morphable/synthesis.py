"""Constrained synthesis with Morphable Graph primitives (Du §4.5.1, §4.5.3): MAP codes (eq. 4.9) by
Levenberg–Marquardt from the space-partitioning tree's candidate.

For one primitive and constraints ``c``, eq. 4.9 minimizes ``O(s, c) − ln p(s)``. Here as least squares
(scipy's ``least_squares(method="lm")``) over residuals:

* each constraint's error vector divided by ``σ_c`` (position: 3 values; orientation: the rotation vector
  from the reached to the target rotation times metres per radian; pose: 63 values over ``√21``);
* the prior: ``√λ · L_k⁻¹ (s − μ_k)`` for the mixture component ``k`` holding the tree's candidate, i.e.
  ``−ln p(s)`` up to a constant where that component dominates (the exact ``−ln p(s)`` is reported).

The start is the tree's best code (:meth:`~.tree.SpaceTree.search`), never a random draw.

**Path following.** :class:`MorphablePrimitive` wraps a model so that
:func:`stylemotion.synthesis.controller.follow_path` uses it like a VAE: the controller sets each step's
target (end position and heading from the median step length, the previous clip's last pose and speed
as the transition keyframe), calls :meth:`MorphablePrimitive.search_step`, decodes, stitches and cleans
up exactly as for the VAEs. The step residuals are the controller's cost terms (position, heading, pose,
speed, each over its scale in :class:`~stylemotion.synthesis.controller.FollowSettings`) and the prior.
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from stylemotion.config import ConfigError
from stylemotion.geometry import rotate_yaw, rotate_yaw_xz, wrap_angle
from stylemotion.morphable.constraints import KeyframeConstraint, constraint_errors, objective
from stylemotion.morphable.model import MorphableModel
from stylemotion.morphable.tree import SpaceTree
from stylemotion.representation import ROOT_JOINT, facing_yaw
from stylemotion.skeleton import NUM_JOINTS

log = logging.getLogger(__name__)


class UnreachableConstraintWarning(UserWarning):
    """A constraint is still missed by more than the tolerance after optimization."""


@dataclass
class MapSettings:
    """Settings of the MAP solve.

    Attributes:
        candidates: beam width of the tree search.
        constraint_scale_m: ``σ_c`` of keyframe constraints, metres.
        prior_weight: ``λ``.
        max_evaluations: objective evaluations LM may spend.
        tolerance_m: a constraint missed by more than this after the solve is reported.
    """

    candidates: int = 4
    constraint_scale_m: float = 0.02
    prior_weight: float = 1.0
    max_evaluations: int = 300
    tolerance_m: float = 0.05


@dataclass
class ConstrainedResult:
    """A MAP code and how well it meets its constraints.

    Attributes:
        latent: ``(d,)``.
        errors_m: each constraint's error (metres; orientations scaled) after the solve.
        start_errors_m: the same for the tree's candidate.
        cost, start_cost: the MAP objective ``½‖r‖²`` (module doc) of the result and of the tree's candidate
            (the result is the better of LM's end point and the candidate).
        neg_log_prior: ``−ln p(s)`` of the result.
        evaluations: tree evaluations + LM function evaluations.
        unreachable: messages naming the constraints missed by more than the tolerance.
    """

    latent: np.ndarray
    errors_m: list[float]
    start_errors_m: list[float]
    cost: float
    start_cost: float
    neg_log_prior: float
    evaluations: int
    unreachable: list[str] = field(default_factory=list)


def _tree(model: MorphableModel) -> SpaceTree:
    if model.tree is None:
        log.info("building the space-partitioning tree of %s (not saved with the model)", model.meta.get("primitive"))
        model.build_tree()
    return model.tree


def _prior_residual(model: MorphableModel, start: np.ndarray, weight: float):
    k = int(np.argmax(model.gmm.component_log_prob(start)))
    chol, mean = np.linalg.cholesky(model.gmm.covariances[k]), model.gmm.means[k]
    scale = np.sqrt(weight)

    def residual(s: np.ndarray) -> np.ndarray:
        return scale * np.linalg.solve(chol, s - mean)

    return residual


def constraint_residuals(model: MorphableModel, latent: np.ndarray, constraints: Sequence[KeyframeConstraint],
                         scale_m: float) -> np.ndarray:
    """``(r,)`` residual vector of one code's constraint errors over ``σ_c`` (see the module doc)."""
    need_rot = any(c.kind == "orientation" for c in constraints)
    out = model.canonical_positions(latent[None], rotations=need_rot)
    pos, rot = (out[0][0], out[1][0]) if need_rot else (out[0], None)
    parts = []
    for c in constraints:
        frame = int(round(c.frame * (model.length - 1)))
        if c.kind == "position":
            parts.append(pos[frame, c.joint_index] - c.target)
        elif c.kind == "pose":
            parts.append((pos[frame] - c.target).ravel() / np.sqrt(NUM_JOINTS))
        else:
            rel = rot[frame, c.joint_index].T @ c.target
            parts.append(Rotation.from_matrix(rel).as_rotvec() * c.orientation_scale_m)
    return np.concatenate(parts) / scale_m


def solve_constraints(model: MorphableModel, constraints: Sequence[KeyframeConstraint],
                      settings: MapSettings | None = None) -> ConstrainedResult:
    """The MAP code of eq. 4.9 for keyframe ``constraints`` (see the module doc). A constraint still missed by
    more than ``settings.tolerance_m`` is named in ``unreachable`` and warned about, with its residual."""
    settings = settings or MapSettings()
    if not constraints:
        raise ValueError("no constraint given")

    def errors(latent: np.ndarray) -> np.ndarray:
        need_rot = any(c.kind == "orientation" for c in constraints)
        out = model.canonical_positions(latent, rotations=need_rot)
        pos, rot = out if need_rot else (out, None)
        return constraint_errors(pos, rot, constraints, model.length)

    found = _tree(model).search(objective(model, constraints), settings.candidates)
    prior = _prior_residual(model, found.latent, settings.prior_weight)

    def residuals(s: np.ndarray) -> np.ndarray:
        return np.concatenate([constraint_residuals(model, s, constraints, settings.constraint_scale_m), prior(s)])

    fit = least_squares(residuals, found.latent, method="lm", max_nfev=settings.max_evaluations)
    start_cost = 0.5 * float((residuals(found.latent) ** 2).sum())
    best, cost = (fit.x, float(fit.cost)) if fit.cost <= start_cost else (found.latent, start_cost)
    final = errors(best[None])[0]
    start = errors(found.latent[None])[0]
    missed = [f"{c.kind} constraint on {c.joint or 'the pose'} at frame {c.frame:g}: residual {e:.3f} m "
              f"(tolerance {settings.tolerance_m} m; the tree's candidate missed it by {s:.3f} m)"
              for c, e, s in zip(constraints, final, start) if e > settings.tolerance_m]
    for message in missed:
        warnings.warn(f"unreachable keyframe: {message}", UnreachableConstraintWarning, stacklevel=2)
    return ConstrainedResult(best, [float(e) for e in final], [float(e) for e in start], cost, start_cost,
                             float(-model.gmm.log_prob(best)), found.evaluations + int(fit.nfev), missed)


# ---------------------------------------------------------------------------------------------
# Path following through the VAE controller


def step_states(model: MorphableModel, latent: np.ndarray) -> dict[str, np.ndarray]:
    """What a step does, for ``(m, d)`` codes: ``displacement`` ``(m, 2)`` root ground displacement (m) in the
    clip's first facing frame, ``turn`` ``(m,)`` heading change (rad), ``first_pose`` ``(m, 63)`` the first
    frame's root-local joints (as in the 66-dim frames), ``speed`` ``(m,)`` mean ground speed (m/s)."""
    _, warp = model.coefficients(latent)
    duration = model.warps(warp)[:, -1] / model.fps
    pos = model.canonical_positions(latent)
    rate = (model.length - 1) / float(np.mean(duration))
    yaw = facing_yaw(pos, rate)
    root = pos[:, :, ROOT_JOINT][..., [0, 2]]
    turn = np.unwrap(yaw, axis=-1)
    ground = pos[:, 0, ROOT_JOINT].copy()
    ground[:, 1] = 0.0
    first = rotate_yaw(pos[:, 0] - ground[:, None], -yaw[:, :1])
    return {"displacement": rotate_yaw_xz(root[:, -1] - root[:, 0], -yaw[:, 0]),
            "turn": turn[:, -1] - turn[:, 0], "first_pose": first.reshape(len(pos), -1),
            "speed": np.linalg.norm(np.diff(root, axis=1), axis=-1).sum(-1) / duration}


class MorphablePrimitive:
    """A :class:`MorphableModel` as a node of :class:`~stylemotion.synthesis.graph.MotionGraph`."""

    def __init__(self, model: MorphableModel, settings: MapSettings | None = None):
        self.model = model
        self.settings = settings or MapSettings()
        self.fps = model.fps
        self.timeline_frames = model.length

    def eval(self) -> MorphablePrimitive:
        return self

    def requires_grad_(self, flag: bool = True) -> MorphablePrimitive:
        return self

    def sample(self, n: int, seed: int = 0):
        return self.model.sample(n, seed)

    def decode_latent(self, latent):
        return self.model.decode_latent(latent)

    def _step_residuals(self, latent: np.ndarray, goal, follow) -> np.ndarray:
        """``(m, r)`` the controller's cost terms as residuals (without the prior)."""
        state = step_states(self.model, latent)
        start_xz, start_yaw = goal.start_xz.double().numpy(), float(goal.start_yaw)
        end = start_xz + rotate_yaw_xz(state["displacement"], start_yaw)
        parts = [(end - goal.target_xz.double().numpy()) / follow.position_scale_m,
                 wrap_angle(start_yaw + state["turn"] - float(goal.target_yaw))[:, None] / follow.heading_scale_rad]
        if goal.previous_pose is not None:
            gap = state["first_pose"] - goal.previous_pose.double().numpy()
            parts.append(gap / (follow.pose_scale_m * np.sqrt(NUM_JOINTS)))
            parts.append((state["speed"] - float(goal.previous_speed))[:, None] / follow.speed_scale_mps)
        return np.concatenate(parts, axis=1)

    def search_step(self, goal, follow, generator: torch.Generator | None = None
                    ) -> tuple[torch.Tensor, float, float, dict[str, float]]:
        """One step of :func:`~stylemotion.synthesis.controller.follow_path`: the tree's best code for the
        step's target, refined by LM on eq. 4.9. Returns ``(code, candidate cost, final cost, terms)``; costs
        are ``½‖r‖²`` of the step residuals plus ``λ (−ln p(s))`` (``λ``: ``follow.prior_weight``)."""
        model, lam = self.model, follow.prior_weight
        offset = model.gmm.max_log_prob()

        def total(latent: np.ndarray) -> np.ndarray:
            r = self._step_residuals(latent, goal, follow)
            return 0.5 * (r ** 2).sum(-1) + lam * (offset - model.gmm.log_prob(latent))

        found = _tree(model).search(total, self.settings.candidates)
        prior = _prior_residual(model, found.latent, lam)
        fit = least_squares(lambda s: np.concatenate([self._step_residuals(s[None], goal, follow)[0], prior(s)]),
                            found.latent, method="lm", max_nfev=self.settings.max_evaluations)
        final = float(total(fit.x[None])[0])
        best = fit.x if final <= found.cost else found.latent
        r = self._step_residuals(best[None], goal, follow)[0]
        terms = {"position": float((r[:2] ** 2).sum()), "heading": float(r[2] ** 2),
                 "prior": float(lam * (offset - model.gmm.log_prob(best))), "evaluations": float(found.evaluations
                                                                                                 + fit.nfev)}
        if goal.previous_pose is not None:
            terms["pose"], terms["speed"] = float((r[3:-1] ** 2).sum()), float(r[-1] ** 2)
        return torch.from_numpy(best.astype(np.float32)), float(found.cost), min(final, found.cost), terms


def load_morphable_graph(models: Mapping[str, str | Path], action: str = "walk", settings: MapSettings | None = None):
    """A :class:`~stylemotion.synthesis.graph.MotionGraph` of Morphable Graph primitives from
    ``{primitive: model file or run folder}`` (``walk_leftStance`` or ``leftStance``)."""
    from stylemotion.synthesis.graph import MotionGraph, _short

    if not models:
        raise ConfigError("model=morphable needs +models.walk_leftStance=<run folder or model.npz> "
                          "+models.walk_rightStance=<…>")
    loaded, sources = {}, {}
    for key, path in sorted(models.items()):
        primitive = _short(str(key), action)
        try:
            model = MorphableModel.load(path)
        except (OSError, ValueError, KeyError) as err:
            raise ConfigError(f"models.{key}={path}: {err}") from err
        have = f"{model.meta.get('action')}_{model.meta.get('primitive')}"
        if have != f"{action}_{primitive}":
            raise ConfigError(f"models.{key}={path} holds a {have} model, not {action}_{primitive}")
        loaded[primitive], sources[primitive] = MorphablePrimitive(model, settings), str(model.meta["path"])
    styles = {m.model.meta.get("style") for m in loaded.values()}
    return MotionGraph(action=action, style="/".join(sorted(str(s) for s in styles)), models=loaded, sources=sources)
