"""``stylemotion-train experiment=morphable_graph``'s work in-process: the run folder it writes (model, metrics,
config, run record), a finished folder refused unless ``force=true``, bad primitives and model values named as
config errors before a model is saved, and the sweep objective (the val error, never the test error)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
import yaml
from hydra import compose, initialize_config_dir

import stylemotion
from stylemotion.config import ConfigError, config_dir
from stylemotion.io.outputs import OutputExistsError
from stylemotion.morphable import MorphableModel
from stylemotion.morphable.training import MODEL_FILE, objective, run

SMALL = ["experiment=morphable_graph", "data.takes_per_pair=3", "data.duration_s=5.0", "model.latent_dim=5",
         "model.reduction=fpca", "model.num_coefficients=6", "model.tree.samples=200", "samples=false", "threads=1"]


def compose_cfg(out: Path, *overrides: str):
    with initialize_config_dir(config_dir(), version_base="1.3"):
        return compose("train", overrides=[*SMALL, f"output_dir={out}", *overrides])


@pytest.fixture(scope="module")
def fitted(tmp_path_factory) -> tuple[Path, dict]:
    out = tmp_path_factory.mktemp("morphable_training") / "left"
    return out, run(compose_cfg(out, "primitive=walk_leftStance", "style=normal"))


def test_the_run_folder_holds_the_model_its_metrics_config_and_record(fitted) -> None:
    out, result = fitted
    assert {p.name for p in out.iterdir()} == {MODEL_FILE, "metrics.json", "config_resolved.yaml", "run.json"}
    model = MorphableModel.load(out)
    assert (model.meta["action"], model.meta["primitive"]) == ("walk", "leftStance")
    assert model.meta["data"] == "synthetic" and model.tree is not None  # model.tree.samples=200
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics == json.loads(json.dumps(result["metrics"]))
    assert metrics["clips"]["train"] > 5 and metrics["fit"]["clips"] == metrics["clips"]["train"]
    assert 0 < metrics["test/joint_rmse_m"] < 0.1 and metrics["num_coefficients"] == 6
    assert metrics["model_bytes"] == (out / MODEL_FILE).stat().st_size and metrics["seconds"] > 0
    config = yaml.safe_load((out / "config_resolved.yaml").read_text())
    assert config["primitive"] == "walk_leftStance" and config["model"]["latent_dim"] == 5
    record = json.loads((out / "run.json").read_text())
    assert record["starts"][0]["stylemotion_version"] == stylemotion.__version__
    assert objective(result["metrics"]) == metrics["val/joint_rmse_m"] != metrics["test/joint_rmse_m"]


def test_a_finished_folder_is_refused_unless_forced(fitted) -> None:
    out, _ = fitted
    before = (out / MODEL_FILE).stat().st_mtime_ns
    with pytest.raises(OutputExistsError, match="already holds a morphable model.*force=true"):
        run(compose_cfg(out, "primitive=walk_leftStance"))
    assert (out / MODEL_FILE).stat().st_mtime_ns == before
    forced = run(compose_cfg(out, "primitive=walk_rightStance", "force=true"))
    assert MorphableModel.load(out).meta["primitive"] == "rightStance" and forced["metrics"]["clips"]["train"] > 5


@pytest.mark.parametrize("override, message", [
    ("primitive=walk_sideStance", "arm primitive"),
    ("primitive=raise-up-left-hand_wave", "use one of raise-up-left-hand_raise"),
    ("model.latent_dim=500", "experiment=morphable_graph, walk_leftStance"),
    ("model.no_such_setting=1", "experiment=morphable_graph, walk_leftStance"),
    ("model.tree.split=nearest", "model.tree"),
    ("turn=sideways", "turn=sideways"),
])
def test_bad_primitives_and_model_values_are_config_errors_and_save_no_model(tmp_path: Path, override: str,
                                                                          message: str) -> None:
    overrides = [override] if override.startswith("primitive=") else ["primitive=walk_leftStance", override]
    if override.startswith("model.no_such"):
        overrides[-1] = "+" + override
    with pytest.raises(ConfigError, match=message):
        run(compose_cfg(tmp_path / "out", *overrides))
    assert not (tmp_path / "out" / MODEL_FILE).exists()


@pytest.mark.parametrize("metrics, expected", [
    ({"test/joint_rmse_m": 0.02, "val/joint_rmse_m": 0.03}, 0.03),
    ({"val/joint_rmse_m": 0.03}, 0.03),
    ({"test/joint_rmse_m": 0.02}, None),  # no val clips: nothing to minimize, never the test figure
    ({}, None),
    ({"val/joint_rmse_m": math.nan, "test/joint_rmse_m": 0.02}, None),
    ({"val/joint_rmse_m": math.inf}, None),
])
def test_the_objective_is_the_validation_error_never_the_test_error(metrics: dict, expected) -> None:
    assert objective(metrics) == expected
