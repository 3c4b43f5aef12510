"""The public API's command calls (stylemotion/api.py): each is its command's library function with the command's
defaults. ``walk``, ``search_motion``, ``reconstruct_motion``, ``learn_templates`` and ``annotate_motion`` run in the
task notebooks (tests/test_task_notebooks.py); ``evaluate`` and the argument checks here."""

from __future__ import annotations

import json

import pytest

import stylemotion
from stylemotion.io.errors import UserInputError


@pytest.mark.slow  # an evaluation of 20 samples per model: ~13 s on a loaded 2-core machine
def test_evaluate_a_run_on_its_own_data(tiny_run, tmp_path):
    report = stylemotion.evaluate(tiny_run.folder, tmp_path / "eval", samples=20, seed=1)
    written = json.loads((tmp_path / "eval" / "report.json").read_text())
    assert written["meta"]["data"] == json.loads((tiny_run.folder / "report" / "report.json").read_text())["meta"][
        "data"]
    assert written["meta"]["samples"] == {"table_5_1": 20, "variance": 20, "metrics": 20}
    table = report["table_5_1"]["walk_leftStance"]
    assert table["models"] == ["neutral", "elderly", "youthful"] and table["samples"] == 20
    assert (tmp_path / "eval" / "report.md").is_file()
    with pytest.raises(UserInputError, match="already exists"):
        stylemotion.evaluate(tiny_run.folder, tmp_path / "eval", samples=20)


def test_bad_calls_are_one_clear_error(tiny_run, tmp_path):
    with pytest.raises(UserInputError, match="give data="):
        stylemotion.evaluate([tiny_run.folder / "vae" / "walk_leftStance"], tmp_path / "e")
    with pytest.raises(UserInputError, match=r"data='nowhere': no such data set config; one of \['bandai'"):
        stylemotion.data_config("nowhere")
    with pytest.raises(UserInputError, match="morphable=True.*takes \\{primitive"):
        stylemotion.walk(tiny_run.folder, tmp_path / "w", morphable=True)


def test_data_config_takes_overrides():
    data = stylemotion.data_config("synthetic", takes_per_pair=2, split={"seed": 3}, styles=["normal"])
    assert data["name"] == "synthetic" and data["takes_per_pair"] == 2 and data["styles"] == ["normal"]
    assert data["split"] == {"seed": 3, "val_fraction": 0.1, "test_fraction": 0.1}
