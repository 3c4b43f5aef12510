"""What later tools read of a finished reproduce run (:mod:`stylemotion.training.run_folder`): its JSON objects
(with clear errors), its stages by kind, its data config, seed and evaluation settings, and recorded paths found
again after the run folder moved."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from stylemotion.config import ConfigError
from stylemotion.training.run_folder import FinishedRun, read_json_object


class RunError(ValueError):
    """A caller's own error class (what read_json_object raises when given one)."""


def stages() -> list[dict]:
    return [{"kind": "autoencoder", "name": "autoencoder", "checkpoint": "autoencoder/checkpoints/best.ckpt"},
            {"kind": "vae", "name": "vae walk_leftStance", "checkpoint": "vae/walk_leftStance/best.ckpt"},
            {"kind": "cvae", "name": "cvae walk_leftStance/elderly", "checkpoint": "cvae/a/best.ckpt"},
            {"kind": "vae", "name": "vae walk_rightStance", "checkpoint": "vae/walk_rightStance/best.ckpt"},
            {"kind": "cvae", "name": "cvae walk_rightStance/elderly", "checkpoint": "cvae/b/best.ckpt"}]


def meta() -> dict:
    return {"data": {"name": "synthetic", "styles": ["normal", "elderly"]}, "seed": 7,
            "settings": {"seed": 123, "neutral_style": "normal", "samples": {"table_5_1": 40, "variance": 50,
                                                                             "metrics": 60}}}


def test_a_json_object_is_read(tmp_path: Path) -> None:
    path = tmp_path / "reproduce.json"
    path.write_text(json.dumps({"stages": stages()}))
    assert read_json_object(path, "summary") == {"stages": stages()}


@pytest.mark.parametrize("content, message", [(None, "cannot read its summary"),
                                              ("{not json", "cannot read its summary"),
                                              ("[1, 2]", "does not hold a JSON object")])
def test_a_missing_broken_or_non_object_file_is_the_callers_error_naming_it(tmp_path: Path, content, message) -> None:
    path = tmp_path / "run" / "reproduce.json"
    path.parent.mkdir()
    if content is not None:
        path.write_text(content)
    with pytest.raises(RunError, match=message) as err:
        read_json_object(path, "summary", RunError)
    assert f"run={path.parent}" in str(err.value) and str(path) in str(err.value)
    with pytest.raises(ValueError, match=message):  # ValueError by default
        read_json_object(path, "summary")


def test_stages_by_kind_keep_the_runs_order(tmp_path: Path) -> None:
    run = FinishedRun(tmp_path, {"stages": stages()}, {})
    assert [s["name"] for s in run.stages("vae")] == ["vae walk_leftStance", "vae walk_rightStance"]
    assert [s["name"] for s in run.stages("cvae")] == ["cvae walk_leftStance/elderly", "cvae walk_rightStance/elderly"]
    assert run.stages("zero_shot") == []
    assert FinishedRun(tmp_path, {"stages": None}, {}).stages("vae") == []
    assert FinishedRun(tmp_path, {}, {}).stages("vae") == []


def test_the_reports_meta_gives_data_seed_and_evaluation_settings(tmp_path: Path) -> None:
    run = FinishedRun(tmp_path, {"stages": stages()}, {"meta": meta()})
    data = run.data_cfg
    assert data == meta()["data"]
    data["name"] = "changed"
    assert run.data_cfg["name"] == "synthetic"  # a copy: the caller cannot change the run's record
    assert run.seed == 7
    settings = run.settings
    assert settings.seed == 7  # the run's seed, not the one recorded inside the settings
    assert (settings.samples.table_5_1, settings.samples.variance, settings.samples.metrics) == (40, 50, 60)
    assert settings.neutral_style == "normal"
    assert run.settings is settings  # computed once


def test_a_report_without_meta_has_defaults_and_a_bad_setting_is_named(tmp_path: Path) -> None:
    run = FinishedRun(tmp_path, {}, {})
    assert run.meta == {} and run.seed == 0 and run.settings.seed == 0
    with pytest.raises(KeyError):
        _ = run.data_cfg  # no data config recorded: the callers check for it
    bad = FinishedRun(tmp_path, {}, {"meta": {"settings": {"no_such_key": 1}}})
    with pytest.raises(ConfigError, match="no_such_key"):
        _ = bad.settings


def test_recorded_paths_are_found_in_the_run_and_after_it_moved(tmp_path: Path) -> None:
    old = tmp_path / "old_place" / "run"
    moved = tmp_path / "new_place" / "run"
    ckpt = moved / "autoencoder" / "checkpoints" / "best.ckpt"
    ckpt.parent.mkdir(parents=True)
    ckpt.write_bytes(b"weights")
    relative = FinishedRun(moved, {"stages": stages()}, {})
    assert relative.autoencoder_ckpt == ckpt  # relative paths: relative to the run folder
    absolute = [{**stages()[0], "checkpoint": str(old / "autoencoder" / "checkpoints" / "best.ckpt")}]
    assert FinishedRun(moved, {"stages": absolute}, {}).autoencoder_ckpt == ckpt  # the run moved since
    elsewhere = tmp_path / "shared" / "ae.ckpt"
    elsewhere.parent.mkdir()
    elsewhere.write_bytes(b"other weights")
    assert FinishedRun(moved, {}, {}).located(str(elsewhere)) == elsewhere  # an existing file stays as recorded
    missing = str(tmp_path / "gone" / "x.ckpt")
    assert FinishedRun(moved, {}, {}).located(missing) == Path(missing)  # the loader names the missing file
