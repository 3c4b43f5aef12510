"""The N-mode SVD of a tensor (Krüger eq. 3.3 / 4.1; Vasilescu & Terzopoulos, De Lathauwer's HOSVD).

``Θ = Φ ×_1 U_1 ×_2 U_2 … ×_N U_N``: ``U_n`` are the left singular vectors of the mode-``n`` unfolding
(``tensorly.unfold``), ordered by singular value, and ``Φ = Θ ×_n U_nᵀ``. Truncating ``U_n`` to its first
``rank_n`` columns and ``Φ`` to the leading ``ranks`` block gives the reduced model of the thesis' truncation
experiments (Tables 4.1–4.3). Generic: nothing here knows about motions.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import tensorly as tl
from tensorly.tenalg import multi_mode_dot
from threadpoolctl import threadpool_limits


def left_singular_vectors(x: np.ndarray) -> np.ndarray:
    """``U`` ``(d, min(d, n))`` of the thin SVD of ``x`` ``(d, n)``. A wide ``x`` (an unfolding: ``n`` up to
    the product of the other modes) is first reduced by the QR factorization ``xᵀ = Q R`` (``x = Rᵀ Qᵀ``
    has the left singular vectors of ``Rᵀ``), so no ``(d, n)`` right factor is formed."""
    x = np.asarray(x, dtype=np.float64)
    if x.shape[1] > x.shape[0]:
        x = np.linalg.qr(x.T, mode="r").T
    return np.linalg.svd(x, full_matrices=False)[0]


def n_mode_svd(tensor: np.ndarray) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
    """Full N-mode SVD: ``(Φ, (U_1, ..., U_N))`` with ``U_n`` ``(d_n, min(d_n, ∏ others))`` and ``Φ`` of shape
    ``(min(d_1, ∏ others), ...)``; ``reconstruct(Φ, U)`` returns ``tensor`` up to rounding."""
    tensor = np.asarray(tensor, dtype=np.float64)
    with threadpool_limits(limits=1):       # thin factorizations: extra BLAS threads only contend
        factors = [left_singular_vectors(tl.unfold(tensor, mode)) for mode in range(tensor.ndim)]
    core = multi_mode_dot(tensor, factors, modes=list(range(tensor.ndim)), transpose=True)
    return core, tuple(factors)


def check_ranks(ranks: Sequence[int], full: Sequence[int]) -> tuple[int, ...]:
    """``ranks`` as ints, each in ``[1, full[n]]``; ValueError naming them otherwise."""
    out = tuple(int(r) for r in ranks)
    if len(out) != len(full) or any(not 1 <= r <= f for r, f in zip(out, full)):
        raise ValueError(f"ranks {tuple(ranks)} must be {len(full)} values, each in [1, {tuple(full)}]")
    return out


def truncate(core: np.ndarray, factors: Sequence[np.ndarray], ranks: Sequence[int]
             ) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
    """The reduced model: ``Φ[:r_1, …, :r_N]`` and ``U_n[:, :r_n]``."""
    ranks = check_ranks(ranks, core.shape)
    return (np.ascontiguousarray(core[tuple(slice(0, r) for r in ranks)]),
            tuple(np.ascontiguousarray(f[:, :r]) for f, r in zip(factors, ranks)))


def reconstruct(core: np.ndarray, factors: Sequence[np.ndarray]) -> np.ndarray:
    """``Φ ×_1 U_1 … ×_N U_N``: the tensor of shape ``(d_1, …, d_N)`` a (reduced) model represents."""
    return multi_mode_dot(core, list(factors), modes=list(range(core.ndim)))


def model_entries(core_shape: Sequence[int], dims: Sequence[int]) -> int:
    """Numbers stored by a reduced model: the core's entries plus every ``U_n`` ``(d_n, r_n)``."""
    return int(np.prod(core_shape) + sum(d * r for d, r in zip(dims, core_shape)))
