"""Gaussian mixture over a primitive's latent space (Du §4.4.1, eq. 4.1), components chosen by BIC.

Fitted with scikit-learn's :class:`~sklearn.mixture.GaussianMixture` (EM, full covariances) for 1 …
``max_components`` components; the lowest BIC wins. The result is kept as plain arrays (weights, means,
covariances), so a saved model loads without pickle; densities and samples are computed from them.
"""

from __future__ import annotations

import logging
import warnings
from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_triangular
from scipy.special import logsumexp
from sklearn.exceptions import ConvergenceWarning
from sklearn.mixture import GaussianMixture

from stylemotion.io.errors import UserInputError

log = logging.getLogger(__name__)


class MixtureFitError(UserInputError, ValueError):
    """No mixture could be fitted to the latent codes."""


@dataclass
class LatentGMM:
    """``p(s) = Σ_k w_k N(s | μ_k, Σ_k)``.

    Attributes:
        weights: ``(k,)`` mixture weights, summing to 1.
        means: ``(k, d)``.
        covariances: ``(k, d, d)`` symmetric positive definite.
        bic: ``{components: BIC}`` of every fit tried.
    """

    weights: np.ndarray
    means: np.ndarray
    covariances: np.ndarray
    bic: dict[int, float]

    def __post_init__(self) -> None:
        self._chol = np.linalg.cholesky(self.covariances)

    @property
    def num_components(self) -> int:
        return int(self.weights.shape[0])

    def component_log_prob(self, latent: np.ndarray) -> np.ndarray:
        """``(..., k)`` ``log w_k + log N(s | μ_k, Σ_k)`` of ``(..., d)`` codes."""
        s = np.asarray(latent, dtype=np.float64)
        lead, d = s.shape[:-1], s.shape[-1]
        flat = s.reshape(-1, d)
        maha = np.stack([(solve_triangular(self._chol[k], (flat - self.means[k]).T, lower=True) ** 2).sum(0)
                         for k in range(self.num_components)], axis=-1)
        logdet = 2.0 * np.log(np.diagonal(self._chol, axis1=-2, axis2=-1)).sum(-1)
        out = np.log(self.weights) - 0.5 * (maha + logdet + d * np.log(2 * np.pi))
        return out.reshape(lead + (self.num_components,))

    def log_prob(self, latent: np.ndarray) -> np.ndarray:
        """``(...)`` ``log p(s)`` of ``(..., d)`` codes."""
        return logsumexp(self.component_log_prob(latent), axis=-1)

    def max_log_prob(self) -> float:
        """An upper bound of ``log p(s)`` over all ``s`` (the sum of the components' peaks)."""
        d = self.means.shape[1]
        logdet = 2.0 * np.log(np.diagonal(self._chol, axis1=-2, axis2=-1)).sum(-1)
        return float(logsumexp(np.log(self.weights) - 0.5 * (logdet + d * np.log(2 * np.pi))))

    def sample(self, n: int, seed: int | np.random.Generator = 0) -> np.ndarray:
        """``(n, d)`` codes drawn from the mixture (numpy's generator, seeded)."""
        rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(int(seed))
        which = rng.choice(self.num_components, size=int(n), p=self.weights)
        noise = rng.standard_normal((int(n), self.means.shape[1]))
        return self.means[which] + np.einsum("nij,nj->ni", self._chol[which], noise)

    def to_arrays(self, prefix: str = "gmm_") -> dict[str, np.ndarray]:
        ks = sorted(self.bic)
        return {f"{prefix}weights": self.weights, f"{prefix}means": self.means,
                f"{prefix}covariances": self.covariances,
                f"{prefix}bic": np.array([[k, self.bic[k]] for k in ks], dtype=np.float64).reshape(-1, 2)}

    @classmethod
    def from_arrays(cls, arrays, prefix: str = "gmm_") -> LatentGMM:
        bic = {int(k): float(v) for k, v in np.asarray(arrays[f"{prefix}bic"]).reshape(-1, 2)}
        return cls(np.asarray(arrays[f"{prefix}weights"], dtype=np.float64),
                   np.asarray(arrays[f"{prefix}means"], dtype=np.float64),
                   np.asarray(arrays[f"{prefix}covariances"], dtype=np.float64), bic)


def fit_gmm(latent: np.ndarray, max_components: int = 10, seed: int = 0, reg_covar: float = 1e-3) -> LatentGMM:
    """The BIC-best mixture with 1 … ``max_components`` components of ``(n, d)`` codes.

    At most ``n / (d + 1)`` components are tried (a full covariance needs more than ``d`` codes), and
    ``reg_covar`` is relative: ``reg_covar ×`` the codes' mean variance is added to every covariance's
    diagonal (without it, components on a handful of codes collapse and win the BIC by degeneracy).

    Raises:
        MixtureFitError: too few codes, non-finite codes, or no fit succeeded (the reasons are named).
    """
    s = np.asarray(latent, dtype=np.float64)
    if s.ndim != 2 or s.shape[0] < 2:
        raise MixtureFitError(f"a mixture needs at least 2 latent codes (n, d), got shape {s.shape}")
    if not np.isfinite(s).all():
        raise MixtureFitError("latent codes contain NaN or inf; the mixture cannot be fitted")
    if max_components < 1:
        raise MixtureFitError(f"max_components must be ≥ 1, got {max_components}")
    bic: dict[int, float] = {}
    fits: dict[int, GaussianMixture] = {}
    failures: dict[int, str] = {}
    largest = max(1, min(int(max_components), s.shape[0] // (s.shape[1] + 1)))
    regularization = float(reg_covar * max(s.var(0).mean(), 1e-12))
    for k in range(1, largest + 1):
        gm = GaussianMixture(k, covariance_type="full", reg_covar=regularization, random_state=seed, n_init=1)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ConvergenceWarning)
                gm.fit(s)
            value = float(gm.bic(s))
        except (ValueError, np.linalg.LinAlgError) as err:
            failures[k] = str(err).splitlines()[0]
            continue
        if np.isfinite(value):
            bic[k], fits[k] = value, gm
        else:
            failures[k] = f"BIC {value}"
    if not fits:
        raise MixtureFitError(f"no Gaussian mixture could be fitted to {s.shape[0]} codes of dimension {s.shape[1]}: "
                              + "; ".join(f"{k} components: {why}" for k, why in failures.items()))
    best = min(bic, key=bic.get)
    log.info("GMM: %d component(s) by BIC (%s)", best, {k: round(v, 1) for k, v in bic.items()})
    gm = fits[best]
    return LatentGMM(gm.weights_.copy(), gm.means_.copy(), gm.covariances_.copy(), bic)
