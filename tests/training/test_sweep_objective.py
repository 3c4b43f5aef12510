"""Sweeps choose on validation: :func:`stylemotion.training.fit.objective` reads ``val/…`` values only, and a real
two-trial Optuna multirun (``hparams_search=autoencoder`` on tiny synthetic data) reports as its best value the
lowest validation score of its trials — a number recomputed here from each trial's ``metrics.json``, and not the
test score — while the ``cvae_style`` search composes with knobs the style CVAE has."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
import yaml
from hydra import compose, initialize_config_dir
from omegaconf import OmegaConf

from stylemotion.config import ConfigError, config_dir
from stylemotion.training.fit import objective

TINY = ["experiment=smoke", "data=synthetic", "data.takes_per_pair=3", "data.duration_s=4.0",
        "data.styles=[normal,elderly]", "data.contents=[walk,run]"]
#: A finished run whose val and test scores differ (so reading the wrong split shows).
METRICS = {"best_score": 0.5, "val": {"val/mpjpe": 0.5, "val/style": 7.0},
           "test": {"test/mpjpe": 0.1, "test/style": 1.0}}


def cfg(**values):
    return OmegaConf.create({"monitor": "val/mpjpe", **values})


def test_the_objective_is_the_best_validation_score_never_the_test_score() -> None:
    assert objective(METRICS, cfg()) == 0.5
    assert objective(METRICS, cfg(sweep_objective=["val/style", "val/mpjpe"])) == [7.0, 0.5]
    assert objective({"test": {"test/mpjpe": 0.1}}, cfg()) is None  # no validation: a failed trial, not a test score
    assert objective({"val": {"val/mpjpe": math.nan}}, cfg()) is None


@pytest.mark.parametrize("name", ["test/mpjpe", "mpjpe", ""])
def test_an_objective_that_is_no_validation_metric_is_refused(name: str) -> None:
    with pytest.raises(ConfigError, match="validation"):
        objective(METRICS, cfg(sweep_objective=name, monitor=name))


def test_an_optuna_multirun_minimizes_the_validation_metric(tmp_path: Path, capsys, monkeypatch) -> None:
    from cli_runner import run_command

    sweep = tmp_path / "sweep"
    done = run_command("train", "hparams_search=autoencoder", *TINY, "hydra.sweeper.n_trials=2", "~logger",
                       f"hydra.sweep.dir={sweep}", capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    trials = [json.loads(p.read_text()) for p in sorted(sweep.glob("*/metrics.json"))]
    assert len(trials) == 2
    val = [t["val"]["val/mpjpe"] for t in trials]
    test = [t["test"]["test/mpjpe"] for t in trials]
    assert all(v != pytest.approx(t) for v, t in zip(val, test))  # the two splits tell apart here
    result = yaml.safe_load((sweep / "optimization_results.yaml").read_text())
    assert result["best_value"] == pytest.approx(min(val))
    assert min(val) == pytest.approx(min(t["best_score"] for t in trials))


def test_the_style_cvae_search_composes_with_knobs_the_model_has() -> None:
    with initialize_config_dir(config_dir(), version_base="1.3"):
        c = compose("train", overrides=["hparams_search=cvae_style", "experiment=style_cvae", "autoencoder_ckpt=x"],
                    return_hydra_config=True)
    assert c.hydra.sweeper._target_.endswith("OptunaSweeper")
    assert list(c.hydra.sweeper.direction) == ["minimize", "minimize"]
    assert all(str(n).startswith("val/") for n in c.sweep_objective)
    for key in c.hydra.sweeper.params:
        node, name = key.rsplit(".", 1)
        assert name in OmegaConf.select(c, node), key
