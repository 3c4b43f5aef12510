""":mod:`stylemotion.training.fit`: a finished run is never overwritten, ``force`` and ``ckpt_path=auto``,
unique run ids, bad values refused before any work, checkpointing that leaves the numbers alone, and
what a run records about itself (run.json, metrics.json, TensorBoard hyperparameters and learning rate).

Trainings run the ``smoke`` preset in-process on a tiny synthetic dataset (a few seconds each).
"""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import lightning.pytorch as pl
import pytest
import torch
from hydra import compose, initialize_config_dir
from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

import stylemotion
from stylemotion.config import ConfigError, config_dir, unique_id
from stylemotion.io.outputs import OutputExistsError
from stylemotion.training.fit import prepare_output, resolve_ckpt_path, run

TINY = ["experiment=smoke", "data=synthetic", "data.takes_per_pair=3", "data.duration_s=4.0",
        "data.styles=[normal,elderly]", "data.contents=[walk,run]"]


def compose_cfg(*overrides: str):
    with initialize_config_dir(config_dir(), version_base="1.3"):
        return compose("train", overrides=[*TINY, *overrides])


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def fake_run(folder: Path) -> list[Path]:
    """A folder as a finished run leaves it (checkpoints, metrics, TensorBoard) plus Hydra's own files."""
    files = [folder / "checkpoints" / "best.ckpt", folder / "checkpoints" / "last.ckpt", folder / "metrics.json",
             folder / "tensorboard" / "events.out.tfevents.1.host.1.0", folder / "tensorboard" / "hparams.yaml"]
    for f in [*files, folder / ".hydra" / "config.yaml", folder / "train.log", folder / "notes.txt"]:
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text("x")
    return files


DIRS = (lambda d: [d / "checkpoints"], lambda d: [d / "tensorboard"])


def prepare(folder: Path, ckpt_path: str | None = None, force: bool = False) -> str | None:
    return prepare_output(folder, ckpt_path, force, *(f(folder) for f in DIRS))


# -- never over a finished run


def test_second_run_into_a_finished_folder_is_refused(tmp_path: Path) -> None:
    run(compose_cfg(f"output_dir={tmp_path}"))
    kept = {p: digest(p) for p in [tmp_path / "metrics.json", *(tmp_path / "checkpoints").glob("*.ckpt"),
                                   *(tmp_path / "tensorboard").glob("events.*")]}
    assert len(kept) >= 4
    with pytest.raises(OutputExistsError) as err:
        run(compose_cfg(f"output_dir={tmp_path}"))
    message = str(err.value)
    assert str(tmp_path) in message and "ckpt_path=" in message and "force=true" in message
    assert {p: digest(p) for p in kept} == kept  # nothing was touched
    assert len(list((tmp_path / "tensorboard").glob("events.*"))) == 2  # no third run's logs mixed in


def test_hydra_files_alone_do_not_count_as_results(tmp_path: Path) -> None:
    for f in (tmp_path / ".hydra" / "config.yaml", tmp_path / "train.log", tmp_path / "run.json"):
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text("x")
    assert prepare(tmp_path) is None


@pytest.mark.parametrize("result", ["checkpoints/best.ckpt", "metrics.json", "tensorboard/events.out.tfevents.1.h"])
def test_any_result_is_enough_to_refuse(tmp_path: Path, result: str) -> None:
    (tmp_path / result).parent.mkdir(parents=True, exist_ok=True)
    (tmp_path / result).write_text("x")
    with pytest.raises(OutputExistsError, match=result.split("/")[-1].replace(".", r"\.")):
        prepare(tmp_path)


def test_force_deletes_the_old_results_only(tmp_path: Path) -> None:
    results = fake_run(tmp_path)
    assert prepare(tmp_path, force=True) is None
    assert not [p for p in results if p.exists()]
    assert all((tmp_path / f).is_file() for f in (".hydra/config.yaml", "train.log", "notes.txt"))


def test_force_with_ckpt_path_is_refused(tmp_path: Path) -> None:
    results = fake_run(tmp_path)
    with pytest.raises(ConfigError, match="force=true .* ckpt_path=last"):
        prepare(tmp_path, "last", force=True)
    assert all(p.exists() for p in results)


def test_resuming_is_allowed_into_a_finished_folder(tmp_path: Path) -> None:
    fake_run(tmp_path)
    last = str(tmp_path / "checkpoints" / "last.ckpt")
    assert prepare(tmp_path, "last") == last and prepare(tmp_path, "auto") == last
    assert prepare(tmp_path, str(tmp_path / "checkpoints" / "best.ckpt")).endswith("best.ckpt")


def test_ckpt_path_auto_starts_when_there_is_nothing_to_resume(tmp_path: Path) -> None:
    assert resolve_ckpt_path("auto", tmp_path) is None and prepare(tmp_path, "auto") is None
    # a requeued job whose first attempt died before its first checkpoint: its logs go, the run starts
    events = tmp_path / "tensorboard" / "events.out.tfevents.1.host.1.0"
    events.parent.mkdir()
    events.write_text("x")
    assert prepare(tmp_path, "auto") is None and not events.exists()
    # results without a last.ckpt are not thrown away
    (tmp_path / "metrics.json").write_text("{}")
    with pytest.raises(OutputExistsError, match="no .*last.ckpt to resume"):
        prepare(tmp_path, "auto")


# -- run ids


def test_run_ids_are_unique_and_sort_by_time() -> None:
    ids = [unique_id() for _ in range(2000)]
    assert len(set(ids)) == len(ids)
    stamps = [i.rsplit("_", 1)[0] for i in ids]
    assert stamps == sorted(stamps) and len(stamps[0]) == len("2025-06-01_12-30-45_123456")


def test_a_run_sees_one_run_id(tmp_path: Path) -> None:
    cfg = compose_cfg(f"output_dir={tmp_path}")
    assert cfg.run_id == cfg.run_id and cfg.run_id != compose_cfg(f"output_dir={tmp_path}").run_id


# -- bad values, before any work


@pytest.mark.parametrize("override, key", [
    ("threads=abc", "threads"), ("threads=0", "threads"), ("threads=-1", "threads"), ("threads=true", "threads"),
    ("trainer.max_steps=abc", "trainer.max_steps"), ("trainer.max_epochs=1.5", "trainer.max_epochs"),
    ("trainer.limit_train_batches=2.5", "trainer.limit_train_batches"),
    ("trainer.gradient_clip_val=nan", "trainer.gradient_clip_val"),
])
def test_bad_values_are_refused_before_any_work(tmp_path: Path, override: str, key: str) -> None:
    with pytest.raises(ConfigError, match="^" + re.escape(key) + " must be"):
        run(compose_cfg(f"output_dir={tmp_path}", override))
    assert not list(tmp_path.iterdir())


# -- checkpoints

#: 12 training windows in batches of 4: three optimizer steps per epoch.
THREE_STEPS_PER_EPOCH = ["datamodule.batch_size=4", "trainer.max_epochs=20"]


class _FailAt(pl.Callback):
    """An exception after ``step`` optimizer steps."""

    def __init__(self, step: int):
        self.step = step

    def on_train_batch_end(self, trainer, *args) -> None:
        if trainer.global_step == self.step:
            raise RuntimeError("simulated failure")


class _FirstStep(pl.Callback):
    def on_train_start(self, trainer, *args) -> None:
        self.global_step = trainer.global_step


class _FailWhileTesting(pl.Callback):
    """Records last.ckpt's digest when testing starts, then fails."""

    def __init__(self, last: Path):
        self.last, self.before = last, ""

    def on_test_start(self, trainer, *args) -> None:
        self.before = digest(self.last)
        raise RuntimeError("simulated failure while testing")


def test_last_checkpoint_after_an_exception_and_auto_resume(tmp_path: Path) -> None:
    overrides = [f"output_dir={tmp_path}", *THREE_STEPS_PER_EPOCH, "trainer.max_steps=7",
                 "callbacks.checkpoint_last.every_n_train_steps=4"]
    with pytest.raises(RuntimeError, match="simulated failure"):
        run(compose_cfg(*overrides), extra_callbacks=[_FailAt(5)])
    last = tmp_path / "checkpoints" / "last.ckpt"
    assert torch.load(last, weights_only=True)["global_step"] == 5  # off the 4-step grid: saved on the exception
    first = _FirstStep()
    result = run(compose_cfg(*overrides, "ckpt_path=auto"), extra_callbacks=[first])
    assert first.global_step == 5 and result["trainer"].global_step == 7
    assert torch.load(last, weights_only=True)["global_step"] == 7  # the end, mid-epoch and off the grid
    starts = json.loads((tmp_path / "run.json").read_text())["starts"]
    assert [s["resumed_from"] for s in starts] == [None, str(last)]


def test_a_failure_while_testing_leaves_last_checkpoint_alone(tmp_path: Path) -> None:
    overrides = [f"output_dir={tmp_path}", *THREE_STEPS_PER_EPOCH, "trainer.max_steps=7",
                 "callbacks.checkpoint_last.every_n_train_steps=4"]
    last = tmp_path / "checkpoints" / "last.ckpt"
    watch = _FailWhileTesting(last)
    with pytest.raises(RuntimeError, match="while testing"):
        run(compose_cfg(*overrides), extra_callbacks=[watch])
    assert watch.before and digest(last) == watch.before
    assert torch.load(last, weights_only=True)["global_step"] == 7


def test_checkpointing_and_logging_leave_the_numbers_alone(tmp_path: Path) -> None:
    """The same seeded run with last.ckpt every step, learning-rate and hyperparameter logging, and
    with none of them: identical test metrics and identical best weights."""
    full = run(compose_cfg(f"output_dir={tmp_path / 'a'}", "callbacks.checkpoint_last.every_n_train_steps=1"))
    bare = run(compose_cfg(f"output_dir={tmp_path / 'b'}", "callbacks.checkpoint_last=null",
                           "callbacks.checkpoint_end=null", "callbacks.learning_rate=null", "~logger"))
    assert full["metrics"]["test"] == bare["metrics"]["test"] and full["metrics"]["test"]
    a, b = (torch.load(tmp_path / d / "checkpoints" / "best.ckpt", weights_only=True)["state_dict"] for d in "ab")
    assert a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a)
    assert not (tmp_path / "b" / "checkpoints" / "last.ckpt").exists()


# -- what a run records


def test_run_records_version_commit_hyperparameters_and_learning_rate(tmp_path: Path) -> None:
    result = run(compose_cfg(f"output_dir={tmp_path}"))
    record = json.loads((tmp_path / "run.json").read_text())
    assert record["output_dir"] == str(tmp_path) and record["run_id"]
    (start,) = record["starts"]
    assert start["stylemotion_version"] == stylemotion.__version__ and start["git_commit"]
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["stylemotion_version"] == stylemotion.__version__ and metrics["git_commit"] == start["git_commit"]
    fit_events = sorted((tmp_path / "tensorboard").glob("events.*"))[0]
    events = EventAccumulator(str(fit_events))
    events.Reload()
    assert "lr-Adam" in events.Tags()["scalars"]
    (best,) = events.Scalars("hp/val/mpjpe")
    assert best.value == pytest.approx(result["metrics"]["best_score"])
    experiment = events.PluginTagToContent("hparams")["_hparams_/experiment"]  # the HPARAMS tab's table
    assert b"hp/val/mpjpe" in experiment and b"model/kernel_size" in experiment
