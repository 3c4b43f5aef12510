"""The leave-one-style-out evaluation end to end on a tiny reproduce run of two styles: a network trained
without each style, conditioned on that style's CVAE example, evaluated next to the CVAE; networks reused
from an earlier output give the same numbers; wrong networks and runs are refused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import torch
from omegaconf import OmegaConf

from stylemotion.cli.schemas import register_schemas
from stylemotion.evaluation.zero_shot import (
    ZeroShotRunError,
    leave_one_style_out,
    load_left_out,
    model_folder,
    read_run,
    train_config,
)
from stylemotion.io.outputs import OutputExistsError
from stylemotion.models.checkpoints import fingerprint, load_autoencoder
from stylemotion.models.loading import load_generative

register_schemas()  # the configs composed here take structured schemas (stylemotion.cli.schemas)

torch.set_num_threads(1)
PRIMITIVE = "walk_leftStance"
#: The networks: tiny, two epochs.
NETWORK = ["model.hidden=[64,32]", "model.embedding_dim=8", "model.samples_per_item=4", "datamodule.min_train_clips=8",
           "trainer.enable_model_summary=false", "trainer.num_sanity_val_steps=0", "~logger"]


@pytest.fixture(scope="module")
def run(tiny_run) -> Path:
    """The shared tiny reproduce run (conftest.py): walks of normal, elderly and youthful, CVAEs of both styles for
    both stance primitives (this evaluation takes walk_leftStance's)."""
    return tiny_run.folder


@pytest.mark.slow  # a reproduce run, two trainings and two evaluations: ~25 s on one busy core
def test_leave_one_style_out_end_to_end_on_two_styles(run, tmp_path) -> None:
    out = tmp_path / "loso"
    lines: list[str] = []
    results = leave_one_style_out(run, out, primitives=[PRIMITIVE], epochs=2, samples=40, overrides=NETWORK, threads=1,
                                  say=lines.append)
    source = read_run(run)
    styles = results["primitives"][PRIMITIVE]["styles"]
    assert list(styles) == ["elderly", "youthful"] and results["primitives"][PRIMITIVE]["columns"] == [
        "neutral", "elderly", "youthful"]
    for style, row in styles.items():
        network = load_generative(model_folder(out, PRIMITIVE, style) / "checkpoints" / "best.ckpt")
        assert network.excluded_styles == [style] and style not in row["trained_styles"]
        cvae = load_generative(source.cvaes[(PRIMITIVE, style)])
        assert [(e["take"], e["start"]) for e in row["example"]] == [(e["take"], e["start"])
                                                                     for e in cvae.style_examples]
        for kind in ("zero_shot", "cvae", "real"):
            assert 0.0 <= row[kind]["recognition"] <= 1.0 and row[kind]["pose_across_sd"] > 0
            assert set(row[kind]["table_5_1_row"]) == {"neutral", "elderly", "youthful"}
            assert row[kind]["nearest_column"] == min(row[kind]["table_5_1_row"], key=row[kind]["table_5_1_row"].get)
        assert row["zero_shot"]["samples"] == row["cvae"]["samples"] == 40 and row["real"]["clips"] >= 2
        assert row["zero_shot"]["train_seconds"] > 0 and row["real"]["recognition"] > 0.5
    assert json.loads((out / "zero_shot.json").read_text())["summary"] == results["summary"]
    markdown = (out / "zero_shot.md").read_text()
    assert f"| {PRIMITIVE} | elderly |" in markdown and "zero-shot without youthful → youthful" in markdown
    assert any("without elderly: training" in line for line in lines)
    # the trained networks reused (no training): the same numbers
    again = leave_one_style_out(run, tmp_path / "again", primitives=[PRIMITIVE], samples=40, checkpoints=out, threads=1,
                                say=lines.append)
    for style, row in again["primitives"][PRIMITIVE]["styles"].items():
        assert row["zero_shot"]["train_seconds"] is None
        assert row["zero_shot"]["table_5_1_row"] == styles[style]["zero_shot"]["table_5_1_row"]
        assert row["zero_shot"]["recognition"] == styles[style]["zero_shot"]["recognition"]
    with pytest.raises(OutputExistsError):
        leave_one_style_out(run, out, checkpoints=out)
    weights = fingerprint(load_autoencoder(source.autoencoder_ckpt))
    with pytest.raises(ZeroShotRunError, match="not the leave-youthful-out network"):
        load_left_out(model_folder(out, PRIMITIVE, "elderly") / "checkpoints" / "best.ckpt", PRIMITIVE, "youthful",
                      weights)


def test_the_train_config_leaves_the_style_out_of_the_runs_data(run, tmp_path) -> None:
    source = read_run(run)
    cfg = train_config(source, PRIMITIVE, "elderly", tmp_path / "m", epochs=7, overrides=["model.style_weight=5"])
    assert cfg.trainer.max_epochs == 7 and cfg.model.style_weight == 5 and cfg.model.anchor
    assert list(cfg.datamodule.exclude_styles) == ["elderly"] and cfg.datamodule.primitive == PRIMITIVE
    assert cfg.autoencoder_ckpt == str(source.autoencoder_ckpt) and cfg.seed == source.seed
    assert OmegaConf.to_container(cfg.data) == source.data_cfg
    assert cfg.datamodule._target_ == "stylemotion.datamodules.multistyle.MultiStyleDataModule"


def test_bad_runs_and_styles_are_refused(run, tmp_path) -> None:
    with pytest.raises(ZeroShotRunError, match="it has no reproduce.json"):
        read_run(tmp_path)
    with pytest.raises(ZeroShotRunError, match=r"has no CVAE of walk_leftStance for style\(s\) \['feminine'\]"):
        leave_one_style_out(run, tmp_path / "x", styles=["feminine"])
    assert not (tmp_path / "x").exists()
