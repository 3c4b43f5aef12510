"""``stylemotion-reproduce`` with a tiny config (every stage in seconds), its resumption, and
``stylemotion-eval`` on its checkpoints, including bad input: checkpoints of different autoencoders,
a style model whose example is not in the data, an existing report folder."""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest
import torch
from cli_runner import run_command
from hydra import compose, initialize_config_dir
from reproduce_fixtures import DATA, copy_run, reproduce, tiny_overrides
from vae_fixtures import feature_module, fit, tiny_autoencoder_ckpt

import stylemotion
from stylemotion.cli.schemas import register_schemas
from stylemotion.config import CONFIG_DIR, ConfigError
from stylemotion.evaluation.run import run_evaluation
from stylemotion.evaluation.sources import MissingExampleError, MixedAutoencodersError
from stylemotion.io.outputs import OutputExistsError
from stylemotion.models.vae import PrimitiveVAE
from stylemotion.training.reproduction import Reproduction, StageConflictError, choose_budget

register_schemas()  # the configs composed here take structured schemas (stylemotion.cli.schemas)

torch.set_num_threads(1)


@pytest.fixture
def reproduced(tiny_run):
    """The shared tiny run (conftest.py): its folder, the summary and the lines ``reproduce`` printed. Tests that
    change a run work on a copy (``copy_run``)."""
    return tiny_run.folder, tiny_run.summary, tiny_run.lines


def data_cfg() -> dict:
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        from omegaconf import OmegaConf

        return OmegaConf.to_container(compose(config_name="reproduce", overrides=DATA).data, resolve=True)


def eval_cfg() -> dict:
    return {"samples": {"table_5_1": 50, "variance": 100, "metrics": 50}, "classifier": {"components": 6}}


def test_reproduce_runs_every_stage_into_a_report(reproduced) -> None:
    out, summary, lines = reproduced
    assert [s["name"] for s in summary["stages"]] == [
        "autoencoder", "vae walk_leftStance", "vae walk_rightStance", "cvae walk_leftStance/elderly",
        "cvae walk_leftStance/youthful", "cvae walk_rightStance/elderly", "cvae walk_rightStance/youthful"]
    assert {s["status"] for s in summary["stages"]} == {"trained"}
    assert [line[:5] for line in lines if line.startswith("[")] == [f"[{k}/9]" for k in range(1, 10)]
    report = json.loads((out / "report" / "report.json").read_text())
    for primitive in ("walk_leftStance", "walk_rightStance"):
        assert report["table_5_1"][primitive]["models"] == ["neutral", "elderly", "youthful"]
    assert report["style_recognition"]["classifier_heldout_accuracy"] >= 0.8  # real clips, chance 1/3
    assert len(report["meta"]["checkpoints"]) == 6 and report["meta"]["samples"]["variance"] == 300
    assert (out / "cvae" / "walk_leftStance_elderly" / "samples").is_dir()  # the training stages' GIFs
    assert lines[0] == "budget: budget/synthetic"


def test_the_run_records_paths_relative_to_its_folder(reproduced) -> None:
    """reproduce.json, done.json, evaluation.json and report.json name files inside the run relative to
    it (so a moved run describes itself); the autoencoder the models embed is the stage's."""
    out, _, _ = reproduced
    summary = json.loads((out / "reproduce.json").read_text())
    assert summary["report"] == "report"
    recorded = summary["provenance"]
    assert recorded["stylemotion_version"] == stylemotion.__version__ and recorded["git_commit"]
    vae = "vae/walk_leftStance/checkpoints/best.ckpt"
    assert [s["folder"] for s in summary["stages"]][:2] == ["autoencoder", "vae/walk_leftStance"]
    assert summary["stages"][1]["checkpoint"] == vae and (out / vae).is_file()
    assert json.loads((out / "vae" / "walk_leftStance" / "done.json").read_text())["checkpoint"] == vae
    assert json.loads((out / "evaluation.json").read_text())["report"] == "report"
    meta = json.loads((out / "report" / "report.json").read_text())["meta"]
    assert meta["paths_relative_to"] == ".." and meta["autoencoder"]["path"] == "autoencoder/checkpoints/best.ckpt"
    assert meta["checkpoints"][0]["path"] == vae
    raw = torch.load(out / vae, weights_only=True)
    ae = torch.load(out / "autoencoder" / "checkpoints" / "best.ckpt", weights_only=True)["state_dict"]
    assert all(torch.equal(raw["autoencoder"]["state_dict"][k], v) for k, v in ae.items())


def test_parallel_stages_train_the_same_models_as_sequential_ones(reproduced, tmp_path: Path) -> None:
    """workers=2 (the fixture: VAEs and CVAEs in spawned processes) and workers=1 (all in this process)
    give the same models: same seeds, one torch thread each. The sequential run trains the fixture's stages of
    one primitive and one style (the same settings): the same stages, the same Table 5.1 entries."""
    out, parallel, _ = reproduced
    sequential = reproduce(tiny_overrides(tmp_path / "seq") + ["workers=1", "primitives=[walk_leftStance]",
                                                                "styles=[elderly]"], [])
    names = ["autoencoder", "vae walk_leftStance", "cvae walk_leftStance/elderly"]
    assert [s["name"] for s in sequential["stages"]] == names
    assert {s["status"] for s in sequential["stages"]} == {"trained"}
    by_name = {s["name"]: s for s in parallel["stages"]}
    for b in sequential["stages"]:
        a = by_name[b["name"]]
        assert a["metrics"]["global_step"] == b["metrics"]["global_step"]
        assert a["metrics"]["test"] == pytest.approx(b["metrics"]["test"], rel=1e-5), a["name"]

    def table(folder: Path, models: int) -> list[float]:
        rows = json.loads((folder / "report" / "report.json").read_text())["table_5_1"]["walk_leftStance"]["distance"]
        return [value for row in rows[:models] for value in row[:models]]

    assert table(tmp_path / "seq", 2) == pytest.approx(table(out, 2), rel=1e-5)  # neutral and elderly


def test_rerun_reuses_finished_stages_and_resumes_an_interrupted_one(tiny_run, tmp_path: Path, capsys,
                                                                      monkeypatch) -> None:
    out = copy_run(tiny_run, tmp_path / "run")
    interrupted = out / "cvae" / "walk_leftStance_youthful"
    (interrupted / "done.json").unlink()  # as if killed after its last checkpoint
    before = (out / "report" / "report.json").read_text()
    proc = run_command("reproduce", *tiny_overrides(out), capsys=capsys, monkeypatch=monkeypatch)
    assert proc.returncode == 0, proc.stderr[-3000:]
    steps = [line for line in proc.stdout.splitlines() if line.startswith("[")]
    assert sum(": reused " in line for line in steps) == 7, proc.stdout  # autoencoder, 2 vaes, 3 cvaes, report
    assert f"resuming from {interrupted / 'checkpoints' / 'last.ckpt'}" in proc.stdout
    log_text = max((out / "hydra").glob("*/reproduce.log"), key=lambda f: f.stat().st_mtime).read_text()
    assert "resuming from" in log_text and "report:" in log_text  # the run folder keeps what the console showed
    assert (interrupted / "done.json").is_file()
    assert (out / "report" / "report.json").read_text() == before


def test_a_moved_run_reuses_its_own_stages(reproduced, tmp_path: Path) -> None:
    """A run folder copied elsewhere resumes there: every stage and the report are reused from the copy."""
    out, _, _ = reproduced
    moved = tmp_path / "moved"
    shutil.copytree(out, moved)
    record = (moved / "reproduce.json").read_bytes()
    lines: list[str] = []
    summary = reproduce(tiny_overrides(moved), lines)
    reused = [line for line in lines if line.startswith("[") and ": reused " in line]
    assert len(reused) == 8 and all(str(moved) in line for line in reused), lines
    assert {s["status"] for s in summary["stages"]} == {"reused"}
    assert (moved / "reproduce.json").read_bytes() == record  # a finished run's record is left as it was


def test_changed_settings_are_refused_not_overwritten(tiny_run, tmp_path: Path) -> None:
    out = copy_run(tiny_run, tmp_path / "run")
    done = (out / "vae" / "walk_leftStance" / "done.json").read_text()
    with pytest.raises(StageConflictError, match="other settings") as err:
        reproduce(tiny_overrides(out, vae_epochs=13), [])
    assert str(out / "vae" / "walk_leftStance") in str(err.value)
    assert (out / "vae" / "walk_leftStance" / "done.json").read_text() == done


def test_a_stage_trained_before_a_default_changed_is_refused_not_reused(tiny_run, tmp_path: Path) -> None:
    """The overrides are the same but a config default differs from what the stage was trained with: as recorded
    in its done.json, or (records written before they held the config) as its checkpoint's hyperparameters say."""
    out = copy_run(tiny_run, tmp_path / "run")
    stage = out / "cvae" / "walk_leftStance_elderly"
    record = json.loads((stage / "done.json").read_text())
    assert record["config"]["model.style_duration_weight"] == 50.0  # the experiment's default, not overridden
    record["config"]["model.style_duration_weight"] = 0.0
    (stage / "done.json").write_text(json.dumps(record))
    with pytest.raises(StageConflictError, match=r"model\.style_duration_weight=0\.0 \(now 50\.0\)") as err:
        reproduce(tiny_overrides(out), [])
    assert str(stage) in str(err.value)

    del record["config"]  # an older record: the checkpoint says what the model was trained with
    (stage / "done.json").write_text(json.dumps(record))
    checkpoint = out / record["checkpoint"]
    saved = torch.load(checkpoint, weights_only=False)
    del saved["hyper_parameters"]["style_duration_weight"]  # saved before the option existed: trained at 0
    torch.save(saved, checkpoint)
    before = checkpoint.read_bytes()
    with pytest.raises(StageConflictError, match=r"model\.style_duration_weight=0\.0 \(now 50\.0\)"):
        reproduce(tiny_overrides(out), [])
    assert checkpoint.read_bytes() == before and json.loads((stage / "done.json").read_text()) == record


def test_another_report_of_the_same_stages_judges_on_test_clips_only(tiny_run, tmp_path: Path) -> None:
    """``report=report_test`` with test-only evaluation settings: every stage reused, a second report beside the
    run's (its record in ``evaluation_report_test.json``), the style models judged on fewer clips (their style's
    test clips only); the run's own report and ``reproduce.json`` untouched; a rerun reuses it."""
    out = copy_run(tiny_run, tmp_path / "run")
    kept = {name: (out / name).read_bytes() for name in ("reproduce.json", "evaluation.json", "report/report.json")}
    test = ["report=report_test", "evaluation.heldout_splits=[test]", "evaluation.style_truth=heldout"]
    lines: list[str] = []
    summary = reproduce(tiny_overrides(out) + test, lines)
    assert {s["status"] for s in summary["stages"]} == {"reused"} and summary["report"] == "report_test"
    assert {name: (out / name).read_bytes() for name in kept} == kept
    report = json.loads((out / "report_test" / "report.json").read_text())
    main = json.loads((out / "report" / "report.json").read_text())
    assert report["meta"]["settings"]["style_truth"] == "heldout"
    assert report["meta"]["settings"]["heldout_splits"] == ["test"]
    clips = [(report["frechet_reference"][p][m]["ground_truth_clips"], ms[m]["ground_truth_clips"])
             for p, ms in main["frechet_reference"].items() for m in ms if m != "neutral"]
    assert clips and all(0 < test_count < all_count for test_count, all_count in clips), clips
    assert (out / "evaluation_report_test.json").is_file()
    lines.clear()
    reproduce(tiny_overrides(out) + test, lines)
    assert any("evaluation: reused" in line for line in lines), lines


@pytest.mark.parametrize("name", ["cvae", "a/b", "..", "evaluation.json"])
def test_a_report_name_that_is_not_a_free_folder_name_is_refused_before_training(tmp_path: Path, name: str) -> None:
    out = tmp_path / "run"
    with pytest.raises(ConfigError, match=f"report: '{re.escape(name)}' is not a report folder name"):
        reproduce(tiny_overrides(out) + [f"report={name}"], [])
    assert not (out / "autoencoder").exists() and not (out / "data.json").exists()


def test_eval_cli_writes_a_report_and_refuses_an_existing_folder(reproduced, tmp_path: Path, capsys,
                                                                 monkeypatch) -> None:
    """``stylemotion-eval`` (in-process) on the run's models of walk_leftStance: folders of checkpoints."""
    out, _, _ = reproduced
    report = tmp_path / "eval"
    models = [out / "vae" / "walk_leftStance", out / "cvae" / "walk_leftStance_elderly",
              out / "cvae" / "walk_leftStance_youthful"]
    args = [*DATA, f"checkpoints=[{','.join(map(str, models))}]", f"out={report}",
            "evaluation.samples.table_5_1=50", "evaluation.samples.variance=100", "evaluation.samples.metrics=50",
            "evaluation.classifier.components=6", "threads=1"]
    done = run_command("evaluate", *args, cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "Table 5.1 walk_leftStance" in done.stdout and (report / "report.md").is_file()
    saved = json.loads((report / "report.json").read_text())
    assert saved["meta"]["autoencoder"]["path"] == str((out / "autoencoder" / "checkpoints" / "best.ckpt").resolve())
    assert saved["table_5_1"]["walk_leftStance"]["models"] == ["neutral", "elderly", "youthful"]
    done = run_command("evaluate", *args, cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    assert done.returncode != 0 and "already exists" in done.stderr
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


def test_what_runs_alone_gets_every_core_unless_told() -> None:
    from stylemotion.training.reproduction import alone_threads

    assert alone_threads(None) == len(os.sched_getaffinity(0))
    assert alone_threads(3) == 3
    with pytest.raises(ValueError, match="alone_threads must be a whole number ≥ 1"):
        alone_threads(0)


def test_the_autoencoder_stage_trains_with_the_alone_threads(tmp_path: Path, monkeypatch) -> None:
    import stylemotion.training.fit as fit_module
    from stylemotion.training.reproduction import Reproduction

    seen: list[int] = []
    original = fit_module.set_torch_threads
    monkeypatch.setattr(fit_module, "set_torch_threads", lambda value, *a: seen.append(value) or original(value, *a))

    def stop(*args, **kwargs):
        raise RuntimeError("stop after the autoencoder stage")

    monkeypatch.setattr(Reproduction, "run_stages_in_parallel", stop)
    with pytest.raises(RuntimeError, match="stop after the autoencoder stage"):
        reproduce(tiny_overrides(tmp_path / "run") + ["alone_threads=2"], [])
    assert seen == [2]  # the stage ran in this process with 2 threads, not the run's threads=1


@pytest.mark.parametrize("override", ["workers=0", "workers=-2", "workers=two", "workers=1.5", "threads=abc",
                                      "threads=0"])
def test_bad_workers_or_threads_value_is_refused_before_any_work(tmp_path: Path, override) -> None:
    key, value = override.split("=")
    with pytest.raises(ValueError, match=rf"{key} must be a whole number ≥ 1, got '?{value}'?"):
        reproduce(tiny_overrides(tmp_path / "run") + [override], [])
    assert not (tmp_path / "run").exists()


# -- style labels as folder names, a user's data, stages on submitit


def test_style_labels_cannot_place_a_stage_outside_the_run(tmp_path: Path) -> None:
    """CVAE folders come from style labels: sanitized, inside ``out``, and two labels never share one."""
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose(config_name="reproduce", overrides=[f"out={tmp_path / 'run'}", "primitives=[walk_leftStance]"])
    repro = Reproduction(cfg)
    repro.plan(["/../../../../escaped", "a b/c"])
    cvae = [s.folder for s in repro.stages if s.kind == "cvae"]
    assert [f.resolve().parent for f in cvae] == [(tmp_path / "run" / "cvae").resolve()] * 2, cvae
    assert [f.name for f in cvae] == ["walk_leftStance_escaped", "walk_leftStance_a_b_c"]
    assert [s.values["style"] for s in repro.stages if s.kind == "cvae"] == ["/../../../../escaped", "a b/c"]
    with pytest.raises(ValueError, match=r"style label '\.\.' has no character usable in a file name"):
        repro.plan([".."])
    with pytest.raises(ValueError, match=r"style labels 'a/b' and 'a_b' would share the folder"):
        repro.plan(["a/b", "a_b"])



def test_a_null_retarget_keeps_the_stage_hashes_of_earlier_runs(tmp_path: Path) -> None:
    """``data.retarget: null`` (the default) hashes like a data config written before the key existed, so
    the finished stages of earlier runs stay valid; a style name is other data."""
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose(config_name="reproduce", overrides=[f"out={tmp_path / 'run'}", "primitives=[walk_leftStance]"])
        repro = Reproduction(cfg)
        repro.plan([])
        stage = repro.stages[0]
        hashes = {}
        for retarget in ("absent", None, "normal"):
            repro.data_cfg.pop("retarget", None)
            if retarget != "absent":
                repro.data_cfg["retarget"] = retarget
            repro.prepare_stage(1, stage)  # composes the stage's config: Hydra's config search is needed
            hashes[retarget] = stage.settings_hash
    assert hashes[None] == hashes["absent"] != hashes["normal"]
    assert cfg.data.retarget is None

def write_user_configs(folder: Path) -> Path:
    """A user's config folder holding ``data/mine.yaml``: a BVH folder with labels from file names, and
    no ``budget/mine.yaml``."""
    (folder / "data").mkdir(parents=True)
    (folder / "data" / "mine.yaml").write_text(
        "# my capture: <style>_<take>.bvh\ndefaults:\n  - bvh_folder\n  - _self_\n\nroot: ~/mocap\n"
        "pattern: (?P<style>[a-z]+)_(?P<take>\\d+)\ndefault_labels: {content: walk}\n")
    return folder


def test_data_without_a_budget_of_its_own_uses_the_default_budget(tmp_path: Path) -> None:
    configs = write_user_configs(tmp_path / "configs")
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose(config_name="reproduce", overrides=[f"hydra.searchpath=[file://{configs}]", "data=mine"])
        bandai = compose(config_name="reproduce", overrides=["data=bandai"])
    assert cfg.get("budget") is None and cfg.data.pattern == "(?P<style>[a-z]+)_(?P<take>\\d+)"
    assert choose_budget(cfg).startswith("budget: budget/default (there is no budget")
    assert list(cfg.stages.vae) == ["experiment=primitive_vae", "trainer.max_epochs=100", "model.samples_per_item=10",
                                    "callbacks.checkpoint_last.every_n_epochs=1"]
    assert list(cfg.stages.cvae)[1:] == list(bandai.stages.cvae)[1:] == [
        "trainer.max_epochs=60", "model.samples_per_item=10", "callbacks.checkpoint_last.every_n_epochs=1",
        "model.style_weight=5.0"]
    assert choose_budget(bandai) == "budget: budget/bandai"


def write_user_mocap(folder: Path) -> None:
    """The tiny synthetic takes as ``<style>_<take>.bvh`` files."""
    from vae_fixtures import tiny_takeset

    from stylemotion.io.export import write_motion_bvh

    folder.mkdir(parents=True)
    for take in tiny_takeset().takes:
        write_motion_bvh(take.positions, folder / f"{take.labels['style']}_{take.labels['take']}.bvh", take.fps)


def test_readme_regex_example_runs(tmp_path: Path) -> None:
    """The bvh_folder line of docs/commands.md with a file-name regex, run as written (``~`` is the user's home)."""
    readme = (Path(__file__).resolve().parents[1] / "docs" / "commands.md").read_text()
    line = next(x for x in readme.splitlines() if "data.pattern=" in x and x.startswith("stylemotion-data"))
    home = tmp_path / "home"
    write_user_mocap(home / "mocap")
    env = {**os.environ, "HOME": str(home), "OMP_NUM_THREADS": "1"}
    proc = subprocess.run(["bash", "-c", line.split("#")[0]], capture_output=True, text=True, cwd=tmp_path, env=env,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    summary = json.loads(next((tmp_path / "runs" / "prepare").rglob("summary.json")).read_text())
    assert all(style in json.dumps(summary) for style in ("normal", "elderly", "youthful")), summary


@pytest.mark.slow
def test_a_users_bvh_folder_end_to_end_with_stages_as_submitit_jobs(tmp_path: Path, monkeypatch) -> None:
    """``stylemotion-reproduce data=<their config>`` with ``~`` paths and executor=local (submitit's
    LocalExecutor): a stage that fails does not lose the ones that finish, a rerun resumes and reuses."""
    home = tmp_path / "home"
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.setenv("OMP_NUM_THREADS", "1")
    write_user_mocap(home / "mocap")
    configs = write_user_configs(tmp_path / "configs")
    user = [f"hydra.searchpath=[file://{configs}]", "data=mine", 'data.root="~/mocap"', "executor=local", "workers=2",
            "primitives=[walk_leftStance]"]
    overrides = [o for o in tiny_overrides(home / "x")  # the user's data has no budget: the default one
                 if not o.startswith(("data.", "out=", "primitives=", "++budget."))] + user
    out = home / "runs" / "mine"
    blocker = out / "cvae" / "walk_leftStance_youthful" / "checkpoints"
    blocker.parent.mkdir(parents=True)
    blocker.write_text("a file where the youthful stage saves its checkpoints: that job fails")
    lines: list[str] = []
    with pytest.raises(RuntimeError, match=r"1 training stage\(s\) failed \(cvae walk_leftStance/youthful\)"):
        reproduce(overrides + ['out="~/runs/mine"'], lines)
    assert lines[0].startswith("budget: budget/default")
    assert any("youthful FAILED" in line for line in lines), lines
    summary = json.loads((out / "reproduce.json").read_text())
    assert {s["name"]: s["status"] for s in summary["stages"]} == {
        "autoencoder": "trained", "vae walk_leftStance": "trained", "cvae walk_leftStance/elderly": "trained",
        "cvae walk_leftStance/youthful": "pending"}
    for stage in ("vae/walk_leftStance", "cvae/walk_leftStance_elderly"):
        assert (out / stage / "done.json").is_file() and any((out / stage / "submitit").iterdir()), stage
    assert not (out / "cvae" / "walk_leftStance_youthful" / "done.json").exists()

    blocker.unlink()
    (out / "cvae" / "walk_leftStance_elderly" / "done.json").unlink()  # as if its job was killed at the end
    lines = []
    summary = reproduce(overrides + ['out="~/runs/mine"'], lines)
    steps = [line for line in lines if line.startswith("[")]
    assert sum(": reused " in line for line in steps) == 2, steps  # autoencoder, vae
    assert any("resuming from" in line and "walk_leftStance_elderly" in line for line in lines), lines
    assert [s["status"] for s in summary["stages"]] == ["reused", "reused", "resumed", "trained"]
    assert summary["report"] == "report" and (out / "report" / "report.md").is_file()
    report = json.loads((out / "report" / "report.json").read_text())
    assert report["table_5_1"]["walk_leftStance"]["models"] == ["neutral", "elderly", "youthful"]


def test_an_unknown_executor_is_refused_before_any_work(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match=r"'executor.engine' must be one of \['pool', 'local', 'slurm'\], got 'sge'"):
        reproduce(tiny_overrides(tmp_path / "run") + ["executor.engine=sge"], [])
    assert not (tmp_path / "run").exists()


def test_slurm_executor_submits_the_configured_job(tmp_path: Path, monkeypatch) -> None:
    """executor=slurm: the sbatch script submitit writes carries the config's partition and resources
    (``sbatch``/``srun`` are stand-ins here: no cluster)."""
    from stylemotion.training.reproduction import submitit_executor

    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / "sbatch").write_text("#!/bin/sh\necho 'Submitted batch job 4242'\n")
    (bin_dir / "srun").write_text("#!/bin/sh\nexit 0\n")
    for tool in bin_dir.iterdir():
        tool.chmod(0o755)
    monkeypatch.setenv("PATH", f"{bin_dir}{os.pathsep}{os.environ['PATH']}")
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose(config_name="reproduce", overrides=["executor=slurm", "executor.partition=cpu",
                                                          "executor.parameters.mem_gb=16"])
    executor = submitit_executor(cfg.executor, tmp_path / "jobs", "slurm", "stylemotion-vae-walk_leftStance")
    assert executor.submit(print, "a stage").job_id == "4242"
    script = (tmp_path / "jobs" / "4242_submission.sh").read_text()
    for line in ("--partition=cpu", "--mem=16GB", "--cpus-per-task=8", "--time=240",
                 "--job-name=stylemotion-vae-walk_leftStance"):
        assert f"#SBATCH {line}" in script, script
