import numpy as np
import pytest
from scipy.stats import ortho_group

from stylemotion.multilinear.decomposition import (
    left_singular_vectors,
    model_entries,
    n_mode_svd,
    reconstruct,
    truncate,
)


def known_tensor(dims=(9, 12, 3, 4, 2), ranks=(4, 5, 2, 3, 2), seed=0):
    """A tensor built from a random core and known orthonormal factors (ground truth subspaces)."""
    rng = np.random.default_rng(seed)
    core = rng.normal(size=ranks)
    factors = [ortho_group.rvs(d, random_state=seed + k)[:, :r] for k, (d, r) in enumerate(zip(dims, ranks))]
    return reconstruct(core, factors), factors, ranks


def test_a_tensor_of_known_factors_is_recovered():
    tensor, factors, ranks = known_tensor()
    core, found = n_mode_svd(tensor)
    assert np.allclose(reconstruct(core, found), tensor, atol=1e-10)
    small_core, small = truncate(core, found, ranks)
    assert np.allclose(reconstruct(small_core, small), tensor, atol=1e-10)   # the true ranks lose nothing
    for true, got in zip(factors, small):                                     # the same subspaces
        assert np.allclose(got @ got.T, true @ true.T, atol=1e-8)
    below = [r - 1 if k == 0 else r for k, r in enumerate(ranks)]
    assert np.abs(reconstruct(*truncate(core, found, below)) - tensor).max() > 1e-3


def test_truncation_checks_ranks_and_counts_entries():
    tensor, _, _ = known_tensor()
    core, factors = n_mode_svd(tensor)
    with pytest.raises(ValueError, match="ranks"):
        truncate(core, factors, (1, 1, 1, 1))
    with pytest.raises(ValueError, match="ranks"):
        truncate(core, factors, (100, 1, 1, 1, 1))
    assert model_entries((2, 3), (5, 7)) == 6 + 10 + 21


def test_left_singular_vectors_equal_numpy_svd():
    rng = np.random.default_rng(2)
    for shape in [(7, 400), (30, 12), (12, 12)]:
        x = rng.normal(size=shape)
        want = np.linalg.svd(x, full_matrices=False)[0]
        got = left_singular_vectors(x)
        assert got.shape == want.shape
        assert np.allclose(np.abs(got.T @ want), np.eye(want.shape[1]), atol=1e-8)   # same vectors up to sign
