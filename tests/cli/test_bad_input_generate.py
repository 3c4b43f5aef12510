"""``stylemotion-generate`` on a bad run folder, checkpoints and follow values (issue 26): one line naming the file
or key, exit status 2, no traceback, nothing written; a ratio without a value is shown as n/a."""

from __future__ import annotations

import json

import pytest
import torch
from cli_runner import run_command

from stylemotion.synthesis.generate import summary_lines


def _run(tmp_path):
    (tmp_path / "cut" / "report").mkdir(parents=True)
    (tmp_path / "cut" / "report" / "report.json").write_text('{"meta": {"checkpoints": [')
    (tmp_path / "empty" / "report").mkdir(parents=True)
    (tmp_path / "empty" / "report" / "report.json").write_text(json.dumps({"meta": {"checkpoints": []}}))
    (tmp_path / "gone" / "report").mkdir(parents=True)
    (tmp_path / "gone" / "report" / "report.json").write_text(json.dumps({"meta": {"checkpoints": [
        {"primitive": "walk_leftStance", "name": "neutral", "style": "normal", "path": "vae/left.ckpt"}]}}))
    torch.save({"hyper_parameters": {"hidden_units": 8, "kernel_size": 3, "representation": "x", "fps": 30},
                "state_dict": {}}, tmp_path / "autoencoder.ckpt")


@pytest.mark.parametrize("overrides, message", [
    (["run=nowhere"], "run=nowhere: nowhere/report/report.json does not exist"),
    (["run=cut"], "cut/report/report.json:1: not valid JSON at column"),
    (["run=empty"], "empty/report/report.json: meta.checkpoints is empty"),
    (["run=gone"], "left.ckpt' does not exist"),
    (["+models={leftStance: missing.ckpt}"], "model checkpoint 'missing.ckpt' does not exist"),
    (["+models={leftStance: autoencoder.ckpt}"], "autoencoder.ckpt is not a trained PrimitiveVAE"),
    (["run=gone", "follow.max_steps=0"], "follow.max_steps must be at least 1, got 0"),
    (["run=gone", "follow.pose_scale_m=-1"], "follow.pose_scale_m must be positive, got -1"),
])
def test_bad_runs_checkpoints_and_values_end_in_one_line(overrides, message, tmp_path, capsys, monkeypatch):
    _run(tmp_path)
    done = run_command("generate", *overrides, "out=walk", "hydra.run.dir=hydra", capsys=capsys,
                       monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-generate: ") and message in line, line
    assert not (tmp_path / "walk").exists()


def test_foot_skating_without_a_planted_foot_is_shown_as_n_a():
    summary = {"style": "neutral", "steps": 1, "duration_s": 0.5, "walked_m": 0.4, "mean_speed_mps": 0.8,
               "deviation": {"mean_m": 0.0, "max_m": 0.0, "final_m": 0.0},
               "transitions": {"ratio": 1.0, "accel_ratio": 1.0}, "foot_skating_ratio": float("nan"),
               "foot_skating_ratio_before_cleanup": None, "synthesis_seconds": 1.0}
    text = "\n".join(summary_lines(summary))
    assert "foot skating n/a (no planted foot) (before clean-up n/a (no planted foot))" in text
