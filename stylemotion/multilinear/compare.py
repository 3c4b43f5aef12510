"""Reconstruction of held-out motions by a multilinear model and by PCA with as many coefficients (Krüger §4.1.4,
Tables 4.1–4.3 and Figs. 4.6/4.7, here on motions the models did not see).

A held-out motion, warped onto the model's timeline, is ``X`` ``(66, f)``. Its representations:

* **natural weights** (eq. 3.5/3.6): the model's Ψ with truncated natural ranks ``(k_a, k_s, k_r)``;
  ``x ≈ Ψ ×_3 α ×_4 β ×_5 γ`` with ``α, β, γ`` in the reduced coefficient spaces, found by alternating linear
  least squares (each block is linear when the others are fixed) from the mean rows: ``k_a + k_s + k_r``
  coefficients;
* **natural subspace**: the least-squares projection onto the span of Ψ's ``k_a · k_s · k_r`` slices (the
  tensor's Tucker coefficients, not restricted to a product of weights);
* **technical modes**: ``U_1ᵀ X U_2`` of the DOF and frame modes truncated to ``(k_d, k_f)``: ``k_d · k_f``;
* **PCA of motions**: centred PCA of the training motions' ``66 · f`` vectors, ``k`` components;
* **PCA of poses**: centred PCA of the training frames' 66 values, ``k`` components per frame (``k · f``).

Errors (:func:`pose_error`): the mean Euclidean distance of the 21 joints in the root-local, facing-normalized
frame, metres (the thesis measured quaternion angles, eq. 4.6; the project's representation is positions), and
:func:`path_error`: the mean distance of the integrated root ground track, metres.
"""

from __future__ import annotations

import numpy as np

from stylemotion.multilinear.model import MultilinearModel
from stylemotion.representation import FRAME_DIM, frames_to_positions
from stylemotion.skeleton import NUM_JOINTS


def pose_error(frames: np.ndarray, reference: np.ndarray) -> float:
    """Mean joint distance (metres) between the root-local poses of two ``(f, 66)`` frame sequences."""
    a = np.asarray(frames, dtype=np.float64)[:, :NUM_JOINTS * 3].reshape(-1, NUM_JOINTS, 3)
    b = np.asarray(reference, dtype=np.float64)[:, :NUM_JOINTS * 3].reshape(-1, NUM_JOINTS, 3)
    return float(np.linalg.norm(a - b, axis=-1).mean())


def path_error(frames: np.ndarray, reference: np.ndarray, fps: float) -> float:
    """Mean ground distance (metres) between the root tracks integrated from two ``(f, 66)`` sequences, both from
    the origin facing +Z."""
    a, b = (frames_to_positions(np.asarray(x, dtype=np.float64), fps)[:, 0, [0, 2]] for x in (frames, reference))
    return float(np.linalg.norm(a - b, axis=-1).mean())


def fit_natural_weights(model: MultilinearModel, frames: np.ndarray, rounds: int = 20
                        ) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
    """``(reconstruction (f, 66), (α, β, γ))``: the product-of-weights fit of ``frames`` ``(f, 66)`` in the
    model's reduced natural coefficient spaces (alternating least squares from the mean rows, on the QR triangle of
    Ψ's slices: ``‖Ψ (α⊗β⊗γ) − x‖² = ‖R (α⊗β⊗γ) − Qᵀx‖² + const``)."""
    q, tri = model.natural_qr
    y = q.T @ np.asarray(frames, dtype=np.float64).T.reshape(-1)
    core = tri.reshape(-1, *model.ranks[2:])                                # (k, k_a, k_s, k_r)
    w = [u.mean(axis=0) for u in model.factors[2:]]
    blocks = ("dabc,b,c->da", "dabc,a,c->db", "dabc,a,b->dc")
    for _ in range(rounds):
        for mode in range(3):
            others = [w[k] for k in range(3) if k != mode]
            w[mode] = np.linalg.lstsq(np.einsum(blocks[mode], core, *others), y, rcond=None)[0]
    fitted = q @ np.einsum("dabc,a,b,c->d", core, *w)
    return fitted.reshape(FRAME_DIM, -1).T, tuple(w)


def project_natural(model: MultilinearModel, frames: np.ndarray) -> np.ndarray:
    """``(f, 66)``: the least-squares projection onto the span of the ``k_a · k_s · k_r`` slices of Ψ."""
    q, _ = model.natural_qr
    x = np.asarray(frames, dtype=np.float64).T.reshape(-1)
    return (q @ (q.T @ x)).reshape(FRAME_DIM, -1).T


def project_technical(model: MultilinearModel, frames: np.ndarray) -> np.ndarray:
    """``(f, 66)``: ``U_1 U_1ᵀ X U_2 U_2ᵀ`` with the model's (truncated) DOF and frame factors."""
    u1, u2 = model.factors[0], model.factors[1]
    x = np.asarray(frames, dtype=np.float64).T
    return (u1 @ (u1.T @ x @ u2) @ u2.T).T


class PCA:
    """Centred PCA of row vectors ``(n, d)`` (``numpy.linalg.svd``); :meth:`reconstruct` keeps ``k`` components."""

    def __init__(self, rows: np.ndarray) -> None:
        x = np.asarray(rows, dtype=np.float64)
        self.mean = x.mean(axis=0)
        self.components = np.linalg.svd(x - self.mean, full_matrices=False)[2]    # (min(n, d), d)

    @property
    def max_components(self) -> int:
        return int(self.components.shape[0])

    def reconstruct(self, rows: np.ndarray, k: int) -> np.ndarray:
        """``rows`` ``(m, d)`` projected onto the first ``k`` components (``k`` ≤ :attr:`max_components`)."""
        if not 0 <= k <= self.max_components:
            raise ValueError(f"k must be in [0, {self.max_components}], got {k}")
        p = self.components[:k]
        x = np.asarray(rows, dtype=np.float64) - self.mean
        return self.mean + (x @ p.T) @ p
