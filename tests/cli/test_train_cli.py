"""``stylemotion-train``: run folders (unique ids, never overwritten), sweeps (basic and joblib
launchers), resume, DDP, bad config and bad values (one line naming the key).

The command-line tests run the entry function in-process (:func:`cli_runner.run_command`) on a tiny synthetic
dataset with the ``smoke`` preset; the joblib sweep and DDP, which need processes of their own, run
``python -m stylemotion.cli.train`` (what the ``stylemotion-train`` console script calls) in a subprocess; the
resume and bad-value tests call :func:`stylemotion.training.run` in-process on a composed config.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import lightning.pytorch as pl
import pytest
import torch
import yaml
from cli_runner import run_command
from hydra import compose, initialize_config_dir
from hydra.errors import InstantiationException

import stylemotion
from stylemotion.config import config_dir
from stylemotion.datamodules import EmptySplitError
from stylemotion.training.fit import resolve_ckpt_path, run

#: 4 (content, style) groups × 3 takes of 4 s: one take per group in each of train/val/test.
TINY_DATA = ["data=synthetic", "data.takes_per_pair=3", "data.duration_s=4.0", "data.styles=[normal,elderly]",
             "data.contents=[walk,run]"]
SMOKE = ["experiment=smoke", *TINY_DATA]


def train_cli(*overrides: str, cwd: Path, timeout: float = 240) -> subprocess.CompletedProcess:
    env = {**os.environ, "HYDRA_FULL_ERROR": "0", "PYTHONWARNINGS": "ignore"}
    return subprocess.run([sys.executable, "-m", "stylemotion.cli.train", *overrides], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)


def compose_cfg(*overrides: str):
    with initialize_config_dir(config_dir(), version_base="1.3"):
        return compose("train", overrides=list(overrides))


def check_run_dir(run_dir: Path, hydra: bool = True) -> dict:
    """The files every run writes (``.hydra/`` only under the Hydra CLI); returns the resolved config."""
    assert (run_dir / ".hydra" / "config.yaml").is_file() or not hydra
    resolved = yaml.safe_load((run_dir / "config_resolved.yaml").read_text())
    assert resolved["output_dir"] == str(run_dir) and resolved["model"]["fps"] == 30
    assert list((run_dir / "tensorboard").glob("events.out.tfevents.*"))
    for name in ("best.ckpt", "last.ckpt"):
        torch.load(run_dir / "checkpoints" / name, weights_only=True)
    metrics = json.loads((run_dir / "metrics.json").read_text())
    assert 0 < metrics["test"]["test/mpjpe"] < 10  # metres
    assert metrics["best_checkpoint"] == str(run_dir / "checkpoints" / "best.ckpt")
    return resolved


def test_sweep_over_kernel_sizes_writes_one_run_folder_each(tmp_path, capsys, monkeypatch):
    # Hydra's basic launcher runs the jobs one after another in the command's process: so here, in this one
    done = run_command("train", "-m", *SMOKE, f"hydra.sweep.dir={tmp_path}/sweep", "model.kernel_size=9,15,25",
                       cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    assert done.returncode == 0, done.stderr[-4000:]
    jobs = sorted((tmp_path / "sweep").glob("[0-9]*"))
    assert [p.name for p in jobs] == ["0", "1", "2"]
    kernels = [check_run_dir(job)["model"]["kernel_size"] for job in jobs]
    assert kernels == [9, 15, 25]
    for job, k in zip(jobs, kernels):
        ckpt = torch.load(job / "checkpoints" / "best.ckpt", weights_only=True)
        assert ckpt["state_dict"]["net.encoder.weight"].shape[-1] == k
        assert ckpt["hyper_parameters"]["kernel_size"] == k


def test_joblib_launcher_runs_the_sweep_in_parallel_processes(tmp_path):
    done = train_cli("-m", *SMOKE, f"hydra.sweep.dir={tmp_path}/sweep", "hydra/launcher=joblib",
                     "hydra.launcher.n_jobs=2", "model.pooling=avg,max", cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-4000:]
    assert "Joblib.Parallel(n_jobs=2" in done.stdout + done.stderr
    jobs = sorted((tmp_path / "sweep").glob("[0-9]*"))
    assert [check_run_dir(job)["model"]["pooling"] for job in jobs] == ["avg", "max"]


def test_single_run_folder_and_unknown_key(tmp_path, capsys, monkeypatch):
    run_dir = tmp_path / "run"
    done = run_command("train", *SMOKE, f"hydra.run.dir={run_dir}", cwd=tmp_path, capsys=capsys,
                       monkeypatch=monkeypatch)
    assert done.returncode == 0, done.stderr[-4000:]
    check_run_dir(run_dir)
    typo = run_command("train", *SMOKE, "model.kernal_size=9", cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    assert typo.returncode != 0
    assert "Could not override 'model.kernal_size'" in typo.stderr
    assert "Key 'kernal_size' is not in struct" in typo.stderr


def test_run_folder_has_a_unique_id_records_itself_and_is_never_overwritten(tmp_path, capsys, monkeypatch):
    done = run_command("train", *SMOKE, cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    assert done.returncode == 0, done.stderr[-4000:]
    (run_dir,) = (tmp_path / "runs" / "train" / "smoke").iterdir()
    resolved = check_run_dir(run_dir)
    assert run_dir.name == resolved["run_id"]
    assert re.fullmatch(r"\d{4}-\d\d-\d\d_\d\d-\d\d-\d\d_\d{6}_[0-9a-f]{4}", run_dir.name)
    assert json.loads((run_dir / "run.json").read_text())["run_id"] == run_dir.name
    assert f"stylemotion {stylemotion.__version__} (commit " in (run_dir / "train.log").read_text()
    kept = {p: p.read_bytes() for p in [run_dir / "metrics.json", *(run_dir / "checkpoints").glob("*.ckpt")]}

    again = run_command("train", *SMOKE, f"hydra.run.dir={run_dir}", cwd=tmp_path, capsys=capsys,
                        monkeypatch=monkeypatch)
    assert again.returncode == 2 and "Traceback" not in again.stderr
    (line,) = again.stderr.strip().splitlines()
    assert line.startswith(f"stylemotion-train: {run_dir} already holds a run's results")
    assert "ckpt_path=last" in line and "force=true" in line
    assert {p: p.read_bytes() for p in kept} == kept


@pytest.mark.parametrize("override, message", [
    ("threads=abc", "threads must be a whole number ≥ 1, got 'abc'"),
    ("trainer.max_steps=abc", "trainer.max_steps must be a whole number ≥ -1, got 'abc'"),
    ("ckpt_path=last", "ckpt_path=last but there is no "),
])
def test_bad_values_end_in_one_line_naming_the_key(override, message, tmp_path, capsys, monkeypatch):
    done = run_command("train", *SMOKE, override, f"hydra.run.dir={tmp_path / 'run'}", cwd=tmp_path, capsys=capsys,
                       monkeypatch=monkeypatch)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith(f"stylemotion-train: {message}")


def test_unknown_or_bad_model_option_is_a_clear_error(tmp_path):
    cfg = compose_cfg(*SMOKE, f"output_dir={tmp_path}", "+model.kernal_size=9")
    with pytest.raises(InstantiationException, match="kernal_size"):
        run(cfg)
    cfg = compose_cfg(*SMOKE, f"output_dir={tmp_path}", "model.pooling=median")
    with pytest.raises(InstantiationException, match=r"pooling must be one of \('avg', 'max'\), got 'median'"):
        run(cfg)


def test_empty_split_from_the_data_config_is_a_clear_error(tmp_path):
    cfg = compose_cfg(*SMOKE, f"output_dir={tmp_path}", "data.split.val_fraction=0.0")
    with pytest.raises(EmptySplitError, match="'val' split of dataset 'synthetic'"):
        run(cfg)


def test_ckpt_path_last_without_checkpoint_is_a_clear_error(tmp_path):
    with pytest.raises(FileNotFoundError, match="ckpt_path=last but there is no .*last.ckpt"):
        resolve_ckpt_path("last", tmp_path)
    assert resolve_ckpt_path(None, tmp_path) is None


class _InterruptAt(pl.Callback):
    """Ctrl+C after ``step`` optimizer steps."""

    def __init__(self, step: int):
        self.step = step

    def on_train_batch_end(self, trainer, *args) -> None:
        if trainer.global_step == self.step:
            raise KeyboardInterrupt


class _FirstStep(pl.Callback):
    def on_train_start(self, trainer, *args) -> None:
        self.global_step = trainer.global_step


def test_interrupted_run_resumes_from_last_checkpoint(tmp_path):
    overrides = [*SMOKE, f"output_dir={tmp_path}", "trainer.max_epochs=20", "trainer.max_steps=9",
                 "callbacks.checkpoint_last.every_n_train_steps=2"]
    handler = signal.getsignal(signal.SIGINT)
    try:
        with pytest.raises(KeyboardInterrupt):  # after Lightning's graceful shutdown (the skeleton: status 130)
            run(compose_cfg(*overrides), extra_callbacks=[_InterruptAt(5)])
    finally:
        signal.signal(signal.SIGINT, handler)  # Lightning ignores SIGINT after a Ctrl+C
    last = tmp_path / "checkpoints" / "last.ckpt"
    assert torch.load(last, weights_only=True)["global_step"] == 5  # saved on Ctrl+C, off the 2-step grid

    first = _FirstStep()
    result = run(compose_cfg(*overrides, "ckpt_path=last"), extra_callbacks=[first])
    assert first.global_step == 5
    assert result["trainer"].global_step == 9
    assert torch.load(last, weights_only=True)["global_step"] == 9
    check_run_dir(tmp_path, hydra=False)


@pytest.mark.slow
def test_ddp_with_two_cpu_processes(tmp_path):
    run_dir = tmp_path / "ddp"
    done = train_cli(*SMOKE, "trainer=ddp", "trainer.accelerator=cpu", "trainer.devices=2",
                     f"hydra.run.dir={run_dir}", cwd=tmp_path, timeout=300)
    out = done.stdout + done.stderr
    assert done.returncode == 0, out[-4000:]
    assert "distributed_backend=gloo" in out and "Starting with 2 processes" in out
    log = (run_dir / "train.log").read_text() + (run_dir / "train_ddp_process_1.log").read_text()
    assert "rank 0 of 2: torch seed 0" in log and "rank 1 of 2: torch seed 1000003" in log
    check_run_dir(run_dir)
    # rank zero alone writes the logs: one fit and one test event file
    assert len(list((run_dir / "tensorboard").glob("events.out.tfevents.*"))) == 2
    metrics = json.loads((run_dir / "metrics.json").read_text())
    # 12 train windows, batch 16: one batch per rank and epoch, 2 epochs
    assert metrics["global_step"] == 2
