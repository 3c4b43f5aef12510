"""Class motion tensors (Krüger §3.3, §4.1; Vasilescu & Terzopoulos' N-mode SVD).

A class's example motions, brought to one timeline, form a tensor ``Θ`` of shape
``(DOF, frames, styles, repetitions)``: the DOF mode holds the 63 root-local joint coordinates of a frame
(metres, the first 63 values of :mod:`stylemotion.representation`'s 66-dim frames: facing-normalized, so no
rigid alignment is needed before comparing), the frame mode the ``f`` frames of the reference timeline, and the
natural modes the styles (sub-classes) and repetitions. Bandai has no actor label, so there is no actor mode.

Time warping: every example is warped onto the reference (the example closest to the mean length, resampled
to that length) by DTW on those coordinates (:func:`stylemotion.annotate.templates.warp_to`).

Decomposition (eq. 3.3): the N-mode SVD of :mod:`stylemotion.multilinear.decomposition` (shared with the
multilinear synthesis of Krüger §4.1), truncated to ``ranks[n]``. The technical modes are folded into
``Ψ = Φ ×_1 U_1 ×_2 U_2`` (eq. 3.4), and a motion is synthesized from weight vectors ``β`` (styles) and
``γ`` (repetitions) as ``M = Ψ ×_3 βᵀU_3 ×_4 γᵀU_4`` (eq. 3.5); a unit ``β = e_s``, ``γ = e_r`` of the
untruncated tensor returns example ``(s, r)``.

Parametrization (eq. 3.6): a segment is warped to the reference length and ``(β, γ)`` minimize the squared
distance of all its coordinates to ``M``, each weight in ``[−0.2, 1.2]``. ``M`` is linear in ``β`` for fixed
``γ`` and vice versa, so the problem is solved by alternating bounded linear least squares
(``scipy.optimize.lsq_linear``, on the QR triangle of each block's matrix) from uniform weights. The
segment's style is the largest ``β``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.optimize import lsq_linear
from tensorly.tenalg import multi_mode_dot
from threadpoolctl import threadpool_limits

from stylemotion.annotate.templates import resample_length, warp_to
from stylemotion.io.errors import UserInputError
from stylemotion.multilinear.decomposition import n_mode_svd, truncate
from stylemotion.representation import positions_to_frames
from stylemotion.skeleton import NUM_JOINTS

#: Bounds of every mode weight in the parametrization (thesis §3.3.2).
WEIGHT_BOUNDS = (-0.2, 1.2)
DOF = NUM_JOINTS * 3


class TensorInputError(UserInputError, ValueError):
    """Examples a motion tensor cannot be built from; the message names the class, style and count."""


def pose_coordinates(positions: np.ndarray, fps: float) -> np.ndarray:
    """``(frames, 63)`` root-local, facing-normalized joint coordinates (metres) of ``(frames, 21, 3)``."""
    return positions_to_frames(np.asarray(positions, dtype=np.float64), fps)[0][:, :DOF]


@dataclass(frozen=True)
class MotionTensor:
    """An N-mode SVD of a class motion tensor.

    Attributes:
        label: the class.  styles: names along the style mode.  repetitions: its size.
        reference: ``(frames, 63)`` the reference timeline's coordinates (warping target).
        core: ``Φ``, shape ``ranks``.  factors: ``U_1..U_4``, ``(dim_n, rank_n)``.
        fps: frames per second of the examples.
    """

    label: str
    styles: tuple[str, ...]
    repetitions: int
    reference: np.ndarray
    core: np.ndarray
    factors: tuple[np.ndarray, ...]
    fps: float

    @property
    def frames(self) -> int:
        return int(self.reference.shape[0])

    @property
    def ranks(self) -> tuple[int, ...]:
        return tuple(int(s) for s in self.core.shape)

    @property
    def nbytes(self) -> int:
        """Memory of the core and the factor matrices, bytes (float64)."""
        return int(self.core.nbytes + sum(f.nbytes for f in self.factors))

    @property
    def psi(self) -> np.ndarray:
        """``Ψ = Φ ×_1 U_1 ×_2 U_2``: ``(63, frames, rank_style, rank_rep)``."""
        return multi_mode_dot(self.core, [self.factors[0], self.factors[1]], modes=[0, 1])

    @cached_property
    def examples(self) -> np.ndarray:
        """``Ψ ×_3 U_3 ×_4 U_4``: ``(63 · frames, styles, repetitions)``, the examples as the (possibly
        truncated) tensor reproduces them; eq. 3.5 is ``Σ_s Σ_r β_s γ_r`` of its columns."""
        e = multi_mode_dot(self.psi, [self.factors[2], self.factors[3]], modes=[2, 3])
        return np.ascontiguousarray(e.reshape(-1, e.shape[2], e.shape[3]))

    def reconstruction(self) -> np.ndarray:
        """``(styles, repetitions, frames, 63)``: every example as this tensor synthesizes it (unit weights)."""
        e = self.examples.reshape(DOF, self.frames, len(self.styles), self.repetitions)
        return np.ascontiguousarray(np.transpose(e, (2, 3, 1, 0)))

    def synthesize(self, style_weights: np.ndarray, repetition_weights: np.ndarray) -> np.ndarray:
        """Eq. 3.5: ``(frames, 63)`` coordinates for ``β`` ``(styles,)`` and ``γ`` ``(repetitions,)``."""
        b = np.asarray(style_weights, dtype=np.float64) @ self.factors[2]
        g = np.asarray(repetition_weights, dtype=np.float64) @ self.factors[3]
        return multi_mode_dot(self.psi, [b, g], modes=[2, 3]).T

    def truncated(self, ranks: Sequence[int]) -> MotionTensor:
        """The tensor with every mode cut to ``ranks`` (≤ the current ranks)."""
        core, factors = truncate(self.core, self.factors, ranks)
        return MotionTensor(self.label, self.styles, self.repetitions, self.reference, core, factors, self.fps)

    def warp(self, positions: np.ndarray) -> np.ndarray:
        """``(frames, 63)`` coordinates of a motion ``(n, 21, 3)`` warped onto the reference timeline."""
        return warp_to(self.reference, pose_coordinates(positions, self.fps))

    def parametrize(self, positions: np.ndarray, rounds: int = 10) -> Parametrization:
        """Eq. 3.6 for a segment ``(n ≥ 2, 21, 3)``: the bounded weights and the style they pick."""
        target = self.warp(positions).T.reshape(-1)                  # (63 · frames,)
        e = self.examples                                            # (63 · frames, styles, repetitions)
        s, r = len(self.styles), self.repetitions
        beta, gamma = np.full(s, 1.0 / s), np.full(r, 1.0 / r)
        with threadpool_limits(limits=1):       # small QRs: extra BLAS threads only contend on a busy machine
            for _ in range(rounds):
                beta = _bounded_least_squares(e @ gamma, target)      # columns: one per style
                gamma = _bounded_least_squares(np.einsum("dsr,s->dr", e, beta), target)
        fitted = np.einsum("dsr,s,r->d", e, beta, gamma)
        residual = float(np.sqrt(np.mean((fitted - target) ** 2)))
        return Parametrization(self.styles[int(np.argmax(beta))], beta, gamma, residual)


def _bounded_least_squares(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``argmin ‖a x − b‖`` with every ``x`` in :data:`WEIGHT_BOUNDS` (BVLS), ``a`` ``(n, k)`` tall: solved on
    the ``k × k`` triangle of ``a``'s QR factorization, whose objective differs from the full one by a
    constant."""
    q, tri = np.linalg.qr(a)
    return lsq_linear(tri, q.T @ b, bounds=WEIGHT_BOUNDS, method="bvls").x


@dataclass(frozen=True)
class Parametrization:
    """The fit of a segment: ``style`` (largest ``β``), ``style_weights`` ``β``, ``repetition_weights`` ``γ``,
    ``rms`` residual in metres over all coordinates."""

    style: str
    style_weights: np.ndarray
    repetition_weights: np.ndarray
    rms: float


def build_tensor(label: str, examples: Mapping[str, Sequence[np.ndarray]], fps: float,
                 repetitions: int | None = None) -> tuple[MotionTensor, np.ndarray]:
    """Warp a class's examples and decompose their tensor.

    Args:
        examples: style → motions ``(frames, 21, 3)``; each style needs ``repetitions`` of them (the first
            ones are used; ``None``: the smallest count over styles).

    Returns:
        The untruncated :class:`MotionTensor` and ``Θ`` ``(63, frames, styles, repetitions)``.

    Raises:
        TensorInputError: fewer than 2 styles, or a style with fewer than 2 (or ``repetitions``) motions.
    """
    styles = tuple(sorted(examples))
    if len(styles) < 2:
        raise TensorInputError(f"class {label!r}: a motion tensor needs at least 2 styles, got {list(styles)}")
    counts = {s: len(examples[s]) for s in styles}
    r = min(counts.values()) if repetitions is None else int(repetitions)
    short = {s: n for s, n in counts.items() if n < max(r, 2)}
    if short:
        raise TensorInputError(f"class {label!r}: styles {short} have fewer than {max(r, 2)} example motions")
    coords = {s: [pose_coordinates(m, fps) for m in examples[s][:r]] for s in styles}
    every = [c for s in styles for c in coords[s]]
    length = int(round(np.mean([c.shape[0] for c in every])))
    reference = resample_length(every[int(np.argmin([abs(c.shape[0] - length) for c in every]))], length)
    theta = np.stack([np.stack([warp_to(reference, c).T for c in coords[s]], axis=-1) for s in styles], axis=2)
    core, factors = n_mode_svd(theta)
    return MotionTensor(label, styles, r, reference, core, factors, fps), theta
