"""``stylemotion-style`` as a command: a new style from a shared-data walk of another skeleton (CMU 21 joints,
60 fps, a frame range) on a tiny synthetic reproduce run, then ``stylemotion-generate`` with it (both called in
this process); refused input (a taken name, a ``network=`` mapping of CVAEs for ``method=zero_shot``) is one line
naming the key, with nothing written; the config names a missing mandatory key."""

from __future__ import annotations

import hashlib
import json
import math
import re
from pathlib import Path

import pytest
from cli_runner import run_command
from hydra import compose, initialize_config_dir
from style_fixtures import example_bvh
from test_commands_cli import one_line_error

from stylemotion.config import CONFIG_DIR, ConfigError
from stylemotion.style_example import add_style_from_config


@pytest.fixture(scope="session")
def run(tiny_run) -> Path:
    return tiny_run.folder


@pytest.mark.realdata
@pytest.mark.slow  # two commands (in this process), one of them training two CVAEs: ~12 s on an idle core
def test_a_style_from_a_cmu_walk_then_a_walk_in_it(run: Path, other_skeleton_paths, tmp_path: Path, capsys,
                                                   monkeypatch) -> None:
    def command(module: str, *args: str):
        return run_command(module, *args, capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)

    bvh = other_skeleton_paths["cmu21_walk"]
    out = tmp_path / "cmu"
    done = command("style", f"example={bvh}:10-150", f"run={run}", "name=cmu", f"out={out}", "samples=40")
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    steps = [line for line in done.stdout.splitlines() if line.startswith("[")]
    assert [s[:5] for s in steps] == [f"[{k}/5]" for k in range(1, 6)], done.stdout
    assert "140 of 162 frames at 60 fps → 70 frames at 30 fps" in steps[0]
    report = json.loads((out / "report.json").read_text())
    assert report["example"]["file_range"] == [10, 150] and report["example"]["file_fps"] == 60.0
    for p in ("walk_leftStance", "walk_rightStance"):
        row = report["table_5_1_row"][p]
        assert list(row) == ["neutral", "elderly", "youthful", "cmu"] and all(math.isfinite(v) for v in row.values())
        examples = report["models"][p]["examples"]
        assert examples and all(e["file"] == str(bvh) for e in examples)
        assert examples[0]["sha256"] == hashlib.sha256(bvh.read_bytes()).hexdigest()
        assert all(10 <= e["file_frames"][0] < e["file_frames"][1] <= 150 for e in examples)
    assert report["meta"]["command"].startswith("stylemotion-style example=")
    walk = command("generate", f"run={out}", "style=cmu", f"out={tmp_path / 'walk'}", "outputs.gif=false",
                   "outputs.bvh=false", "follow.iterations=5", "follow.candidates=32", "path.points=[[0,0],[0,2]]")
    assert walk.returncode == 0, walk.stderr[-3000:]
    assert "cmu:" in walk.stdout and (tmp_path / "walk" / "motion.npz").is_file()


def test_refused_input_is_one_line_and_writes_nothing(run: Path, tmp_path: Path, capsys, monkeypatch) -> None:
    done = run_command("style", f"example={example_bvh(tmp_path)}", f"run={run}", "name=elderly",
                       f"out={tmp_path / 'out'}", f"hydra.run.dir={tmp_path / 'hydra'}", cwd=tmp_path, capsys=capsys,
                       monkeypatch=monkeypatch)
    message = one_line_error(done, "stylemotion-style")
    assert message.startswith("stylemotion-style: name=elderly is taken: 'elderly' is a model of the run")
    assert not (tmp_path / "out").exists()


def test_a_network_that_is_no_zero_shot_network_is_one_line_and_writes_nothing(run: Path, tmp_path: Path, capsys,
                                                                                monkeypatch) -> None:
    cvae = {p: run / "cvae" / f"{p}_elderly" / "checkpoints" / "best.ckpt" for p in ("walk_leftStance",
                                                                                   "walk_rightStance")}
    mapping = "{" + ",".join(f"{p}:'{path}'" for p, path in cvae.items()) + "}"
    done = run_command("style", f"example={example_bvh(tmp_path)}", f"run={run}", "name=mine",
                       f"out={tmp_path / 'out'}", "method=zero_shot", f"network={mapping}",
                       f"hydra.run.dir={tmp_path / 'hydra'}", cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    message = one_line_error(done, "stylemotion-style")
    assert message == (f"stylemotion-style: network: {cvae['walk_leftStance']} is a StyleCVAE, not a zero-shot style "
                       "network (stylemotion-train experiment=zero_shot; or network=null trains one here)")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("missing, message", [("name", "name is missing: give name=<the new style's name>"),
                                              ("example", "example is missing: give example=<BVH>[:start-end]")])
def test_the_config_names_a_missing_key(tmp_path: Path, missing: str, message: str) -> None:
    given = {"example": "walk.bvh", "name": "mine"}
    given.pop(missing)
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose(config_name="style", overrides=[f"{k}={v}" for k, v in given.items()]
                      + [f"out={tmp_path / 'out'}"])
    with pytest.raises(ConfigError, match=re.escape(message)):
        add_style_from_config(cfg)
    assert cfg.method == "zero_shot" and cfg.samples == 1000 and not (tmp_path / "out").exists()
    assert cfg.network is None and cfg.network_epochs is None


def test_a_bad_item_of_an_example_list_is_one_line_naming_it(run: Path, tmp_path: Path, capsys, monkeypatch) -> None:
    good = example_bvh(tmp_path)
    gone = tmp_path / "gone.bvh"
    for bad, message in ((f"{good}:9-3", f"stylemotion-style: example[2]={good}:9-3: the frame range 9-3 is empty"),
                         (str(gone), f"stylemotion-style: example[2]={gone}: ")):
        done = run_command("style", f"example=[{good},{bad}]", f"run={run}", "name=mine", f"out={tmp_path / 'out'}",
                           f"hydra.run.dir={tmp_path / 'hydra'}", cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
        assert one_line_error(done, "stylemotion-style").startswith(message)
        assert not (tmp_path / "out").exists()
