"""Functional PCA of spline coefficients (Du §3.3.4): FPCA, normalized FPCA and SFPCA.

The coefficients of a clip's functions are one vector ``c`` (``(D,)``). PCA runs on the scaled vectors
``W c`` where ``W`` holds one weight per *function* (all the coefficients of a joint's quaternion, of the
root translation, of the time warping, …):

* ``fpca``: ``W = I`` (standard PCA of the coefficients, [RS05]);
* ``normalized``: each function divided by its standard deviation over clips (Z-score);
* ``sfpca``: ``W`` minimizing the joint-space reconstruction error of eq. 3.8,
  ``1/N ‖f_k(Y) − f_k(W⁻¹ V′V′ᵀ W Y)‖²`` with the eigenfunctions ``V′`` recomputed from ``W Y`` at every
  evaluation, by L-BFGS-B (scipy); initialized, as the thesis does, with whichever of FPCA and
  normalized FPCA has the smaller joint-space error. The best weights seen are kept, so SFPCA is never
  worse than that start on its training data. Given a ``selection_error`` (the same error on validation
  clips), the weights kept are whichever of the start and that best-on-train has the lower validation error.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize
from threadpoolctl import threadpool_limits

log = logging.getLogger(__name__)

METHODS = ("fpca", "normalized", "sfpca")


@dataclass
class FunctionalPCA:
    """A fitted (scaled) PCA.

    Attributes:
        mean: ``(D,)`` mean coefficient vector.
        components: ``(d, D)`` orthonormal principal axes of the scaled, centred vectors.
        scale: ``(D,)`` per-coefficient weight (each function's weight repeated over its coefficients).
        variance: ``(d,)`` variance of the latent coordinates.
    """

    mean: np.ndarray
    components: np.ndarray
    scale: np.ndarray
    variance: np.ndarray

    @property
    def latent_dim(self) -> int:
        return int(self.components.shape[0])

    def project(self, vectors: np.ndarray) -> np.ndarray:
        """``(..., D)`` coefficient vectors → ``(..., d)`` latent coordinates."""
        return ((np.asarray(vectors) - self.mean) * self.scale) @ self.components.T

    def reconstruct(self, latent: np.ndarray) -> np.ndarray:
        """``(..., d)`` latent coordinates → ``(..., D)`` coefficient vectors."""
        return self.mean + (np.asarray(latent) @ self.components) / self.scale


def pca(vectors: np.ndarray, scale: np.ndarray, latent_dim: int) -> FunctionalPCA:
    """PCA of ``(n, D)`` vectors scaled by ``scale`` ``(D,)``, keeping ``latent_dim`` axes."""
    n = vectors.shape[0]
    if latent_dim > n - 1:
        raise ValueError(f"{n} clips give at most {n - 1} principal components; latent_dim={latent_dim} is too "
                         "many (use fewer latent dimensions or more clips)")
    mean = vectors.mean(0)
    x = (vectors - mean) * scale
    _, sv, vt = np.linalg.svd(x, full_matrices=False)
    return FunctionalPCA(mean, vt[:latent_dim], scale, sv[:latent_dim] ** 2 / max(n - 1, 1))


def group_scale(weights: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """Per-coefficient scale ``(D,)`` from one weight per function and each coefficient's function index."""
    return np.asarray(weights, dtype=np.float64)[groups]


def zscore_weights(vectors: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """One weight per function: 1 / the standard deviation of its coefficients over clips (1 where constant)."""
    centred = vectors - vectors.mean(0)
    count = np.bincount(groups)
    sd = np.sqrt(np.bincount(groups, weights=(centred ** 2).mean(0)) / np.maximum(count, 1))
    return np.where(sd > 1e-9, 1.0 / np.maximum(sd, 1e-12), 1.0)


def fit_reduction(vectors: np.ndarray, groups: np.ndarray, latent_dim: int, method: str,
                  joint_error: Callable[[np.ndarray], float] | None = None, max_iterations: int = 30,
                  selection_error: Callable[[Callable[[np.ndarray], np.ndarray]], float] | None = None,
                  ) -> tuple[FunctionalPCA, dict[str, float]]:
    """Fit one of :data:`METHODS`.

    Args:
        vectors: ``(n, D)`` coefficient vectors of the training clips.
        groups: ``(D,)`` function index of each coefficient.
        latent_dim: ``d``.
        method: ``fpca``, ``normalized`` or ``sfpca``.
        joint_error: reconstructed vectors ``(n, D)`` → mean squared joint-space error (m²) against the
            clips' own functional data (needed by ``sfpca``).
        max_iterations: L-BFGS-B iterations of ``sfpca``.
        selection_error: ``sfpca`` only: given a fitted PCA's ``reconstruct ∘ project`` (``(m, D)`` → ``(m, D)``),
            its mean squared joint-space error on validation clips; chooses between the start and the optimized
            weights (never consulted by the optimizer).

    Returns:
        The PCA and a record (``joint_mse_start``/``joint_mse`` for ``sfpca``, evaluations).
    """
    if method not in METHODS:
        raise ValueError(f"unknown dimension reduction {method!r}; one of {list(METHODS)}")
    vectors = np.asarray(vectors, dtype=np.float64)
    groups = np.asarray(groups)
    ones = np.ones(int(groups.max()) + 1)
    if method == "fpca":
        return pca(vectors, group_scale(ones, groups), latent_dim), {}
    normal = zscore_weights(vectors, groups)
    if method == "normalized":
        return pca(vectors, group_scale(normal, groups), latent_dim), {}
    if joint_error is None:
        raise ValueError("sfpca needs the joint-space error function")

    def error(weights: np.ndarray) -> float:
        model = pca(vectors, group_scale(weights, groups), latent_dim)
        return float(joint_error(model.reconstruct(model.project(vectors))))

    starts = {"fpca": (ones, error(ones)), "normalized": (normal, error(normal))}
    start_name = min(starts, key=lambda k: starts[k][1])
    start, start_error = starts[start_name]
    best = {"x": np.log(start), "f": start_error, "evaluations": 2}

    def objective(x: np.ndarray) -> float:
        value = error(np.exp(x))
        best["evaluations"] += 1
        if value < best["f"]:
            best["x"], best["f"] = x.copy(), value
        return value

    x0 = np.log(start)
    bounds = [(v - np.log(100.0), v + np.log(100.0)) for v in x0]
    # hundreds of small SVDs: one BLAS thread is fastest (0.06 s against 0.8 s each for 380 × 440 on a busy
    # 2-core machine, where BLAS threads oversubscribe the cores)
    with threadpool_limits(limits=1):
        minimize(objective, x0, method="L-BFGS-B", bounds=bounds,
                 options={"maxiter": int(max_iterations), "eps": 1e-3})
    weights = np.exp(best["x"])
    weights = weights / weights.max()  # the error does not depend on the overall scale
    record = {"joint_mse_fpca": starts["fpca"][1], "joint_mse_normalized": starts["normalized"][1],
              "start": start_name, "joint_mse": best["f"], "evaluations": best["evaluations"]}
    if selection_error is not None:
        def rebuild(w: np.ndarray):
            model = pca(vectors, group_scale(w, groups), latent_dim)
            return lambda v: model.reconstruct(model.project(v))

        val = {"start": float(selection_error(rebuild(start))), "optimized": float(selection_error(rebuild(weights)))}
        record.update(val_mse_start=val["start"], val_mse_optimized=val["optimized"],
                      kept="optimized" if val["optimized"] <= val["start"] else "start")
        if record["kept"] == "start":
            weights, record["joint_mse"] = start / start.max(), start_error
    log.info("SFPCA: joint MSE %.3g (start %s %.3g) after %d evaluations", best["f"], start_name, start_error,
             best["evaluations"])
    return pca(vectors, group_scale(weights, groups), latent_dim), record
