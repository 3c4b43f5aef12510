"""The α rule (stylemotion/training/style_weight.py) against hand-worked products of relative costs."""

from __future__ import annotations

import math

import pytest

from stylemotion.training.style_weight import SAMPLE_METRICS, choose_style_weight, style_weight_scores


def metrics(style: float, mpjpe: float, spread: float = 1.0) -> dict[str, float]:
    return {"val/style": style, "val/mpjpe": mpjpe, "samples/pose_across_sd": spread}


def test_the_balanced_alpha_wins_and_scores_are_log_products() -> None:
    # relative costs (style ÷ 1, mpjpe ÷ 1): α=1 → 4·1 = 4, α=5 → 2·1.5 = 3, α=50 → 1·4 = 4
    values = {1.0: {"a": metrics(4, 1)}, 5.0: {"a": metrics(2, 1.5)}, 50.0: {"a": metrics(1, 4)}}
    scores = style_weight_scores(values)
    assert scores == pytest.approx({1.0: math.log(4), 5.0: math.log(3), 50.0: math.log(4)})
    assert choose_style_weight(values) == 5.0


def test_the_rule_is_scale_free_per_style_and_averages_styles() -> None:
    # style b alone would choose α=50 (products 8, 4, 2); a alone α=5 (4, 3, 4); the mean of logs:
    # α=1: (log 4 + log 8)/2 = log √32, α=5: log √12, α=50: log √8 → α=50
    values = {1.0: {"a": metrics(4, 1), "b": metrics(8000, 0.001)},
              5.0: {"a": metrics(2, 1.5), "b": metrics(2000, 0.002)},
              50.0: {"a": metrics(1, 4), "b": metrics(1000, 0.002)}}
    assert style_weight_scores(values)[50.0] == pytest.approx(math.log(math.sqrt(8)))
    assert choose_style_weight(values) == 50.0


def test_a_failed_candidate_is_never_chosen() -> None:
    values = {1.0: {"a": metrics(4, 1), "b": metrics(4, 1)},
              5.0: {"a": metrics(1, 1), "b": {"val/style": float("nan"), "val/mpjpe": 1.0,
                                               "samples/pose_across_sd": 1.0}}}
    assert style_weight_scores(values)[5.0] == math.inf
    assert choose_style_weight(values) == 1.0
    with pytest.raises(ValueError, match="every candidate failed"):
        choose_style_weight({1.0: {"a": {}}, 2.0: {"a": metrics(0, 1)}})


def test_ties_go_to_the_smaller_alpha() -> None:
    values = {10.0: {"a": metrics(1, 2)}, 2.0: {"a": metrics(2, 1)}}
    assert choose_style_weight(values) == 2.0


def test_a_collapsing_spread_costs_as_much_as_the_style_it_buys() -> None:
    # α=200 halves the style distance but its samples spread 4× less: 1/2 · 4 = 2 > 1 (α=5's product)
    values = {5.0: {"a": metrics(2, 1, spread=8)}, 200.0: {"a": metrics(1, 1, spread=2)}}
    assert style_weight_scores(values) == pytest.approx({5.0: math.log(2), 200.0: math.log(4)})
    assert choose_style_weight(values) == 5.0
    values[200.0]["a"]["samples/pose_across_sd"] = 8.0  # no collapse: the stronger style wins
    assert choose_style_weight(values) == 200.0


def test_sample_metrics_read_the_samples_style_distance_not_the_logged_one() -> None:
    # candidates whose logged val/style measures different decodes: SAMPLE_METRICS ignores it
    values = {"distance/both": {"a": {**metrics(9, 1, 4), "samples/style": 2.0}},
              "distance/posterior": {"a": {**metrics(1, 1, 4), "samples/style": 4.0}}}
    assert choose_style_weight(values) == "distance/posterior"  # by the logged val/style
    scores = style_weight_scores(values, SAMPLE_METRICS)
    assert scores == pytest.approx({"distance/both": 0.0, "distance/posterior": math.log(2)})
    assert choose_style_weight(values, SAMPLE_METRICS) == "distance/both"
    del values["distance/both"]["a"]["samples/style"]  # a missing figure of the rule: a failure
    assert choose_style_weight(values, SAMPLE_METRICS) == "distance/posterior"


def test_prior_sample_figures_against_a_direct_gram_distance(tiny_run) -> None:
    """``samples/style`` of a style CVAE is the mean ‖FFᵀ/T − G_example‖_F of its seeded prior samples' features (the
    pose-only features its term sees), recomputed here with numpy from the checkpoint's own target Gram; a plain VAE
    has no style figure."""
    import numpy as np
    import torch

    from stylemotion.models.cvae import pose_features
    from stylemotion.models.loading import load_generative
    from stylemotion.training.style_weight import prior_sample_figures, prior_sample_spread

    cvae = next(p for p in sorted((tiny_run.folder / "cvae").rglob("best.ckpt")))
    figures = prior_sample_figures(cvae, samples=32, seed=3)
    model = load_generative(cvae)
    drawn = model.sample(32, seed=3).features
    # the commands' default Gram sees pose channels only (suite style_channels): the same features the term sees
    assert model.style_channels == "pose"
    with torch.no_grad():
        features = pose_features(model.autoencoder, drawn).numpy().astype(np.float64)
    grams = features @ features.transpose(0, 2, 1) / features.shape[-1]
    target = model.style_gram.numpy().astype(np.float64)
    expected = np.linalg.norm(grams - target, axis=(1, 2)).mean()
    assert figures["samples/style"] == pytest.approx(expected, rel=1e-3)
    assert figures["samples/pose_across_sd"] == pytest.approx(prior_sample_spread(cvae, samples=32, seed=3))
    vae = next(p for p in sorted((tiny_run.folder / "vae").rglob("best.ckpt")))
    assert set(prior_sample_figures(vae, samples=8)) == {"samples/pose_across_sd"}
