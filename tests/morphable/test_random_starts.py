"""§4.6.3's random initial codes: a seed fixes a Morphable Graph walk, another seed gives another walk, and the
start codes are draws of the primitive's mixture."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from stylemotion.morphable.synthesis import MapSettings, MorphablePrimitive, random_start
from stylemotion.synthesis import follow_path, s_curve
from stylemotion.synthesis.graph import MotionGraph


def _walk(left_model, right_model, seed: int, random_starts: int, accept_cost: float = 0.0,
          prior_centre: str = "mixture"):
    settings = MapSettings(random_starts=random_starts, max_evaluations=40, accept_cost=accept_cost,
                           prior_centre=prior_centre)
    graph = MotionGraph("walk", "normal", {"leftStance": MorphablePrimitive(left_model, settings),
                                           "rightStance": MorphablePrimitive(right_model, settings)})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return follow_path(graph, s_curve(1.8, amplitude_m=0.2, waves=0.5), seed=seed)


def test_one_seed_one_walk_and_another_seed_another(left_model, right_model):
    """Starts kept as drawn (a large accept_cost): the walk's codes are the seed's draws."""
    first, again, other = (_walk(left_model, right_model, s, 100, accept_cost=1e9) for s in (3, 3, 4))
    assert np.array_equal(first.frames, again.frames)
    assert [s.latent for s in first.steps] == [s.latent for s in again.steps]
    assert all(s.terms["refined"] == 0.0 for s in first.steps)
    assert not np.allclose(first.steps[0].latent, other.steps[0].latent, atol=1e-2)
    n = min(len(first.frames), len(other.frames))
    assert np.abs(first.frames[:n] - other.frames[:n]).max() > 1e-2


def test_refined_starts_still_follow_the_path(left_model, right_model):
    """accept_cost 0: every drawn start is refined by LM, which never leaves it worse."""
    drawn = _walk(left_model, right_model, 5, 100)
    assert all(s.terms["refined"] == 1.0 for s in drawn.steps)
    assert all(s.cost_final <= s.cost_best_candidate + 1e-9 for s in drawn.steps)


def test_refined_towards_the_start_walks_still_differ(left_model, right_model):
    """prior_centre='start': every step is refined by LM, pulled towards its own draw, so seeds still differ."""
    a, b = (_walk(left_model, right_model, s, 100, prior_centre="start") for s in (3, 4))
    assert all(s.terms["refined"] == 1.0 for s in a.steps)
    assert not np.allclose(a.steps[0].latent, b.steps[0].latent, atol=1e-2)


def test_without_random_starts_every_seed_walks_the_same(left_model, right_model):
    a, b = (_walk(left_model, right_model, s, 0) for s in (3, 4))
    assert np.array_equal(a.frames, b.frames)


def test_start_draws_follow_the_mixture(left_model):
    """One draw per call (nothing to choose): the starts' mean and covariance match the mixture's, computed from
    its weights, means and covariances."""
    gmm = left_model.gmm
    rng = np.random.default_rng(0)
    n = 4000
    starts = np.stack([random_start(left_model, lambda c: np.zeros(len(c)), 1, rng)[0] for _ in range(n)])
    mean = (gmm.weights[:, None] * gmm.means).sum(0)
    second = np.einsum("k,kij->ij", gmm.weights, gmm.covariances + np.einsum("ki,kj->kij", gmm.means, gmm.means))
    cov = second - np.outer(mean, mean)
    sd = np.sqrt(np.diag(cov))
    assert np.abs(starts.mean(0) - mean).max() < 5 * sd.max() / np.sqrt(n)
    assert np.allclose(np.cov(starts.T), cov, atol=0.1 * np.diag(cov).max())


def test_the_cheapest_draw_is_the_start(left_model):
    target = left_model.gmm.means[0] + 1.0
    objective = lambda c: np.linalg.norm(c - target, axis=1)  # noqa: E731
    start, cost = random_start(left_model, objective, 50, np.random.default_rng(1))
    draws = left_model.gmm.sample(50, np.random.default_rng(1))  # the same generator state: the same 50 draws
    assert cost == pytest.approx(objective(draws).min()) and objective(start[None])[0] == pytest.approx(cost)


def test_bad_start_settings_are_refused():
    with pytest.raises(ValueError, match="random_starts ≥ 0"):
        MapSettings(random_starts=-1)
    with pytest.raises(ValueError, match="prior_centre"):
        MapSettings(prior_centre="mode")
