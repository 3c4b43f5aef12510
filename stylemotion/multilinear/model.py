"""The class motion tensor of Krüger §4.1 / §3.3 with the root path, and synthesis from its mode coefficients.

A class's examples, each labelled by actor and style, are warped onto a reference (the example whose length is
closest to the mean; :mod:`.warping`) and turned into the project's 66-dim frames
(:func:`stylemotion.representation.positions_to_frames`: 63 root-local, facing-normalized joint coordinates in
metres, the root's ground velocity in m/s and its yaw rate in rad/s, at the reference timeline's fps). They form
``Θ`` of shape ``(66, f, a, s, r)`` (DOF, frames, actors, styles, repetitions), decomposed by the N-mode SVD
(:mod:`.decomposition`). Because the root's velocities are DOFs of the tensor, a synthesized motion carries its
own root path: :func:`stylemotion.representation.frames_to_positions` integrates it.

Synthesis (eq. 3.5): ``M = Ψ ×_3 αᵀU_3 ×_4 βᵀU_4 ×_5 γᵀU_5`` with ``Ψ = Φ ×_1 U_1 ×_2 U_2`` and weights
``α`` ``(a,)``, ``β`` ``(s,)``, ``γ`` ``(r,)`` over the actors, styles and repetitions; unit weights of the
untruncated model return an example, ``β = ½ (e_1 + e_2)`` blends two styles.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np
from tensorly.tenalg import multi_mode_dot

from stylemotion.ik import rest_offsets
from stylemotion.io.errors import UserInputError
from stylemotion.multilinear.decomposition import n_mode_svd, truncate
from stylemotion.multilinear.warping import Method, warp_function, warp_positions
from stylemotion.representation import FRAME_DIM, frames_to_positions, positions_to_frames

#: The natural modes, in the order of the tensor's modes 3, 4, 5.
NATURAL_MODES: tuple[str, ...] = ("actor", "style", "repetition")

Weights = Mapping[str, float] | Sequence[float] | np.ndarray | None


class TensorDesignError(UserInputError, ValueError):
    """Examples that do not fill a class tensor; the message names the class and the missing actor/style."""


@dataclass(frozen=True, eq=False)
class MultilinearModel:
    """A (possibly truncated) N-mode SVD of a class tensor ``(66, f, a, s, r)``.

    Attributes:
        label: the class.  actors, styles: names along modes 3 and 4.  repetitions: ``r``.
        core: ``Φ``, shape ``ranks``.  factors: ``U_1..U_5``, ``(dim_n, rank_n)``.
        reference: ``(f, 21, 3)`` the warping reference's positions (metres); its rest skeleton is the BVH
            skeleton of every synthesized motion.  fps: frames per second of the timeline.
        warping: the method that aligned the examples (:data:`stylemotion.multilinear.warping.METHODS`).
    """

    label: str
    actors: tuple[str, ...]
    styles: tuple[str, ...]
    repetitions: int
    core: np.ndarray
    factors: tuple[np.ndarray, ...]
    reference: np.ndarray
    fps: float
    warping: str

    @property
    def frames(self) -> int:
        return int(self.reference.shape[0])

    @property
    def dims(self) -> tuple[int, ...]:
        return tuple(int(f.shape[0]) for f in self.factors)

    @property
    def ranks(self) -> tuple[int, ...]:
        return tuple(int(s) for s in self.core.shape)

    @cached_property
    def psi(self) -> np.ndarray:
        """``Ψ = Φ ×_1 U_1 ×_2 U_2``: ``(66, f, rank_actor, rank_style, rank_repetition)``."""
        return multi_mode_dot(self.core, [self.factors[0], self.factors[1]], modes=[0, 1])

    @cached_property
    def natural_qr(self) -> tuple[np.ndarray, np.ndarray]:
        """``(Q, R)``: the thin QR factorization of Ψ's slices as columns, ``Q`` ``(66 f, k)`` and ``R`` ``(k, k)``
        with ``k = k_a k_s k_r`` (least-squares fits in the natural coefficient spaces work on ``R`` and ``Qᵀ x``)."""
        return np.linalg.qr(self.psi.reshape(self.psi.shape[0] * self.psi.shape[1], -1))

    def truncated(self, ranks: Sequence[int]) -> MultilinearModel:
        """The model with every mode cut to ``ranks`` (5 values, each ≤ the current rank)."""
        core, factors = truncate(self.core, self.factors, ranks)
        return replace(self, core=core, factors=factors)

    def weight_vector(self, mode: str, weights: Weights) -> np.ndarray:
        """The weight vector over a natural mode's entries: ``None`` is the mean (``1/d`` each); a mapping names
        entries (actor or style names, repetition indices as strings) and leaves the rest 0."""
        names = {"actor": self.actors, "style": self.styles,
                 "repetition": tuple(str(i) for i in range(self.repetitions))}[mode]
        if weights is None:
            return np.full(len(names), 1.0 / len(names))
        if isinstance(weights, Mapping):
            unknown = sorted(set(map(str, weights)) - set(names))
            if unknown:
                raise ValueError(f"{mode} weights name {unknown}; the {mode}s are {list(names)}")
            return np.array([float(weights.get(n, 0.0)) for n in names])
        w = np.asarray(weights, dtype=np.float64)
        if w.shape != (len(names),):
            raise ValueError(f"{mode} weights must have shape ({len(names)},), got {w.shape}")
        return w

    def synthesize_frames(self, actor: Weights = None, style: Weights = None,
                          repetition: Weights = None) -> np.ndarray:
        """Eq. 3.5: ``(f, 66)`` frames for actor, style and repetition weights (see :meth:`weight_vector`)."""
        rows = [self.weight_vector(m, w) @ u for m, w, u in zip(NATURAL_MODES, (actor, style, repetition),
                                                                  self.factors[2:])]
        return multi_mode_dot(self.psi, rows, modes=[2, 3, 4]).T

    def synthesize(self, actor: Weights = None, style: Weights = None, repetition: Weights = None,
                   start_xz: np.ndarray | None = None, start_yaw: float = 0.0) -> np.ndarray:
        """``(f, 21, 3)`` global positions (metres, Y up, at :attr:`fps`) of the synthesized motion, its root path
        integrated from the synthesized root velocities from ``start_xz`` ``(2,)`` facing ``start_yaw`` (rad)."""
        return frames_to_positions(self.synthesize_frames(actor, style, repetition), self.fps, start_xz, start_yaw)

    def rest_offsets(self) -> np.ndarray:
        """``(21, 3)`` the reference take's rest skeleton (metres): one skeleton for every exported motion."""
        return rest_offsets(self.reference)

    def warp(self, positions: np.ndarray, levels: int = 4, radius: int = 2) -> np.ndarray:
        """``(f, 66)`` frames of a motion ``(m, 21, 3)`` warped onto the reference timeline by :attr:`warping`."""
        w, _ = warp_function(self.reference, positions, self.fps, self.warping, levels, radius)
        return positions_to_frames(warp_positions(positions, w), self.fps)[0].astype(np.float64)


@dataclass(frozen=True)
class WarpStats:
    """What aligning the examples cost: ``cells`` DTW cost cells per example (``(a, s, r)``)."""

    cells: np.ndarray


def build_model(label: str, examples: Mapping[tuple[str, str], Sequence[np.ndarray]], fps: float,
                repetitions: int | None = None, warping: Method = "physics", levels: int = 4,
                radius: int = 2) -> tuple[MultilinearModel, np.ndarray, WarpStats]:
    """Warp a class's examples and decompose their tensor.

    Args:
        examples: ``(actor, style)`` → motions ``(frames ≥ 3, 21, 3)`` (metres, at ``fps``); every actor needs
            every style (a full design), each with ``repetitions`` motions (the first ones are used; ``None``:
            the smallest count).
        warping, levels, radius: see :func:`stylemotion.multilinear.warping.warp_function`.

    Returns:
        The untruncated :class:`MultilinearModel`, ``Θ`` ``(66, f, a, s, r)`` and the warping cost.

    Raises:
        TensorDesignError: an actor without a style another actor has, fewer than 2 examples in all, or a cell
            with fewer than ``repetitions`` motions.
    """
    actors = tuple(sorted({a for a, _ in examples}))
    styles = tuple(sorted({s for _, s in examples}))
    missing = [(a, s) for a in actors for s in styles if len(examples.get((a, s), ())) == 0]
    if missing:
        raise TensorDesignError(f"class {label!r}: no examples of actor/style {missing}; a tensor needs every "
                                f"actor in every style")
    counts = {k: len(v) for k, v in examples.items()}
    r = min(counts.values()) if repetitions is None else int(repetitions)
    short = {f"{a}/{s}": n for (a, s), n in counts.items() if n < max(r, 1)}
    if short or r < 1 or len(actors) * len(styles) * r < 2:
        raise TensorDesignError(f"class {label!r}: {short or counts} examples per actor/style; "
                                f"{r} repetitions of each and at least 2 examples in all are needed")
    chosen = [[[np.asarray(examples[(a, s)][k], dtype=np.float64) for k in range(r)] for s in styles]
              for a in actors]
    every = [m for per_actor in chosen for per_style in per_actor for m in per_style]
    mean_length = np.mean([len(m) for m in every])
    reference = every[int(np.argmin([abs(len(m) - mean_length) for m in every]))]
    f = len(reference)
    theta = np.empty((FRAME_DIM, f, len(actors), len(styles), r))
    cells = np.zeros((len(actors), len(styles), r), dtype=np.int64)
    for ai, per_actor in enumerate(chosen):
        for si, per_style in enumerate(per_actor):
            for k, motion in enumerate(per_style):
                w, cells[ai, si, k] = warp_function(reference, motion, fps, warping, levels, radius)
                theta[:, :, ai, si, k] = positions_to_frames(warp_positions(motion, w), fps)[0].T
    core, factors = n_mode_svd(theta)
    model = MultilinearModel(label, actors, styles, r, core, factors, reference, float(fps), warping)
    return model, theta, WarpStats(cells)
