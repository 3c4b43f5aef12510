"""``stylemotion-style`` as a library call on a tiny synthetic reproduce run: the new style's CVAEs are the
run's CVAE training with the user's example, the report's Table 5.1 row covers every run column and the new
one; bad input (a taken name, a bad range, an unmapped skeleton, no complete step, an unknown method, an
existing out, a run that is not a finished reproduce run) is refused with a clear message and writes nothing."""

from __future__ import annotations

import hashlib
import json
import math
import shutil
from pathlib import Path

import pytest
import torch
import yaml
from conftest import tiny_bvh_text
from reproduce_fixtures import copy_run, reproduce, tiny_overrides
from style_fixtures import SAMPLES, example_bvh, tiny_style

from stylemotion.config import ConfigError
from stylemotion.io.outputs import OutputExistsError
from stylemotion.models.cvae import StyleCVAE
from stylemotion.style_example import NameTakenError, StyleExampleError, add_style
from stylemotion.style_example.evaluate import example_range

torch.set_num_threads(1)
PRIMITIVES = ("walk_leftStance", "walk_rightStance")


@pytest.fixture(scope="session")
def style_folder(tiny_run) -> tuple[Path, dict]:
    return tiny_style(tiny_run.folder)


@pytest.fixture(scope="session")
def run(tiny_run) -> Path:
    return tiny_run.folder


@pytest.fixture(scope="module")
def elderly_run(tiny_run, tmp_path_factory) -> Path:
    """The shared run with CVAEs of elderly only (its stages reused from a copy, its own report): youthful is then
    a style of the run's data without a model."""
    out = tmp_path_factory.mktemp("elderly_run") / "run"
    copy_run(tiny_run, out, ("autoencoder", "vae", "cvae/walk_leftStance_elderly", "cvae/walk_rightStance_elderly"))
    reproduce(tiny_overrides(out) + ["styles=[elderly]"], [])
    return out


def test_report_has_a_finite_table_5_1_row_for_every_run_column_and_the_new_example(style_folder) -> None:
    folder, made = style_folder
    report = json.loads((folder / "report.json").read_text())
    assert report == made["results"]
    run_report = json.loads((folder.parent / "run" / "report" / "report.json").read_text())
    for p in PRIMITIVES:
        columns = run_report["table_5_1"][p]["examples"]  # neutral, elderly
        row = report["table_5_1_row"][p]
        assert list(row) == [*columns, "tired"] and columns == ["neutral", "elderly", "youthful"]
        assert all(isinstance(v, float) and math.isfinite(v) and v > 0 for v in row.values()), row
        nearest = report["nearest_existing_style"][p]
        assert row[nearest] == min(v for k, v in row.items() if k != "tired")
        assert report["new_column_is_minimum"][p] == (row["tired"] == min(row.values()))
        assert report["variation"][p]["samples"]["motions"] == SAMPLES
        assert report["variation"][p]["example"]["pose_across_sd"] > 0  # two example clips per stance
        assert report["foot_skating"][p]["samples"]["motions"] == SAMPLES
        check = report["example_range"][p]  # a synthetic exhausted walk: well inside the autoencoder's range
        assert check["distance_to_neutral"] > 0 and not check["out_of_range"], check
    text = (folder / "report.md").read_text()
    assert "## Table 5.1 row" in text and f"nearest to **{report['nearest_existing_style']['walk_leftStance']}**" \
        in text


def test_each_cvae_records_the_users_file_and_is_trained_as_the_runs_cvae_stage(style_folder) -> None:
    folder, _ = style_folder
    report = json.loads((folder / "report.json").read_text())
    bvh = example_bvh(folder.parent)
    sha = hashlib.sha256(bvh.read_bytes()).hexdigest()
    for p in PRIMITIVES:
        model = StyleCVAE.load_from_checkpoint(folder / report["models"][p]["checkpoint"], weights_only=True)
        assert model.style == "tired" and model.primitive == p
        examples = model.style_examples
        assert examples and all(e["file"] == str(bvh) and e["sha256"] == sha for e in examples)
        assert {e["primitive"] for e in examples} == {p.split("_")[1]} and all(e["duration_s"] > 0 for e in examples)
        assert [e["file_frames"] for e in examples] == [e["file_frames"] for e in report["models"][p]["examples"]]
        # the run's CVAE stage of the primitive composed the same config, but for the style and the folders
        ours = yaml.safe_load((folder / "cvae" / f"{p}_tired" / "config_resolved.yaml").read_text())
        theirs = yaml.safe_load((folder.parent / "run" / "cvae" / f"{p}_elderly" / "config_resolved.yaml").read_text())
        assert _without_places(ours, "tired") == _without_places(theirs, "elderly")
        assert ours["trainer"]["max_epochs"] == 10 and ours["model"]["style_weight"] == 20.0


def _without_places(cfg: dict, style: str) -> dict:
    """A resolved train config without what differs by design: style, run id, folders, resume mode."""
    folder = cfg["output_dir"]

    def strip(node):
        if isinstance(node, dict):
            return {k: strip(v) for k, v in node.items() if k not in ("run_id", "ckpt_path")}
        if isinstance(node, str):
            return node.replace(folder, "<out>").replace(style, "<style>")
        return node

    return strip(cfg)


def test_progress_is_one_line_per_stage(style_folder) -> None:
    lines = style_folder[1]["lines"]
    steps = [line for line in lines if line.startswith("[")]
    assert [s[:5] for s in steps] == [f"[{k}/5]" for k in range(1, 6)]
    assert "cut with the run's segmentation: walk_leftStance 2, walk_rightStance 2" in steps[1]
    assert steps[2].startswith("[3/5] cvae walk_leftStance/tired: training (10 epochs")
    assert lines[-1].endswith("report.md") and any("nearest existing style" in line for line in lines)


def test_the_report_records_provenance_and_the_run(style_folder, run) -> None:
    meta = json.loads((style_folder[0] / "report.json").read_text())["meta"]
    assert meta["kind"] == "style" and meta["run"] == str(run.resolve()) and meta["run_relative"] == "../run"
    assert meta["git_commit"] and meta["stylemotion_version"] and meta["train_seed"] == 0
    assert [c["path"] for c in meta["checkpoints"]] == [f"cvae/{p}_tired/checkpoints/best.ckpt" for p in PRIMITIVES]
    assert (style_folder[0] / "example" / "example.npz").is_file()


# -- refused input: nothing is written


def _refused(tmp_path: Path, error: type[Exception], message: str, **kwargs) -> None:
    out = tmp_path / "style"
    with pytest.raises(error, match=message):
        add_style(kwargs.pop("example"), kwargs.pop("run"), kwargs.pop("name", "mine"), out, samples=10,
                  **kwargs)
    assert not out.exists() and not [p for p in tmp_path.iterdir() if p.name.startswith(".style")]


@pytest.mark.parametrize("name, why", [("elderly", "a model of the run"), ("youthful", "a style of the run's data"),
                                       ("normal", "the run's neutral style"), ("Neutral", "a model of the run")])
def test_a_taken_name_is_refused(elderly_run, tmp_path: Path, name: str, why: str) -> None:
    _refused(tmp_path, NameTakenError, rf"name={name} is taken: '{name.lower()}' is {why}",
             example=str(example_bvh(tmp_path)), run=elderly_run, name=name)


@pytest.mark.parametrize("name", ["my style", "../x", ""])
def test_a_name_that_is_no_file_name_is_refused(run, tmp_path: Path, name: str) -> None:
    _refused(tmp_path, StyleExampleError, "cannot name a style", example=str(example_bvh(tmp_path)), run=run,
             name=name)


@pytest.mark.parametrize("suffix, message", [(":9-3", "the frame range 9-3 is empty"),
                                             (":0-99999", "ends after the file's last frame"),
                                             (":x-3", "must be START-END")])
def test_a_bad_frame_range_is_refused(run, tmp_path: Path, suffix: str, message: str) -> None:
    _refused(tmp_path, StyleExampleError, message, example=f"{example_bvh(tmp_path)}{suffix}", run=run)


def test_an_example_without_a_complete_step_is_refused(run, tmp_path: Path) -> None:
    _refused(tmp_path, StyleExampleError, "no complete step", example=f"{example_bvh(tmp_path)}:0-30", run=run)


def test_an_unmapped_skeleton_is_refused(run, tmp_path: Path) -> None:
    (tmp_path / "odd.bvh").write_text(tiny_bvh_text())
    _refused(tmp_path, StyleExampleError, "no built-in joint map fits", example=str(tmp_path / "odd.bvh"), run=run)


def test_an_unknown_method_is_refused(run, tmp_path: Path) -> None:
    _refused(tmp_path, ConfigError, r"method must be one of \['cvae', 'zero_shot'\], got 'zeroshot'",
             example=str(example_bvh(tmp_path)), run=run, method="zeroshot")


@pytest.mark.parametrize("key, value, message", [("samples", 1, "samples must be at least 2"),
                                                   ("samples", "many", "samples must be a whole number"),
                                                   ("seed", -1, "seed must be a whole number ≥ 0 or null"),
                                                   ("threads", 0, "threads must be a whole number ≥ 1")])
def test_bad_numbers_are_refused_naming_the_key(run, tmp_path: Path, key: str, value, message: str) -> None:
    out = tmp_path / "style"
    with pytest.raises(ConfigError, match=message):
        add_style(str(example_bvh(tmp_path)), run, "mine", out, **{key: value})
    assert not out.exists()


def test_an_existing_out_is_refused_and_kept(run, tmp_path: Path) -> None:
    out = tmp_path / "style"
    out.mkdir()
    (out / "mine.txt").write_text("kept")
    with pytest.raises(OutputExistsError, match="already exists"):
        add_style(str(example_bvh(tmp_path)), run, "mine", out)
    assert [p.name for p in out.iterdir()] == ["mine.txt"]


def test_a_folder_that_is_no_finished_reproduce_run_is_refused(run, style_folder, tmp_path: Path) -> None:
    example = str(example_bvh(tmp_path))
    _refused(tmp_path, StyleExampleError, "does not exist", example=example, run=tmp_path / "nowhere")
    (tmp_path / "empty").mkdir()
    _refused(tmp_path, StyleExampleError, "has no reproduce.json", example=example, run=tmp_path / "empty")
    _refused(tmp_path, StyleExampleError, "is a stylemotion-style folder", example=example, run=style_folder[0])
    copy = tmp_path / "copy"
    shutil.copytree(run, copy)
    summary = json.loads((copy / "reproduce.json").read_text())
    for stage in summary["stages"]:
        stage.pop("overrides")
    (copy / "reproduce.json").write_text(json.dumps(summary))
    _refused(tmp_path, StyleExampleError, "recorded before reproduce.json kept", example=example, run=copy)
    summary["stages"][-1]["status"] = "pending"
    (copy / "reproduce.json").write_text(json.dumps(summary))
    _refused(tmp_path, StyleExampleError, r"not a finished stylemotion-reproduce run: stage\(s\) \['cvae "
             r"walk_rightStance/youthful'\]", example=example, run=copy)  # the last stage


def test_an_example_far_outside_the_data_is_flagged() -> None:
    assert example_range(10.0, {"elderly": 5.0, "active": 4.0}) == {
        "distance_to_neutral": 10.0, "run_examples_max": 5.0, "out_of_range": False}
    assert example_range(15.1, {"elderly": 5.0})["out_of_range"]  # beyond 3 × the farthest example
    assert not example_range(15.1, {})["out_of_range"]  # nothing to compare with: no verdict
