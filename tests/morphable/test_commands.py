"""``stylemotion-train experiment=morphable_graph`` and ``stylemotion-generate model=morphable`` as console
commands on the synthetic default (entry functions called in this process: :func:`cli_runner.run_command`)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from cli_runner import run_command

from stylemotion.morphable import MorphableModel

SMALL = ["data.takes_per_pair=3", "data.duration_s=5.0", "model.latent_dim=5", "model.reduction=fpca",
         "model.num_coefficients=6", "model.tree.samples=500", "samples=false", "threads=1"]


@pytest.mark.slow  # four console commands (in this process): ~4 s on a loaded 2-core machine
def test_train_then_generate(tmp_path, capsys, monkeypatch):
    def command(module: str, *args: str):
        return run_command(module, *args, capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)

    runs = {}
    for primitive in ("walk_leftStance", "walk_rightStance"):
        out = tmp_path / primitive
        done = command("train", "experiment=morphable_graph", f"primitive={primitive}", f"hydra.run.dir={out}", *SMALL)
        assert done.returncode == 0, done.stderr[-2000:]
        metrics = json.loads((out / "metrics.json").read_text())
        assert metrics["fit"]["clips"] > 5 and 0 < metrics["test/joint_rmse_m"] < 0.1
        assert {"run.json", "config_resolved.yaml", "model.npz"} <= {p.name for p in out.iterdir()}
        model = MorphableModel.load(out)
        assert model.meta["primitive"] == primitive.split("_")[1] and model.tree is not None
        runs[primitive] = out
    again = command("train", "experiment=morphable_graph", f"hydra.run.dir={runs['walk_leftStance']}", *SMALL)
    assert again.returncode != 0 and "already holds a morphable model" in again.stderr + again.stdout
    walk = tmp_path / "walk"
    done = command("generate", "model=morphable", f"+models.walk_leftStance={runs['walk_leftStance']}",
                   f"+models.walk_rightStance={runs['walk_rightStance'] / 'model.npz'}", f"out={walk}",
                   "path.s_curve.length_m=3.0", "path.s_curve.amplitude_m=0.2", "outputs.gif=false")
    assert done.returncode == 0, done.stderr[-2000:]
    summary = json.loads((walk / "summary.json").read_text())
    assert summary["meta"]["model"] == "morphable" and summary["deviation"]["mean_m"] < 0.15
    with np.load(walk / "motion.npz", allow_pickle=False) as z:
        assert z["positions"].shape[1:] == (21, 3)
    assert (walk / "motion.bvh").is_file()


@pytest.mark.realdata
def test_an_arm_primitive_of_bandai_trains_through_the_command(tmp_path, bandai_zip_path, capsys, monkeypatch):
    def train(*args: str):
        return run_command("train", "experiment=morphable_graph", *args, capsys=capsys, monkeypatch=monkeypatch,
                           cwd=tmp_path)

    out = tmp_path / "raise"
    bandai = ["data=bandai", f"data.root={bandai_zip_path}", "data.contents=[raise-up-left-hand]"]
    done = train(*bandai, "primitive=raise-up-left-hand_raise", f"hydra.run.dir={out}", "samples=false", "threads=1")
    assert done.returncode == 0, done.stderr[-2000:]
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["clips"]["train"] >= 20 and metrics["clips"]["test"] >= 1
    assert metrics["test/joint_rmse_m"] < 0.02  # measured 0.0049 m
    model = MorphableModel.load(out)
    assert (model.meta["action"], model.meta["primitive"]) == ("raise-up-left-hand", "raise")
    bad = train(*bandai, "primitive=raise-up-left-hand_wave", f"hydra.run.dir={tmp_path / 'bad'}", "samples=false")
    assert bad.returncode != 0 and "raise-up-left-hand_raise" in bad.stderr + bad.stdout
