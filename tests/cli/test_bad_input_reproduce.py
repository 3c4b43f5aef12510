"""``stylemotion-reproduce`` on bad keys and damaged records of earlier runs (issue 26): one line naming the key or
file, exit status 2, no traceback, found before any training and with nothing an earlier run wrote touched."""

from __future__ import annotations

import pytest
from cli_runner import run_command
from hydra import compose, initialize_config_dir

from stylemotion.config import CONFIG_DIR
from stylemotion.io.jsonfile import JsonFileError
from stylemotion.training.reproduction import Reproduction

#: Two short takes per style: the data stage takes about a second.
DATA = ["data.takes_per_pair=2", "data.duration_s=3.0", "data.styles=[normal,elderly]", "data.contents=[walk]"]


@pytest.mark.parametrize("overrides, message", [
    (["styles=[nope]"], "styles: ['nope'] are not in dataset 'synthetic'"),
    (["primitives=[nope]"], "primitives: unknown motion primitive 'nope'"),
    (["primitives=[run_leftStance]"], "primitives: ['run_leftStance'] have no clips in dataset 'synthetic'"),
    (["evaluation.neutral_style=nope"], "evaluation.neutral_style: the neutral style 'nope' is not in dataset"),
    (["evaluation.samples.table_5_1=0"], "evaluation.samples.table_5_1 must be at least 2"),  # not after training
])
def test_unknown_styles_and_primitives_end_in_one_line_before_training(overrides, message, tmp_path, capsys,
                                                                       monkeypatch):
    done = run_command("reproduce", *DATA, *overrides, "out=run", "hydra.run.dir=hydra", capsys=capsys,
                       monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-reproduce: ") and message in line, line
    assert not (tmp_path / "run").exists() or not any((tmp_path / "run").iterdir())  # no data.json, no stage


@pytest.mark.parametrize("out, message", [
    ("file", "out=file is a file, not a folder"),
    ("file/run", "file is not a folder; choose another out=…"),
])
def test_an_out_that_is_a_file_ends_in_one_line(out, message, tmp_path, capsys, monkeypatch):
    (tmp_path / "file").write_text("mine")
    done = run_command("reproduce", *DATA, f"out={out}", capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-reproduce: ") and message in line, line
    assert (tmp_path / "file").read_text() == "mine"


@pytest.mark.parametrize("record", ['{"settings_hash": "ab', '["not", "an", "object"]'])
def test_a_cut_off_done_json_is_named_before_training(record, tmp_path, capsys, monkeypatch):
    (tmp_path / "run" / "autoencoder").mkdir(parents=True)
    done_json = tmp_path / "run" / "autoencoder" / "done.json"
    done_json.write_text(record)
    done = run_command("reproduce", *DATA, "out=run", "hydra.run.dir=hydra", capsys=capsys, monkeypatch=monkeypatch,
                       cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-reproduce: run/autoencoder/done.json") and "stage's record" in line, line
    assert line.endswith("delete run/autoencoder to train the autoencoder stage again"), line
    assert done_json.read_text() == record  # the stage is not started again over it
    assert sorted(p.name for p in (tmp_path / "run" / "autoencoder").iterdir()) == ["done.json"]


@pytest.mark.parametrize("name, text", [("evaluation.json", '{"settings_hash": '), ("evaluation.json", "3")])
def test_a_cut_off_evaluation_record_is_named(name, text, tmp_path):
    out = tmp_path / "run"
    (out / "report").mkdir(parents=True)
    (out / name).write_text(text)
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose(config_name="reproduce", overrides=[*DATA, f"out={out}"])
    repro = Reproduction(cfg)
    with pytest.raises(JsonFileError, match=rf"{out / name}.*evaluation record.*delete {out / 'report'}"):
        repro.evaluation_stage()
    assert (out / name).read_text() == text


def test_a_refused_rerun_leaves_the_runs_data_summary_as_it_was(tmp_path, capsys, monkeypatch):
    (tmp_path / "run" / "autoencoder").mkdir(parents=True)
    (tmp_path / "run" / "autoencoder" / "done.json").write_text('{"settings_hash": "ab')
    for _ in range(2):
        done = run_command("reproduce", *DATA, "out=run", "hydra.run.dir=hydra", capsys=capsys,
                           monkeypatch=monkeypatch, cwd=tmp_path)
        assert done.returncode == 2, done.stderr
        if _ == 0:
            data_json = tmp_path / "run" / "data.json"
            first = (data_json.stat().st_mtime_ns, data_json.stat().st_ino, data_json.read_bytes())
    assert (data_json.stat().st_mtime_ns, data_json.stat().st_ino, data_json.read_bytes()) == first
