"""``stylemotion-train -m experiment=primitive_vae|style_cvae``: Hydra multiruns over primitives and
styles through the joblib launcher, one run folder each with checkpoints, metrics, GIF and PNG.

The sweeps run ``python -m stylemotion.cli.train`` (what the console script calls) in a subprocess on
the tiny synthetic data, with the tiny autoencoder of :mod:`vae_fixtures`, for a few epochs.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import torch
import yaml
from hydra import compose, initialize_config_dir
from omegaconf import OmegaConf
from omegaconf.errors import InterpolationToMissingValueError
from PIL import Image
from vae_fixtures import TINY_OVERRIDES, tiny_autoencoder_ckpt

from stylemotion.config import config_dir
from stylemotion.models.cvae import StyleCVAE
from stylemotion.models.vae import PrimitiveVAE

FAST = [*TINY_OVERRIDES, "threads=1", "trainer.max_epochs=3", "callbacks.progress_bar=null",
        "trainer.enable_progress_bar=false", "trainer.enable_model_summary=false", "hydra/launcher=joblib",
        "hydra.launcher.n_jobs=2"]


@pytest.fixture(scope="session")
def ae_ckpt(tmp_path_factory) -> Path:
    return tiny_autoencoder_ckpt(tmp_path_factory.mktemp("sweep_ae"))


def sweep(*overrides: str, cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "HYDRA_FULL_ERROR": "0", "PYTHONWARNINGS": "ignore"}
    return subprocess.run([sys.executable, "-m", "stylemotion.cli.train", "-m", *overrides], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=240)


def check_run(run: Path, cls: type) -> PrimitiveVAE:
    """The files of one run; returns its best model, loaded as a notebook would."""
    for name in ("best.ckpt", "last.ckpt"):
        torch.load(run / "checkpoints" / name, weights_only=True)
    metrics = json.loads((run / "metrics.json").read_text())
    assert 0 < metrics["test"]["test/mpjpe"] < 1.0  # metres
    with Image.open(run / "samples" / "samples.gif") as gif:
        assert gif.n_frames > 5
    with Image.open(run / "samples" / "samples_last_frames.png") as png:
        assert png.size[0] > 800
    return cls.load_from_checkpoint(run / "checkpoints" / "best.ckpt")


def test_vae_sweep_over_primitives(ae_ckpt, tmp_path) -> None:
    done = sweep("experiment=primitive_vae", f"autoencoder_ckpt={ae_ckpt}",
                 "primitive=walk_leftStance,walk_rightStance", *FAST, f"hydra.sweep.dir={tmp_path}/sweep", cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-4000:]
    assert "Joblib.Parallel(n_jobs=2" in done.stdout + done.stderr
    runs = sorted(p for p in (tmp_path / "sweep").iterdir() if p.is_dir())
    assert [p.name for p in runs] == ["0_walk_leftStance", "1_walk_rightStance"]
    for run, primitive in zip(runs, ("walk_leftStance", "walk_rightStance")):
        model = check_run(run, PrimitiveVAE)
        assert model.primitive == primitive and model.spec["style"] is None
        assert model.spec["autoencoder"]["path"] == str(ae_ckpt)
        assert yaml.safe_load((run / "config_resolved.yaml").read_text())["datamodule"]["primitive"] == primitive


def test_style_cvae_sweep_over_styles_records_the_examples(ae_ckpt, tmp_path) -> None:
    done = sweep("experiment=style_cvae", f"autoencoder_ckpt={ae_ckpt}", "primitive=walk_rightStance",
                 "style=elderly,youthful", *FAST, f"hydra.sweep.dir={tmp_path}/sweep", cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-4000:]
    runs = sorted(p for p in (tmp_path / "sweep").iterdir() if p.is_dir())
    assert [p.name for p in runs] == ["0_walk_rightStance_elderly", "1_walk_rightStance_youthful"]
    takes = []
    for run, style in zip(runs, ("elderly", "youthful")):
        model = check_run(run, StyleCVAE)
        assert model.style == style and model.hparams.style_weight == 5.0
        [example] = model.style_examples
        assert example["style"] == style and example["primitive"] == "rightStance" and example["content"] == "walk"
        metrics = json.loads((run / "metrics.json").read_text())
        assert metrics["data"]["style_examples"][0]["take"] == example["take"]
        assert metrics["test"]["test/style"] > 0
        takes.append(example["take"])
    assert takes[0] != takes[1]


def test_experiment_configs_compose() -> None:
    with initialize_config_dir(config_dir(), version_base="1.3"):
        vae = compose("train", overrides=["experiment=primitive_vae", "primitive=run_rightStance",
                                          "autoencoder_ckpt=ae.ckpt"])
        cvae = compose("train", overrides=["experiment=style_cvae", "style=exhausted", "autoencoder_ckpt=ae.ckpt",
                                           "model.style_weight=50"])
        missing = compose("train", overrides=["experiment=primitive_vae"])
    assert vae.model._target_.endswith("PrimitiveVAE") and vae.datamodule.primitive == "run_rightStance"
    assert vae.datamodule.style is None and vae.model.samples_per_item == 10 and vae.model.kl_weight == 1.0
    assert cvae.model._target_.endswith("StyleCVAE") and cvae.model.style_weight == 50
    assert cvae.datamodule.style == "exhausted" and cvae.model.hidden == [512, 256, 128]
    assert OmegaConf.to_container(cvae.datamodule, resolve=True)["autoencoder_ckpt"] == "ae.ckpt"
    with pytest.raises(InterpolationToMissingValueError, match="Missing mandatory value: autoencoder_ckpt"):
        OmegaConf.to_container(missing.datamodule, resolve=True)
