"""Graph walk with look-ahead (Du §4.5.1): which of a step's competing primitives to take.

Where several primitives may take the next step (here: the turn variants of a stance, :mod:`.variants`),
the thesis enumerates every sequence of options over the next ``T`` steps, evaluates each with the *mean
motion* of its primitives against the steps' constraints (eq. 4.2), and takes the first primitive of the best
sequence; the chosen primitive's code is then searched and optimized as usual (tree + MAP).

Each option is summarized by what its mean motion does in one step (:class:`MeanStep`: the root's ground
displacement in the step's first facing frame, and the heading change). A sequence is chained from where the
walk stands, and its cost is the step targets' error, each term over the path follower's scales::

    Σ_k ‖p_k − p*_k‖² / σ_p² + wrap(θ_k − θ*_k)² / σ_θ²

With ``T = 1`` this is the greedy choice of the option whose mean step lands closest to the current target.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from stylemotion.geometry import rotate_yaw, rotate_yaw_xz, wrap_angle
from stylemotion.representation import ROOT_JOINT, facing_yaw
from stylemotion.skeleton import NUM_JOINTS

#: Largest number of option sequences enumerated (the look-ahead is shortened to stay below it).
MAX_SEQUENCES = 4096


def step_states(model, latent: np.ndarray) -> dict[str, np.ndarray]:
    """What a step does, for ``(m, d)`` codes of a :class:`~.model.MorphableModel`: ``displacement`` ``(m, 2)``
    root ground displacement (m) in the clip's first facing frame, ``turn`` ``(m,)`` heading change (rad),
    ``first_pose`` ``(m, 63)`` the first frame's root-local joints (as in the 66-dim frames), ``speed``
    ``(m,)`` mean ground speed (m/s)."""
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
            "turn": turn[:, -1] - turn[:, 0], "first_pose": first.reshape(len(pos), NUM_JOINTS * 3),
            "speed": np.linalg.norm(np.diff(root, axis=1), axis=-1).sum(-1) / duration}


@dataclass(frozen=True)
class MeanStep:
    """One option's mean motion as a step: ``displacement`` ``(2,)`` metres in its first facing frame
    (x: to the left, z: forward), ``turn`` radians (positive: to the left)."""

    name: str
    displacement: np.ndarray
    turn: float


def mean_step(model, name: str) -> MeanStep:
    """The :class:`MeanStep` of a model's mean motion (the decoded mean of its latent mixture)."""
    mean = (model.gmm.weights[:, None] * model.gmm.means).sum(0)
    state = step_states(model, mean[None])
    return MeanStep(name, state["displacement"][0].astype(np.float64), float(state["turn"][0]))


@dataclass(frozen=True)
class Choice:
    """The chosen option of the first step, the cost of the best sequence starting with each option (same
    order as the options), and the best sequence's option names."""

    index: int
    first_costs: list[float]
    sequence: list[str]


def choose(options: Sequence[Sequence[MeanStep]], start_xz: np.ndarray, start_yaw: float,
           targets: Sequence[tuple[np.ndarray, float]], position_scale_m: float, heading_scale_rad: float
           ) -> Choice:
    """The best first option (module doc): ``options[k]`` are the primitives that may take step ``k`` (as
    many steps as ``targets``; extra options are ignored), chained from ``(start_xz, start_yaw)``."""
    steps = min(len(options), len(targets))
    if steps < 1 or any(len(o) == 0 for o in options[:steps]):
        raise ValueError(f"need at least one target and one option per step: {len(targets)} targets, "
                         f"options per step {[len(o) for o in options]}")
    while steps > 1 and np.prod([len(o) for o in options[:steps]]) > MAX_SEQUENCES:
        steps -= 1
    best = np.full(len(options[0]), np.inf)
    best_sequence: dict[int, list[str]] = {}
    for sequence in itertools.product(*[range(len(o)) for o in options[:steps]]):
        xz, yaw, cost = np.asarray(start_xz, dtype=np.float64), float(start_yaw), 0.0
        for k, i in enumerate(sequence):
            step = options[k][i]
            xz = xz + rotate_yaw_xz(step.displacement, yaw)
            yaw = yaw + step.turn
            target_xz, target_yaw = targets[k]
            cost += float(((xz - np.asarray(target_xz)) ** 2).sum()) / position_scale_m ** 2
            cost += float(wrap_angle(yaw - target_yaw)) ** 2 / heading_scale_rad ** 2
        if cost < best[sequence[0]]:
            best[sequence[0]] = cost
            best_sequence[sequence[0]] = [options[k][i].name for k, i in enumerate(sequence)]
    index = int(np.argmin(best))
    return Choice(index, [float(c) for c in best], best_sequence[index])
