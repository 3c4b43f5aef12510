"""``stylemotion-segment``: the report folder, refusing to overwrite, reported bad takes."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest
from cli_runner import run_command
from hydra import compose, initialize_config_dir
from omegaconf import OmegaConf

from stylemotion.cli.schemas import register_schemas
from stylemotion.config import CONFIG_DIR
from stylemotion.io.outputs import OutputExistsError
from stylemotion.primitives.report import write_report
from stylemotion.primitives.segmentation import SegmentSettings

register_schemas()  # the configs composed here take structured schemas (stylemotion.cli.schemas)

SMALL = ["data.takes_per_pair=1", "data.duration_s=3.0", "data.styles=[normal,elderly]", "data.contents=[walk,run]",
         "plot_rejected=2"]


def config(*overrides: str):
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        return compose(config_name="segment", overrides=list(overrides))


def test_report_folder_contents(tmp_path: Path) -> None:
    out = tmp_path / "report"
    report = write_report(config(*SMALL), out, command="test")
    assert {p.name for p in out.iterdir()} == {"report.json", "report.md", "takes", "clips_walk.png", "clips_run.png"}
    assert len(list((out / "takes").glob("*.png"))) == 4  # one take per action × style
    saved = json.loads((out / "report.json").read_text())
    assert saved["coverage_total"][0]["coverage"] == 1.0
    assert saved["provenance"]["command"] == "test" and saved["provenance"]["stylemotion_version"]
    counts = {(r["action"], r["primitive"], r["style"]): r["clips"] for r in saved["counts"]}
    assert len(counts) == 2 * 6 * 2 and counts[("walk", "beginLeftStance", "normal")] == 0
    assert counts[("walk", "leftStance", "elderly")] > 0
    assert sum(counts.values()) == sum(r["clips"] for r in saved["coverage"])
    assert {r["action"] for r in saved["stance_speeds"]} == {"walk", "run"}
    assert all(r["planted_mid_mps"] < r["swing_mid_mps"] for r in saved["stance_speeds"])
    assert [r["kind"] for r in saved["rejections"]].count("border") == 2 * 4  # two per take, 4 takes
    md = (out / "report.md").read_text()
    for heading in ("## Step coverage", "## Planted vs swing foot", "## Clip lengths", "## Clips per action",
                    "## Rejections by reason", "![clips_walk](clips_walk.png)"):
        assert heading in md
    assert report["lengths"][0]["canonical_frames"] > 5


def test_refuses_to_overwrite_unless_forced(tmp_path: Path) -> None:
    out = tmp_path / "report"
    out.mkdir()
    (out / "notes.txt").write_text("keep me")
    fast = (*SMALL, "plot_takes=0", "sheet_clips=1")
    with pytest.raises(OutputExistsError, match="force=true"):
        write_report(config(*fast), out)
    assert (out / "notes.txt").read_text() == "keep me"
    write_report(config(*fast), out, force=True)
    assert not (out / "notes.txt").exists() and (out / "report.json").is_file()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary folders left


def test_too_short_takes_are_reported_not_dropped(tmp_path: Path) -> None:
    out = tmp_path / "short"
    report = write_report(config("data.takes_per_pair=1", "data.duration_s=0.15", "data.styles=[normal]"), out)
    takes = [r for r in report["rejections"] if r["kind"] == "take"]
    assert len(takes) == 4 and all("too short for a step" in r["reason"] for r in takes)  # 4 contents
    assert report["coverage_total"][0]["rejected_takes"] == 4
    assert "too short for a step" in (out / "report.md").read_text()


def test_config_defaults_match_the_code() -> None:
    cfg = OmegaConf.to_container(config().segment)
    assert SegmentSettings.from_dict(cfg) == SegmentSettings()
    assert set(cfg["contacts"]) == {f.name for f in dataclasses.fields(SegmentSettings().contacts)}


def test_command_line(tmp_path: Path, capsys, monkeypatch) -> None:
    out = tmp_path / "cli"
    args = ["segment", f"out={out}", *SMALL, "plot_takes=0", "sheet_clips=2", f"hydra.run.dir={tmp_path / 'run'}"]
    first = run_command(*args, cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    assert first.returncode == 0, first.stderr
    assert "walk:" in first.stdout and "report written to" in first.stdout
    assert "report written to" in (tmp_path / "run" / "segment.log").read_text()  # the run folder keeps it too
    again = run_command(*args, cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    assert again.returncode != 0 and "exists" in again.stderr and "force=true" in again.stderr
