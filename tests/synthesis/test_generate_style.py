"""``stylemotion-generate run=<stylemotion-style folder> style=<name>``: a walk from a style made from the user's
example; ``neutral`` and the run's own styles resolve through the folder; a moved pair of folders still works;
a style folder whose run is gone names it."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch
from style_fixtures import tiny_style

from stylemotion.synthesis import UnknownStyleError, load_graph
from stylemotion.synthesis.generate import generate

torch.set_num_threads(1)
SHORT = {"path": {"points": [[0, 0], [0, 2.5]], "spline": False}, "follow": {"candidates": 32, "iterations": 5},
         "outputs": {"bvh": False, "gif": False}, "seed": 0}


@pytest.fixture(scope="session")
def style_folder(tiny_run) -> Path:
    return tiny_style(tiny_run.folder)[0]


def test_generate_walks_in_the_new_style_from_the_style_folder(style_folder: Path, tmp_path: Path) -> None:
    summary = generate({**SHORT, "run": str(style_folder), "style": "tired", "out": str(tmp_path / "walk")})
    report = json.loads((style_folder / "report.json").read_text())
    assert summary["meta"]["style"] == "tired" and summary["steps"] >= 3
    assert summary["meta"]["models"] == {p.split("_")[1]: str(style_folder / m["checkpoint"])
                                         for p, m in report["models"].items()}
    assert summary["real_foot_skating_ratio"] == pytest.approx(report["foot_skating_pooled"]["example"])
    with np.load(tmp_path / "walk" / "motion.npz") as npz:
        assert npz["positions"].shape[1:] == (21, 3) and np.isfinite(npz["positions"]).all()
    assert summary["walked_m"] > 1.5


def test_neutral_and_the_runs_styles_resolve_through_the_style_folder(style_folder: Path) -> None:
    run = style_folder.parent / "run"
    for style in ("neutral", "normal", "elderly"):
        through, direct = load_graph(style, run=style_folder), load_graph(style, run=run)
        assert through.sources == direct.sources and through.style == direct.style
    with pytest.raises(UnknownStyleError, match=r"styles there: \['elderly', 'neutral', 'tired', 'youthful'\]"):
        load_graph("sleepy", run=style_folder)


def test_a_style_folder_moved_with_its_run_still_loads_and_one_without_it_names_the_run(style_folder: Path,
                                                                                        tmp_path: Path) -> None:
    moved = tmp_path / "moved"
    shutil.copytree(style_folder.parent / "run", moved / "run")
    shutil.copytree(style_folder, moved / "tired")
    report = json.loads((moved / "tired" / "report.json").read_text())
    report["meta"]["run"] = "/nonexistent/runs/reproduce/synthetic"  # as if both came from another machine
    (moved / "tired" / "report.json").write_text(json.dumps(report))
    graph = load_graph("tired", run=moved / "tired")
    assert graph.sources["leftStance"] == str(moved / "tired" / "cvae" / "walk_leftStance_tired" / "checkpoints" /
                                              "best.ckpt")
    assert load_graph("elderly", run=moved / "tired").sources["leftStance"].startswith(str(moved / "run"))
    shutil.rmtree(moved / "run")
    with pytest.raises(FileNotFoundError, match=r"extends the stylemotion-reproduce run /nonexistent/.* which is gone"):
        load_graph("tired", run=moved / "tired")
