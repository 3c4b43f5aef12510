"""``stylemotion-train`` on bad input (issue 26): a resume is checked before the run folder is touched, a finished
run resumed with nothing left to train keeps its ``metrics.json``, and nothing is written or deleted through a link
out of the run folder."""

from __future__ import annotations

import json
import shutil

import pytest
import torch
from cli_runner import run_command
from hydra import compose, initialize_config_dir

from stylemotion.config import config_dir
from stylemotion.io.outputs import UnsafePathError
from stylemotion.training.fit import ResumeCheckpointError, nothing_left_to_train, run

SMOKE = ["experiment=smoke", "data=synthetic", "data.takes_per_pair=3", "data.duration_s=4.0",
         "data.styles=[normal,elderly]", "data.contents=[walk,run]"]


def _cfg(*overrides: str):
    with initialize_config_dir(config_dir(), version_base="1.3"):
        return compose("train", overrides=[*SMOKE, *overrides])


def _snapshot(folder):
    return {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished smoke run (seconds)."""
    folder = tmp_path_factory.mktemp("train") / "run"
    run(_cfg(f"output_dir={folder}"))
    return folder


@pytest.fixture
def run_copy(finished, tmp_path):
    folder = tmp_path / "run"
    shutil.copytree(finished, folder)
    return folder


def test_a_mismatched_resume_is_refused_before_the_run_folder_is_touched(run_copy):
    before = _snapshot(run_copy)
    with pytest.raises(ResumeCheckpointError, match=r"ckpt_path=.*last\.ckpt: .*hidden_units: checkpoint 32, model 64"):
        run(_cfg(f"output_dir={run_copy}", "ckpt_path=last", "model.hidden_units=64"))
    assert _snapshot(run_copy) == before  # config_resolved.yaml and run.json included


def test_junk_truncated_and_foreign_checkpoints_are_refused_by_name(run_copy, tmp_path):
    junk = tmp_path / "junk.ckpt"
    junk.write_bytes(b"not a checkpoint")
    cut = tmp_path / "cut.ckpt"
    cut.write_bytes((run_copy / "checkpoints" / "last.ckpt").read_bytes()[:4000])
    foreign = tmp_path / "foreign.ckpt"
    torch.save({"weights": torch.zeros(3)}, foreign)
    before = _snapshot(run_copy)
    for path, message in [(junk, "is not a readable checkpoint"), (cut, "is not a readable checkpoint"),
                          (foreign, "not a Lightning training checkpoint")]:
        with pytest.raises(ResumeCheckpointError, match=f"ckpt_path={path}: .*{message}"):
            run(_cfg(f"output_dir={run_copy}", f"ckpt_path={path}"))
    assert _snapshot(run_copy) == before


@pytest.mark.parametrize("ckpt_path", ["auto", "last"])
def test_resuming_a_finished_run_with_nothing_to_train_touches_none_of_its_files(run_copy, ckpt_path):
    before = _snapshot(run_copy)
    result = run(_cfg(f"output_dir={run_copy}", f"ckpt_path={ckpt_path}"))
    assert _snapshot(run_copy) == before  # metrics.json, config_resolved.yaml (run_id), run.json, checkpoints
    assert result["metrics"] == json.loads((run_copy / "metrics.json").read_text())
    assert result["metrics"]["best_score"] is not None


def test_what_is_left_to_train_is_read_from_the_checkpoint(finished):
    last = str(finished / "checkpoints" / "last.ckpt")
    state = torch.load(last, map_location="cpu", weights_only=True)
    epochs, step = state["loops"]["fit_loop"]["epoch_progress"]["current"]["completed"], state["global_step"]
    assert nothing_left_to_train(last, {"max_epochs": epochs, "max_steps": -1})
    assert nothing_left_to_train(last, {"max_epochs": epochs + 5, "max_steps": step})
    assert not nothing_left_to_train(last, {"max_epochs": epochs + 5, "max_steps": -1})


def test_a_finished_run_given_more_epochs_trains_on(run_copy):
    result = run(_cfg(f"output_dir={run_copy}", "ckpt_path=last", "trainer.max_epochs=4", "trainer.max_steps=-1"))
    assert result["trainer"].current_epoch == 4
    assert len(json.loads((run_copy / "run.json").read_text())["starts"]) == 2


def test_force_refuses_a_checkpoint_folder_that_links_out_of_the_run(run_copy, tmp_path):
    elsewhere = tmp_path / "elsewhere"
    shutil.move(run_copy / "checkpoints", elsewhere)
    (run_copy / "checkpoints").symlink_to(elsewhere, target_is_directory=True)
    kept = _snapshot(elsewhere)
    with pytest.raises(UnsafePathError, match=f"{run_copy / 'checkpoints'} is a link to {elsewhere}, outside"):
        run(_cfg(f"output_dir={run_copy}", "force=true"))
    assert _snapshot(elsewhere) == kept


def test_the_command_refuses_a_junk_checkpoint_in_one_line(finished, tmp_path, capsys, monkeypatch):
    junk = tmp_path / "junk.ckpt"
    junk.write_bytes(b"\x00" * 10)
    done = run_command("train", *SMOKE, f"hydra.run.dir={tmp_path / 'run'}", f"ckpt_path={junk}",
                       capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    line = done.stderr.strip().splitlines()[-1]
    assert line.startswith(f"stylemotion-train: ckpt_path={junk}: ") and "not a readable checkpoint" in line
    assert not (tmp_path / "run" / "config_resolved.yaml").exists()


@pytest.mark.parametrize("seed", ["abc", "-1", "1.5"])
def test_a_bad_seed_is_refused_before_the_run_folder_is_made(seed, tmp_path):
    from stylemotion.config import ConfigError

    with pytest.raises(ConfigError, match="seed must be a whole number ≥ 0"):
        run(_cfg(f"output_dir={tmp_path / 'run'}", f"seed={seed}"))
    assert not (tmp_path / "run").exists()


def test_ctrl_c_while_training_is_a_keyboard_interrupt_not_exit_status_1(tmp_path):
    import signal

    import lightning.pytorch as pl

    class CtrlC(pl.Callback):
        def on_train_batch_start(self, trainer, pl_module, batch, batch_idx):
            raise KeyboardInterrupt

    handler = signal.getsignal(signal.SIGINT)
    try:
        with pytest.raises(KeyboardInterrupt):  # the skeleton turns it into one line and status 130
            run(_cfg(f"output_dir={tmp_path / 'run'}"), extra_callbacks=[CtrlC()])
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # Ctrl-C works again
    finally:
        signal.signal(signal.SIGINT, handler)
    assert not (tmp_path / "run" / "metrics.json").exists()


@pytest.mark.parametrize("overrides, status", [(["ckpt_path=auto"], 0), (["ckpt_path=last"], 0),
                                               (["ckpt_path=last", "model.hidden_units=64"], 2)])
def test_the_command_touches_no_file_of_a_finished_run_it_does_not_train(run_copy, overrides, status, capsys,
                                                                       monkeypatch):
    before = _snapshot(run_copy)
    done = run_command("train", *SMOKE, f"hydra.run.dir={run_copy}", *overrides, capsys=capsys,
                       monkeypatch=monkeypatch, cwd=run_copy.parent)
    assert done.returncode == status, done.stderr
    assert _snapshot(run_copy) == before  # no .hydra/ record, no job log, no run.json start, no config
