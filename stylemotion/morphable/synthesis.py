"""Constrained synthesis with Morphable Graph primitives (Du §4.5.1, §4.5.3): MAP codes (eq. 4.9) by
Levenberg–Marquardt from the space-partitioning tree's candidate.

For one primitive and constraints ``c``, eq. 4.9 minimizes ``O(s, c) − ln p(s)``. Here as least squares
(scipy's ``least_squares(method="lm")``) over residuals:

* each constraint's error vector divided by ``σ_c`` (position: 3 values; orientation: the rotation vector
  from the reached to the target rotation times metres per radian; pose: 63 values over ``√21``);
* the prior: ``√λ · L_k⁻¹ (s − μ_k)`` for the mixture component ``k`` holding the tree's candidate, i.e.
  ``−ln p(s)`` up to a constant where that component dominates (the exact ``−ln p(s)`` is reported).

For keyframe constraints (:func:`solve_constraints`) the start is the tree's best code: its branch-and-bound
search over keyframe boxes for constraints at the primitive's first or last frame, its beam search otherwise
(:func:`.bounds.best_code`).

**Path following.** :class:`MorphablePrimitive` wraps a model so that
:func:`stylemotion.synthesis.controller.follow_path` uses it like a VAE: the controller sets each step's
target (end position and heading from the median step length, the previous clip's last pose and speed
as the transition keyframe), calls :meth:`MorphablePrimitive.search_step`, decodes, stitches and cleans
up exactly as for the VAEs. The step residuals are the controller's cost terms (position, heading, pose,
speed, each over its scale in :class:`~stylemotion.synthesis.settings.FollowSettings`) and the prior.

**Walks that vary (§4.6.3).** A step's start is drawn at random, as the thesis does: ``random_starts`` codes
drawn from the primitive's mixture (the prior itself, by the walk's seeded generator), the cheapest under the
step's objective is the start. As in the thesis' authors' implementation, a start that already meets the step
(its step residual cost ``½‖r‖²`` without the prior at most ``accept_cost``) is kept as drawn; otherwise LM refines
it (``accept_cost = 1``, the default chosen on a validation path with line 9 after the walk; 0 refines every
start, the choice before line 9 was built). LM converges to
nearly the same MAP code from any start of one mixture component, so refined walks differ where the draws fall in
other components or basins, and from then on through the previous step's pose and speed; ``accept_cost`` and
``prior_centre = "start"`` keep more of the draw. One seed gives one walk.
``random_starts = 0`` takes the tree's beam-search candidate instead (deterministic: every seed, the same walk).
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import torch
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from stylemotion.geometry import rotate_yaw_xz, wrap_angle
from stylemotion.morphable.bounds import MAX_EVALUATIONS, best_code
from stylemotion.morphable.constraints import KeyframeConstraint, constraint_errors
from stylemotion.morphable.lookahead import MeanStep, choose, mean_step, step_states
from stylemotion.morphable.model import MorphableModel
from stylemotion.skeleton import NUM_JOINTS

log = logging.getLogger(__name__)


class UnreachableConstraintWarning(UserWarning):
    """A constraint is still missed by more than the tolerance after optimization."""


@dataclass
class MapSettings:
    """Settings of the MAP solve.

    Attributes:
        candidates: beam width of the tree's beam search (path steps; constraints off the keyframes).
        tree_evaluations: codes the tree's branch-and-bound search may evaluate for keyframe constraints
            (:func:`.bounds.best_code`).
        constraint_scale_m: ``σ_c`` of keyframe constraints, metres (10 mm: chosen among 1–50 mm on validation
            hand targets by the fewest failures — missed by more than ``tolerance_m``, or met by a code off the
            mixture —, suite ``morphable``; smaller values meet far targets with implausible codes).
        prior_weight: ``λ``.
        max_evaluations: objective evaluations LM may spend.
        tolerance_m: a constraint missed by more than this after the solve is reported.
        lookahead_steps: ``T``, steps over which a primitive's variants are compared (§4.5.1; 1 = greedy, the
            default: chosen among 1–3 on a validation path, a corner, by suite ``morphable --lookahead``).
        random_starts: codes drawn from the mixture per path step, the cheapest of them LM's start (§4.6.3: another
            seed, another walk). 100: the value of the thesis' authors' implementation (``n_random_samples``),
            kept, not tuned. 0: the tree's candidate (the same walk for every seed).
        accept_cost: a random start whose step residual cost (``½‖r‖²`` of the position, heading, pose and speed
            residuals over their ``follow.*`` scales, without the prior) is at most this is kept without LM
            (the authors' implementation's ``start_error_threshold``); 0: every start is refined. 1: chosen with
            ``prior_centre`` on a validation path, a corner, by suite ``morphable_variation`` with line 9 after
            each walk (without line 9 the same rule had chosen 0).
        joint_evaluations: after the walk, Algorithm 1's line 9: LM on the codes of all steps together
            (:mod:`stylemotion.synthesis.joint_walk`), at most this many objective evaluations; 0: off (the walk as
            searched step by step). 5: chosen among 0, 5, 10, 20, 40 and 80 on validation paths (suite
            ``morphable``'s corner and suite ``synthesis``'s random splines) by suite ``morphable_joint``; LM has
            nearly converged there by 5 (larger budgets score within 0.01; a first run with ``accept_cost`` 0
            chose 10).
        prior_centre: where LM's prior residual ``√λ L_k⁻¹ (s − c)`` is centred: ``mixture`` (``c = μ_k``, eq. 4.9,
            the thesis') or ``start`` (``c`` = the drawn start: LM meets the step and keeps the draw where the step
            leaves the code free, a perturb-and-MAP draw; the prior still counts in the costs compared).
    """

    candidates: int = 4
    tree_evaluations: int = MAX_EVALUATIONS
    constraint_scale_m: float = 0.01
    prior_weight: float = 1.0
    max_evaluations: int = 300
    tolerance_m: float = 0.05
    lookahead_steps: int = 1
    random_starts: int = 100
    accept_cost: float = 1.0
    prior_centre: str = "mixture"
    joint_evaluations: int = 5

    def __post_init__(self) -> None:
        if self.candidates < 1 or self.tree_evaluations < 1 or self.max_evaluations < 1 or self.lookahead_steps < 1:
            raise ValueError(f"MapSettings need candidates, tree_evaluations, max_evaluations and lookahead_steps "
                             f"≥ 1; got {self}")
        if self.prior_centre not in ("mixture", "start"):
            raise ValueError(f"MapSettings.prior_centre is 'mixture' or 'start', got {self.prior_centre!r}")
        if self.joint_evaluations < 0:
            raise ValueError(f"MapSettings need joint_evaluations ≥ 0 (0: off); got {self.joint_evaluations}")
        if self.random_starts < 0 or not self.accept_cost >= 0:
            raise ValueError(f"MapSettings need random_starts ≥ 0 (0: the tree's candidate) and accept_cost ≥ 0; "
                             f"got {self}")
        if not self.constraint_scale_m > 0 or not self.tolerance_m > 0 or self.prior_weight < 0:
            raise ValueError(f"MapSettings need constraint_scale_m > 0, tolerance_m > 0, prior_weight ≥ 0; got {self}")


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


def _prior_residual(model: MorphableModel, start: np.ndarray, weight: float, centre: np.ndarray | None = None):
    k = int(np.argmax(model.gmm.component_log_prob(start)))
    chol = np.linalg.cholesky(model.gmm.covariances[k])
    mean = model.gmm.means[k] if centre is None else centre
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

    found = best_code(model, constraints, settings.candidates, settings.tree_evaluations)
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


class MorphablePrimitive:
    """One or more :class:`MorphableModel` variants of a primitive as a node of
    :class:`~stylemotion.synthesis.graph.MotionGraph`.

    With several variants (e.g. the turn variants of a stance, :mod:`.variants`) each step first chooses one by
    the look-ahead of §4.5.1 (:mod:`.lookahead`, over ``settings.lookahead_steps`` steps and the variants of the
    nodes that follow, see :func:`stylemotion.synthesis.morphable_graph.link_graph`), then searches its code.
    ``last_variant`` names the variant of the last step searched; :meth:`decode_latent` decodes with it."""

    def __init__(self, model: MorphableModel | Sequence[MorphableModel], settings: MapSettings | None = None,
                 names: Sequence[str] | None = None):
        models = [model] if isinstance(model, MorphableModel) else list(model)
        if not models:
            raise ValueError("a Morphable Graph node needs at least one model")
        names = list(names) if names is not None else _variant_names(models)
        if len(names) != len(models) or len(set(names)) != len(names):
            raise ValueError(f"need one distinct name per variant, got {names} for {len(models)} models")
        self.variants: dict[str, MorphableModel] = dict(zip(names, models))
        self.model = models[0]
        self.settings = settings or MapSettings()
        self.fps = self.model.fps
        self.timeline_frames = self.model.length
        self.last_variant = names[0]
        self.following: list[MorphablePrimitive] = []  # the nodes of the next steps (synthesis.morphable_graph)
        self._mean_steps = None

    def eval(self) -> MorphablePrimitive:
        return self

    def requires_grad_(self, flag: bool = True) -> MorphablePrimitive:
        return self

    def sample(self, n: int, seed: int = 0):
        """``n`` samples spread evenly over the variants (what the step profile measures). Variants differ in
        timeline, coefficients and latent size, so a several-variant node's samples carry the motions
        (positions, frames, durations) and, where their shapes differ, empty features, normalized frames and
        codes."""
        from stylemotion.morphable.model import concat_samples

        counts = np.diff(np.linspace(0, n, len(self.variants) + 1).round().astype(int))
        parts = [m.sample(int(c), seed) for m, c in zip(self.variants.values(), counts) if c > 0]
        if len(parts) == 1:
            return parts[0]
        for name in ("features", "normalized_frames", "latent"):
            if len({tuple(getattr(p, name).shape[1:]) for p in parts}) > 1:
                parts = [replace(p, **{name: getattr(p, name).reshape(len(p), -1)[:, :0]}) for p in parts]
        return concat_samples(parts)

    def decode_latent(self, latent):
        return self.variants[self.last_variant].decode_latent(latent)

    def mean_steps(self) -> list[MeanStep]:
        if self._mean_steps is None:
            self._mean_steps = [mean_step(m, name) for name, m in self.variants.items()]
        return self._mean_steps

    def choose_variant(self, goal, follow) -> str:
        """The variant for the step of ``goal`` (module doc of :mod:`.lookahead`)."""
        if len(self.variants) == 1:
            return self.last_variant
        nodes = [self] + self.following[:self.settings.lookahead_steps - 1]
        options = [n.mean_steps() for n in nodes]
        targets = [(goal.target_xz.double().numpy(), float(goal.target_yaw))] + list(goal.ahead)
        choice = choose(options, goal.start_xz.double().numpy(), float(goal.start_yaw), targets,
                        follow.position_scale_m, follow.heading_scale_rad)
        return options[0][choice.index].name

    def search_step(self, goal, follow, generator: torch.Generator | None = None
                    ) -> tuple[torch.Tensor, float, float, dict[str, float]]:
        """One step of :func:`~stylemotion.synthesis.controller.follow_path`: the variant chosen by look-ahead,
        then the best of ``settings.random_starts`` codes drawn from its mixture by ``generator`` (or, with 0 or
        no generator, the tree's best code) for the step's target, refined by LM on eq. 4.9. Returns ``(code,
        candidate cost, final cost, terms)``; costs are ``½‖r‖²`` of the step residuals plus ``λ (−ln p(s))``
        (``λ``: ``follow.prior_weight``)."""
        self.last_variant = self.choose_variant(goal, follow)
        rng = None
        if generator is not None and self.settings.random_starts > 0:
            rng = np.random.default_rng(int(torch.randint(0, 2 ** 62, (1,), generator=generator)))
        return _map_step(self.variants[self.last_variant], goal, follow, self.settings, rng)


def _variant_names(models: Sequence[MorphableModel]) -> list[str]:
    names = []
    for i, m in enumerate(models):
        name = str(m.meta.get("variant") or Path(str(m.meta.get("path", f"variant{i}"))).parent.name or f"variant{i}")
        names.append(name if name not in names else f"{name}_{i}")
    return names


def _step_residuals(model: MorphableModel, latent: np.ndarray, goal, follow) -> np.ndarray:
    """``(m, r)`` the controller's cost terms as residuals (without the prior)."""
    state = step_states(model, latent)
    start_xz, start_yaw = goal.start_xz.double().numpy(), float(goal.start_yaw)
    end = start_xz + rotate_yaw_xz(state["displacement"], start_yaw)
    parts = [(end - goal.target_xz.double().numpy()) / follow.position_scale_m,
             wrap_angle(start_yaw + state["turn"] - float(goal.target_yaw))[:, None] / follow.heading_scale_rad]
    if goal.previous_pose is not None:
        gap = state["first_pose"] - goal.previous_pose.double().numpy()
        parts.append(gap / (follow.pose_scale_m * np.sqrt(NUM_JOINTS)))
        parts.append((state["speed"] - float(goal.previous_speed))[:, None] / follow.speed_scale_mps)
    return np.concatenate(parts, axis=1)


def random_start(model: MorphableModel, objective, draws: int, rng: np.random.Generator
                 ) -> tuple[np.ndarray, float]:
    """The cheapest of ``draws`` codes drawn from ``model``'s mixture under ``objective`` (``(m, d)`` codes →
    ``(m,)`` costs): §4.6.3's random initial code. Returns ``(code (d,), its cost)``."""
    codes = model.gmm.sample(draws, rng)
    costs = objective(codes)
    best = int(np.argmin(costs))
    return codes[best], float(costs[best])


def _map_step(model: MorphableModel, goal, follow, settings: MapSettings, rng: np.random.Generator | None = None
              ) -> tuple[torch.Tensor, float, float, dict[str, float]]:
    """The start (the best of ``settings.random_starts`` mixture draws by ``rng``, else the tree's best code) for
    one step, refined by LM (see :meth:`MorphablePrimitive.search_step`)."""
    lam = follow.prior_weight
    offset = model.gmm.max_log_prob()

    def total(latent: np.ndarray) -> np.ndarray:
        r = _step_residuals(model, latent, goal, follow)
        return 0.5 * (r ** 2).sum(-1) + lam * (offset - model.gmm.log_prob(latent))

    refine = True
    if rng is not None and settings.random_starts > 0:
        start, start_cost = random_start(model, total, settings.random_starts, rng)
        spent = settings.random_starts
        refine = 0.5 * float((_step_residuals(model, start[None], goal, follow) ** 2).sum()) > settings.accept_cost
    else:
        found = model.ensure_tree().search(total, settings.candidates)
        start, start_cost, spent = found.latent, float(found.cost), found.evaluations
    best, final = start, start_cost
    if refine:
        prior = _prior_residual(model, start, lam, start if settings.prior_centre == "start" else None)
        fit = least_squares(lambda s: np.concatenate([_step_residuals(model, s[None], goal, follow)[0], prior(s)]),
                            start, method="lm", max_nfev=settings.max_evaluations)
        final = float(total(fit.x[None])[0])
        best = fit.x if final <= start_cost else start
        spent += fit.nfev
    r = _step_residuals(model, best[None], goal, follow)[0]
    terms = {"position": float((r[:2] ** 2).sum()), "heading": float(r[2] ** 2),
             "prior": float(lam * (offset - model.gmm.log_prob(best))),
             "evaluations": float(spent), "refined": float(refine)}
    if goal.previous_pose is not None:
        terms["pose"], terms["speed"] = float((r[3:-1] ** 2).sum()), float(r[-1] ** 2)
    return torch.from_numpy(best.astype(np.float32)), start_cost, min(final, start_cost), terms
