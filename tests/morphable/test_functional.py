"""B-spline functions, DTW warping, FPCA/SFPCA and the BIC mixture on their own and on synthetic clips."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.morphable.bspline import SplineBasis
from stylemotion.morphable.fpca import fit_reduction
from stylemotion.morphable.gmm import MixtureFitError, fit_gmm
from stylemotion.morphable.model import (
    FitSettings,
    coefficient_vectors,
    fit_primitive,
    functional_data,
    joint_error_function,
    spline_rmse,
)
from stylemotion.morphable.warping import canonical_times, dtw_warp


def test_spline_reproduces_cubics_and_evaluates_at_any_length():
    basis = SplineBasis(7)
    t = np.linspace(0.0, 1.0, 40)
    values = np.stack([t ** 3 - t, 2.0 * t ** 2, np.ones_like(t)], axis=1)  # (40, 3): cubics lie in the space
    coeffs = basis.fit(np.stack([values, 2 * values]))  # batch of 2 clips
    assert coeffs.shape == (2, 3, 7)
    again = basis.evaluate(coeffs, 40)
    np.testing.assert_allclose(again[0], values, atol=1e-10)
    np.testing.assert_allclose(again[1], 2 * values, atol=1e-10)
    fine = basis.evaluate(coeffs[0], 101)
    u = np.linspace(0.0, 1.0, 101)
    np.testing.assert_allclose(fine[:, 0], u ** 3 - u, atol=1e-10)
    with pytest.raises(ValueError, match="5 frames cannot determine 7"):
        basis.fit(np.zeros((5, 2)))
    with pytest.raises(ValueError, match="at least 4"):
        SplineBasis(3)


def test_dtw_recovers_a_time_stretch():
    t = np.linspace(0.0, 1.0, 30)
    reference = np.stack([np.sin(2 * np.pi * t), np.cos(2 * np.pi * t)], axis=1)
    slow = np.linspace(0.0, 1.0, 45) ** 1.3  # a clip played non-uniformly and longer
    clip = np.stack([np.sin(2 * np.pi * slow), np.cos(2 * np.pi * slow)], axis=1)
    warp = dtw_warp(reference, clip)
    assert warp[0] == 0.0 and warp[-1] == pytest.approx(44.0) and (np.diff(warp) > 0).all()
    truth = 44.0 * t ** (1 / 1.3)  # clip frame showing reference time t
    assert np.abs(warp - truth).mean() < 1.5
    times = canonical_times(warp, 45)
    assert times[0] == 0.0 and times[-1] == pytest.approx(1.0) and (np.diff(times) >= 0).all()


def test_spline_rmse_falls_with_more_coefficients(left_clips):
    data = functional_data(left_clips["train"])
    errors = [spline_rmse(data, k) for k in (4, 6, 8)]
    assert errors[0] > errors[1] > errors[2] > 0


@pytest.mark.parametrize("representation", ["quaternion", "frames"])
def test_sfpca_is_never_worse_than_fpca_in_joint_space(left_clips, representation):
    data = functional_data(left_clips["train"][:12], representation)  # few clips keep L-BFGS-B quick
    basis = SplineBasis(6)
    vectors, groups, names = coefficient_vectors(data, basis)
    assert names[-1] == "time_warping" and groups.max() == len(names) - 1
    error = joint_error_function(data, basis, vectors)
    for dims in (2, 4):
        fpca, _ = fit_reduction(vectors, groups, dims, "fpca")
        sfpca, record = fit_reduction(vectors, groups, dims, "sfpca", error, max_iterations=2)
        e_fpca = error(fpca.reconstruct(fpca.project(vectors)))
        e_sfpca = error(sfpca.reconstruct(sfpca.project(vectors)))
        assert e_sfpca <= e_fpca * (1 + 1e-9)
        assert record["joint_mse"] == pytest.approx(e_sfpca, rel=1e-6)


def test_bic_picks_two_separated_clusters_and_fit_failures_are_named():
    rng = np.random.default_rng(0)
    codes = np.concatenate([rng.normal(-5, 1, (200, 2)), rng.normal(5, 1, (200, 2))])
    gmm = fit_gmm(codes, max_components=5)
    assert gmm.num_components == 2 and set(gmm.bic) == {1, 2, 3, 4, 5}
    assert gmm.log_prob(np.zeros(2)) < gmm.log_prob(np.full(2, 5.0)) <= gmm.max_log_prob()
    draws = gmm.sample(1000, seed=1)
    assert draws.shape == (1000, 2) and np.allclose(np.sort(np.abs(draws.mean(0))), 0.0, atol=0.6)
    with pytest.raises(MixtureFitError, match="NaN"):
        fit_gmm(np.full((10, 2), np.nan))
    with pytest.raises(MixtureFitError, match="at least 2"):
        fit_gmm(np.zeros((1, 3)))
    with pytest.raises(MixtureFitError, match="max_components"):
        fit_gmm(codes, max_components=0)


def test_fewer_clips_than_latent_dimensions_is_refused(left_clips):
    clips = left_clips["train"][:5]
    with pytest.raises(ValueError, match="5 clips cannot give 8 latent dimensions"):
        fit_primitive(clips, FitSettings(latent_dim=8))
    with pytest.raises(ValueError, match="unknown dimension reduction 'pca'"):
        fit_primitive(left_clips["train"], FitSettings(latent_dim=3, reduction="pca", num_coefficients=5))
