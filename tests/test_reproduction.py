"""``stylemotion-reproduce`` with a tiny config (every stage in seconds), its resumption, and
``stylemotion-eval`` on its checkpoints, including bad input: checkpoints of different autoencoders,
a style model whose example is not in the data, an existing report folder."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import torch
from hydra import compose, initialize_config_dir
from vae_fixtures import feature_module, fit, tiny_autoencoder_ckpt

from stylemotion.config import CONFIG_DIR
from stylemotion.evaluation.run import run_evaluation
from stylemotion.evaluation.sources import MissingExampleError, MixedAutoencodersError
from stylemotion.io.outputs import OutputExistsError
from stylemotion.models.vae import PrimitiveVAE
from stylemotion.reproduction import StageConflictError
from stylemotion.reproduction import reproduce as run_reproduction

torch.set_num_threads(1)
QUIET = "trainer.enable_progress_bar=false,callbacks.progress_bar=null,trainer.enable_model_summary=false," \
        "trainer.num_sanity_val_steps=0,~logger"
# the model stages keep the configs' progress-bar callback: worker processes must drop it themselves
QUIET_MODELS = "trainer.enable_model_summary=false,trainer.num_sanity_val_steps=0,~logger"
DATA = ["data.takes_per_pair=6", "data.duration_s=6.0", "data.styles=[normal,elderly,youthful]", "data.contents=[walk]"]
EVAL = ["evaluation.samples.table_5_1=100", "evaluation.samples.variance=300", "evaluation.samples.metrics=100",
        "evaluation.classifier.components=8"]


def stage_list(name: str, items: str) -> str:
    """``stages.<name>=['a=1','b=2']``: a list of overrides as one override (quoted items)."""
    return f"stages.{name}=[" + ",".join(f"'{item}'" for item in items.split(",")) + "]"


def tiny_overrides(out: Path, vae_epochs: int = 12) -> list[str]:
    return DATA + EVAL + [
        f"out={out}", "threads=1", "primitives=[walk_leftStance]",
        stage_list("autoencoder", "experiment=smoke,model.hidden_units=32,trainer.max_steps=40,trainer.max_epochs=20,"
                                  "trainer.limit_train_batches=null,datamodule.window_frames=30,datamodule.stride=15,"
                                  + QUIET),
        stage_list("vae", f"experiment=primitive_vae,trainer.max_epochs={vae_epochs},datamodule.min_train_clips=8,"
                          "callbacks.samples=null," + QUIET_MODELS),
        stage_list("cvae", "experiment=style_cvae,trainer.max_epochs=12,datamodule.min_train_clips=8,"
                           "callbacks.samples.num_samples=4," + QUIET_MODELS),
    ]


def reproduce(overrides: list[str], lines: list[str] | None = None) -> dict:
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose(config_name="reproduce", overrides=overrides)
        return run_reproduction(cfg, say=(lines.append if lines is not None else print))


@pytest.fixture(scope="module")
def reproduced(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce") / "run"
    lines: list[str] = []
    summary = reproduce(tiny_overrides(out), lines)
    return out, summary, lines


def data_cfg() -> dict:
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        from omegaconf import OmegaConf

        return OmegaConf.to_container(compose(config_name="reproduce", overrides=DATA).data, resolve=True)


def eval_cfg() -> dict:
    return {"samples": {"table_5_1": 50, "variance": 100, "metrics": 50}, "classifier": {"components": 6}}


def test_reproduce_runs_every_stage_into_a_report(reproduced) -> None:
    out, summary, lines = reproduced
    assert [s["name"] for s in summary["stages"]] == ["autoencoder", "vae walk_leftStance",
                                                      "cvae walk_leftStance/elderly", "cvae walk_leftStance/youthful"]
    assert {s["status"] for s in summary["stages"]} == {"trained"}
    assert [line[:5] for line in lines if line.startswith("[")] == [f"[{k}/6]" for k in range(1, 7)]
    report = json.loads((out / "report" / "report.json").read_text())
    assert report["table_5_1"]["walk_leftStance"]["models"] == ["neutral", "elderly", "youthful"]
    assert report["style_recognition"]["classifier_heldout_accuracy"] >= 0.8  # real clips, chance 1/3
    assert len(report["meta"]["checkpoints"]) == 3 and report["meta"]["samples"]["variance"] == 300
    assert json.loads((out / "reproduce.json").read_text())["report"] == str(out / "report")
    assert (out / "cvae" / "walk_leftStance_elderly" / "samples").is_dir()  # the training stages' GIFs


def test_parallel_stages_train_the_same_models_as_sequential_ones(reproduced, tmp_path: Path) -> None:
    """workers=2 (the fixture: VAE and CVAEs in spawned processes) and workers=1 (all in this process)
    give the same models: same seeds, one torch thread each."""
    out, parallel, _ = reproduced
    sequential = reproduce(tiny_overrides(tmp_path / "seq") + ["workers=1"], [])
    for a, b in zip(parallel["stages"], sequential["stages"], strict=True):
        assert a["name"] == b["name"] and a["metrics"]["global_step"] == b["metrics"]["global_step"]
        assert a["metrics"]["test"] == pytest.approx(b["metrics"]["test"], rel=1e-5), a["name"]
    def table(folder: Path) -> list[float]:
        rows = json.loads((folder / "report" / "report.json").read_text())["table_5_1"]["walk_leftStance"]["distance"]
        return [value for row in rows for value in row]

    assert table(tmp_path / "seq") == pytest.approx(table(out), rel=1e-5)


def test_rerun_reuses_finished_stages_and_resumes_an_interrupted_one(reproduced) -> None:
    out, _, _ = reproduced
    interrupted = out / "cvae" / "walk_leftStance_youthful"
    (interrupted / "done.json").unlink()  # as if killed after its last checkpoint
    before = (out / "report" / "report.json").read_text()
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.run([sys.executable, "-m", "stylemotion.cli.reproduce", *tiny_overrides(out)],
                          capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    steps = [line for line in proc.stdout.splitlines() if line.startswith("[")]
    assert sum(": reused " in line for line in steps) == 4, proc.stdout  # autoencoder, vae, elderly cvae, report
    assert f"resuming from {interrupted / 'checkpoints' / 'last.ckpt'}" in proc.stdout
    assert (interrupted / "done.json").is_file()
    assert (out / "report" / "report.json").read_text() == before


def test_changed_settings_are_refused_not_overwritten(reproduced) -> None:
    out, _, _ = reproduced
    done = (out / "vae" / "walk_leftStance" / "done.json").read_text()
    with pytest.raises(StageConflictError, match="other settings") as err:
        reproduce(tiny_overrides(out, vae_epochs=13), [])
    assert str(out / "vae" / "walk_leftStance") in str(err.value)
    assert (out / "vae" / "walk_leftStance" / "done.json").read_text() == done


def test_eval_cli_writes_a_report_and_refuses_an_existing_folder(reproduced, tmp_path: Path) -> None:
    out, _, _ = reproduced
    report = tmp_path / "eval"
    args = [sys.executable, "-m", "stylemotion.cli.evaluate", *DATA, f"checkpoints=[{out / 'vae'},{out / 'cvae'}]",
            f"out={report}", "evaluation.samples.table_5_1=50", "evaluation.samples.variance=100",
            "evaluation.samples.metrics=50", "evaluation.classifier.components=6", "threads=1"]
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.run(args, capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "Table 5.1 walk_leftStance" in proc.stdout and (report / "report.md").is_file()
    saved = json.loads((report / "report.json").read_text())
    assert saved["meta"]["autoencoder"]["path"] == str((out / "autoencoder" / "checkpoints" / "best.ckpt").resolve())
    proc = subprocess.run(args, capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300)
    assert proc.returncode != 0 and "already exists" in proc.stderr
    assert json.loads((report / "report.json").read_text()) == saved


def test_checkpoints_of_different_autoencoders_are_refused(reproduced, tmp_path: Path) -> None:
    out, _, _ = reproduced
    other_ae = tiny_autoencoder_ckpt(tmp_path / "other_ae")  # another autoencoder (other weights)
    foreign = PrimitiveVAE(latent_dim=4, hidden=[16])
    fit(foreign, feature_module(other_ae), steps=2, folder=tmp_path / "foreign")
    with pytest.raises(MixedAutoencodersError, match="different autoencoders"):
        run_evaluation(data_cfg(), [str(out / "vae"), str(tmp_path / "foreign" / "best.ckpt")], eval_cfg(),
                       tmp_path / "mixed")
    with pytest.raises(MixedAutoencodersError, match="another autoencoder"):
        run_evaluation(data_cfg(), [str(out / "cvae")], eval_cfg(), tmp_path / "mixed", autoencoder_ckpt=str(other_ae))
    assert not (tmp_path / "mixed").exists()


def test_style_model_without_its_example_in_the_data_is_refused(reproduced, tmp_path: Path) -> None:
    out, _, _ = reproduced
    youthful = str(out / "cvae" / "walk_leftStance_youthful" / "checkpoints" / "best.ckpt")
    no_youthful = {**data_cfg(), "styles": ["normal", "elderly"]}
    with pytest.raises(MissingExampleError, match="youthful"):
        run_evaluation(no_youthful, [str(out / "vae"), youthful], eval_cfg(), tmp_path / "a")
    other_takes = {**data_cfg(), "seed": 1}  # same names, other motions
    with pytest.raises(MissingExampleError, match="trained on"):
        run_evaluation(other_takes, [youthful], eval_cfg(), tmp_path / "b")
    with pytest.raises(OutputExistsError, match="already exists"):
        run_evaluation(data_cfg(), [youthful], eval_cfg(), out / "report")


def test_budget_precision_follows_the_cpu(tmp_path) -> None:
    """bf16 autocast only where the CPU has bf16 instructions (emulated bf16 is ~40× slower)."""
    from stylemotion.config import cpu_precision

    with_bf16, without = tmp_path / "bf16", tmp_path / "plain"
    with_bf16.write_text("processor : 0\nflags : fpu sse2 avx2 avx512f avx512_bf16 amx_tile\n")
    without.write_text("processor : 0\nflags : fpu sse2 avx2 fma\n")
    assert cpu_precision(with_bf16) == "bf16-mixed" and cpu_precision(without) == "32-true"
    assert cpu_precision(tmp_path / "missing") == "32-true"
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose(config_name="reproduce", overrides=["data=bandai"])
    assert cfg.budget.autoencoder.precision == cpu_precision()
    assert f"trainer.precision={cpu_precision()}" in list(cfg.stages.autoencoder)


@pytest.mark.parametrize("workers", [0, -2, "two"])
def test_bad_workers_value_is_refused_before_any_work(tmp_path: Path, workers) -> None:
    with pytest.raises(ValueError, match=r"'workers' must be an integer ≥ 1.*got"):
        reproduce(tiny_overrides(tmp_path / "run") + [f"workers={workers}"], [])
    assert not (tmp_path / "run").exists()
