"""``stylemotion-style method=zero_shot`` on the tiny synthetic reproduce run: the networks are trained inside the
command on every style of the run and bound to the example, the report is the ``cvae`` one plus the network; a
second style with ``network=<first out>/network`` trains nothing and gives the same row; a wrong network is
refused with a clear message and nothing written; ``stylemotion-generate`` walks in a zero-shot style."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest
import torch
import yaml
from log_lines import logged_lines
from style_fixtures import NETWORK_EPOCHS, SAMPLES, example_bvh, tiny_zero_shot_style

from stylemotion.config import ConfigError
from stylemotion.models.loading import load_generative
from stylemotion.models.zero_shot import BoundExample, ZeroShotStyleVAE
from stylemotion.style_example import StyleExampleError, add_style
from stylemotion.style_example.evaluate import variation
from stylemotion.style_example.zero_shot import sampling_defaults
from stylemotion.synthesis import load_graph
from stylemotion.synthesis.generate import generate

torch.set_num_threads(1)
PRIMITIVES = ("walk_leftStance", "walk_rightStance")
SHORT = {"path": {"points": [[0, 0], [0, 2.5]], "spline": False}, "follow": {"candidates": 32, "iterations": 5},
         "outputs": {"bvh": False, "gif": False}, "seed": 0}


@pytest.fixture(scope="session")
def zero_shot(tiny_run) -> tuple[Path, dict]:
    return tiny_zero_shot_style(tiny_run.folder)


@pytest.fixture(scope="session")
def run(tiny_run) -> Path:
    return tiny_run.folder


@pytest.fixture(scope="session")
def reused(zero_shot, run) -> tuple[Path, dict, dict[str, int]]:
    """A second style from the same example, with the first call's networks: its folder, report and the
    networks' checkpoint times before the call."""
    networks = zero_shot[0] / "network"
    before = {str(p): p.stat().st_mtime_ns for p in networks.rglob("*") if p.is_file()}
    out = zero_shot[0].parent / "weary_again"
    with logged_lines("stylemotion.style_example") as lines:
        results = add_style(str(example_bvh(zero_shot[0].parent)), run, "weary", out, method="zero_shot",
                            network=str(networks), samples=SAMPLES)
    return out, {"results": results, "lines": lines}, before


def test_the_networks_are_trained_in_the_command_on_every_style_and_the_report_is_the_cvae_one(zero_shot,
                                                                                              run) -> None:
    folder, made = zero_shot
    report = json.loads((folder / "report.json").read_text())
    assert report == made["results"] and report["method"] == "zero_shot"
    assert sorted(p.name for p in folder.iterdir()) == ["example", "network", "report.json", "report.md"]  # no cvae/
    run_report = json.loads((run / "report" / "report.json").read_text())
    for p in PRIMITIVES:
        row = report["table_5_1_row"][p]
        assert list(row) == [*run_report["table_5_1"][p]["examples"], "weary"] == ["neutral", "elderly", "youthful",
                                                                                                 "weary"]
        assert all(isinstance(v, float) and math.isfinite(v) and v > 0 for v in row.values()), row
        assert report["nearest_existing_style"][p] == min(("neutral", "elderly"), key=row.get)
        assert not report["example_range"][p]["out_of_range"]
        assert report["variation"][p]["samples"]["motions"] == SAMPLES
        assert report["foot_skating"][p]["samples"]["motions"] == SAMPLES
        checkpoint = f"network/{p}/checkpoints/best.ckpt"
        assert report["models"][p]["checkpoint"] == report["network"]["checkpoints"][p] == checkpoint
        network = load_generative(folder / checkpoint)
        assert isinstance(network, ZeroShotStyleVAE) and network.primitive == p
        assert sorted(network.styles) == ["elderly", "normal", "youthful"] and network.excluded_styles == []
        assert network.spec["autoencoder"]["fingerprint"] == run_report["meta"]["autoencoder"]["fingerprint"]
        assert report["network"]["trained_styles"][p] == network.styles
        examples = report["models"][p]["examples"]  # the clips it is bound to, recorded as a CVAE's
        assert examples and all(e["file"] == str(example_bvh(folder.parent)) and e["style"] == "weary"
                                and e["encoded_frames"] == network.timeline_frames for e in examples)
        entry = next(e for e in report["meta"]["checkpoints"] if e["primitive"] == p)
        assert entry == {"path": checkpoint, "primitive": p, "name": "weary", "style": "weary", "method": "zero_shot",
                         "example": "example/example.npz", "clips": [[e["start"], e["stop"]] for e in examples],
                         "sampling": sampling_defaults()}  # how it sampled: loading the style samples the same
        cfg = yaml.safe_load((folder / "network" / p / "config_resolved.yaml").read_text())
        assert cfg["name"] == "zero_shot" and cfg["trainer"]["max_epochs"] == NETWORK_EPOCHS
        assert cfg["datamodule"]["exclude_styles"] == [] and cfg["seed"] == 0
        assert cfg["data"] == run_report["meta"]["data"] and cfg["autoencoder_ckpt"] == str(run / "autoencoder" /
                                                                                            "checkpoints" / "best.ckpt")
        assert cfg["trainer"]["enable_progress_bar"] is False  # as the run's stages show their training
    assert report["network"] | {"trained_styles": None, "checkpoints": None} == {
        "trained_here": True, "given": None, "epochs": NETWORK_EPOCHS, "trained_styles": None, "checkpoints": None,
        "excluded_styles": {p: [] for p in PRIMITIVES},
        # as configs/model/zero_shot.yaml samples today (chosen on validation clips)
        "sampling": {p: {"temperature": 1.0, "centred": True, "pooling": "per_sample"} for p in PRIMITIVES}}
    steps = [line for line in made["lines"] if line.startswith("[")]
    assert [s[:5] for s in steps] == [f"[{k}/5]" for k in range(1, 6)]
    assert steps[2].startswith(f"[3/5] network walk_leftStance: training ({NETWORK_EPOCHS} epochs) on the clips of "
                               "every style of the run")
    text = (folder / "report.md").read_text()
    assert "method `zero_shot`" in text and "no model was trained for this style" in text
    assert "give `network=<this folder>/network`" in text


def test_a_second_style_with_the_first_network_trains_nothing_and_gives_the_same_row(zero_shot, reused) -> None:
    out, made, before = reused
    report = made["results"]
    assert sorted(p.name for p in out.iterdir()) == ["example", "report.json", "report.md"]  # no network/, no cvae/
    networks = zero_shot[0] / "network"
    assert {str(p): p.stat().st_mtime_ns for p in networks.rglob("*") if p.is_file()} == before  # nothing rewritten
    assert report["network"]["trained_here"] is False and report["network"]["given"] == str(networks)
    assert report["network"]["epochs"] is None
    first = json.loads((zero_shot[0] / "report.json").read_text())
    for p in PRIMITIVES:
        assert report["models"][p]["checkpoint"] == str((networks / p / "checkpoints" / "best.ckpt").resolve())
        # the same network, example and seed: the same samples, so the same row
        assert report["table_5_1_row"][p] == first["table_5_1_row"][p]
        assert all(math.isfinite(v) for v in report["table_5_1_row"][p].values())
    steps = [line for line in made["lines"] if line.startswith("[")]
    assert [s[:5] for s in steps] == [f"[{k}/4]" for k in range(1, 5)]
    assert steps[2].startswith(f"[3/4] network: taken from {networks}, no training")
    assert "taken from" in (out / "report.md").read_text()


# -- refused: nothing is written


def _refused(tmp_path: Path, error: type[Exception], message: str, run: Path, **kwargs) -> None:
    out = tmp_path / "style"
    with pytest.raises(error, match=message):
        add_style(str(example_bvh(tmp_path)), run, "mine", out, samples=10, **kwargs)
    assert not out.exists() and not [p for p in tmp_path.iterdir() if p.name.startswith(".style")]


def _network(folder: Path, primitive: str) -> Path:
    return folder / "network" / primitive / "checkpoints" / "best.ckpt"


def test_a_network_of_another_primitive_or_kind_is_refused(zero_shot, run, tmp_path: Path) -> None:
    right = _network(zero_shot[0], "walk_rightStance")
    _refused(tmp_path, StyleExampleError, rf"network: {right} is the network of walk_rightStance, not of "
             "walk_leftStance", run, method="zero_shot", network={p: str(right) for p in PRIMITIVES})
    cvae = run / "cvae" / "walk_leftStance_elderly" / "checkpoints" / "best.ckpt"
    _refused(tmp_path, StyleExampleError, "is a StyleCVAE, not a zero-shot style network", run, method="zero_shot",
             network={"walk_leftStance": str(cvae), "walk_rightStance": str(right)})
    _refused(tmp_path, StyleExampleError, r"missing \['walk_rightStance'\]", run, method="zero_shot",
             network={"walk_leftStance": str(right)})


def test_a_network_of_another_autoencoder_is_refused(zero_shot, run, tmp_path: Path) -> None:
    """A copy of the left network whose record names other autoencoder weights stands for a network of another
    run: the fingerprint is what the command compares."""
    folder = tmp_path / "other" / "walk_leftStance" / "checkpoints"
    folder.mkdir(parents=True)
    checkpoint = torch.load(_network(zero_shot[0], "walk_leftStance"), map_location="cpu", weights_only=True)
    checkpoint["hyper_parameters"]["spec"]["autoencoder"]["fingerprint"] = "0123456789abcdef"
    torch.save(checkpoint, folder / "best.ckpt")
    shutil.copytree(_network(zero_shot[0], "walk_rightStance").parents[1], tmp_path / "other" / "walk_rightStance")
    _refused(tmp_path, StyleExampleError, r"was trained on another autoencoder \(weights 0123456789abcdef", run,
             method="zero_shot", network=str(tmp_path / "other"))


def test_a_folder_without_networks_and_keys_of_the_other_method_are_refused(zero_shot, run, tmp_path: Path) -> None:
    _refused(tmp_path, StyleExampleError, rf"its networks are in {zero_shot[0] / 'network'}", run, method="zero_shot",
             network=str(zero_shot[0]))
    _refused(tmp_path, StyleExampleError, "is no folder", run, method="zero_shot", network=str(tmp_path / "nowhere"))
    _refused(tmp_path, ConfigError, "network=x is a key of method=zero_shot, not of method=cvae", run, method="cvae",
             network="x")
    _refused(tmp_path, ConfigError, "network_epochs=3 sets the training of a network made here", run,
             method="zero_shot", network=str(zero_shot[0] / "network"), network_epochs=3)
    _refused(tmp_path, ConfigError, "network_epochs must be a whole number", run, method="zero_shot",
             network_epochs=0)


# -- generating with it


def test_generate_walks_in_a_zero_shot_style_bound_to_the_same_clips(zero_shot, tmp_path: Path) -> None:
    folder = zero_shot[0]
    report = json.loads((folder / "report.json").read_text())
    summary = generate({**SHORT, "run": str(folder), "style": "weary", "out": str(tmp_path / "walk")})
    assert summary["meta"]["style"] == "weary" and summary["steps"] >= 3 and summary["walked_m"] > 1.5
    assert summary["meta"]["models"] == {p.split("_")[1]: str(folder / m["checkpoint"])
                                         for p, m in report["models"].items()}
    assert summary["real_foot_skating_ratio"] == pytest.approx(report["foot_skating_pooled"]["example"])
    graph = load_graph("weary", run=folder)
    for p in PRIMITIVES:  # generate binds the clips the report's samples came from: the same samples again
        model = graph.models[p.split("_")[1]]
        assert isinstance(model, BoundExample)
        again = variation(model.sample(SAMPLES, seed=report["meta"]["seed"]))
        assert again["pose_sd"] == pytest.approx(report["variation"][p]["samples"]["pose_sd"], rel=1e-6)


def test_a_style_whose_network_lies_elsewhere_loads_when_both_folders_moved(zero_shot, reused, tmp_path) -> None:
    out = reused[0]
    moved = tmp_path / "moved"
    shutil.copytree(zero_shot[0], moved / zero_shot[0].name)
    shutil.copytree(out, moved / out.name)
    report = json.loads((moved / out.name / "report.json").read_text())
    for entry in report["meta"]["checkpoints"]:  # as if both came from another machine
        entry["path"] = "/nonexistent" + entry["path"]
    (moved / out.name / "report.json").write_text(json.dumps(report))
    graph = load_graph("weary", run=moved / out.name)
    assert graph.sources["leftStance"] == str(_network(moved / zero_shot[0].name, "walk_leftStance"))
