"""``stylemotion-eval`` on a zero-shot style network (issues 27 item 3, 30): the network is evaluated once per style
example it is bound to — each style's CVAE example by default, or a user's recording — with the rows of every other
model (Tables 5.1–5.3, recognition, variation), named by kind; its recognition and its Table 5.1 row recomputed
here from samples drawn by binding the network to the same clips by hand; the shift baseline's Table 5.1 row
recomputed by hand (and a shift of zero giving the neutral samples); and the one-line errors of an example that is
missing or does not fit.

The network: trained here for two epochs on the shared tiny reproduce run's data and autoencoder (conftest's
``tiny_run``: walks of normal, elderly and youthful; CVAEs of elderly and youthful).
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
import torch
from cli_runner import run_command
from conftest import tiny_bvh_text
from recognition_reference import example_gram, hand_share
from reproduce_fixtures import DATA
from style_fixtures import example_bvh

from stylemotion.datasets import build_dataset
from stylemotion.evaluation.pipeline import ShiftBaseline
from stylemotion.evaluation.reference import primitive_data
from stylemotion.evaluation.run import run_evaluation, settings_from_config
from stylemotion.evaluation.sources import MissingExampleError, motions_from_clips
from stylemotion.evaluation.zero_shot import network_train_config, read_run, train_once
from stylemotion.models.checkpoints import MissingCheckpointError, find_checkpoints, load_autoencoder
from stylemotion.models.loading import load_generative, load_model
from stylemotion.primitives.segmentation import time_normalize
from stylemotion.synthesis.graph import available_models

PRIMITIVE, SEED = "walk_leftStance", 3
#: The network: tiny, two epochs, quiet.
NETWORK = ["model.hidden=[64,32]", "model.embedding_dim=8", "model.samples_per_item=4", "datamodule.min_train_clips=8",
           "trainer.enable_model_summary=false", "trainer.num_sanity_val_steps=0", "~logger",
           "trainer.enable_progress_bar=false", "callbacks.progress_bar=null"]
#: Small samples: Table 5.1 on 40, Tables 5.2/5.3 on 60, recognition and the other metrics on 40.
EVAL = {"samples": {"table_5_1": 40, "variance": 60, "metrics": 40}, "classifier": {"components": 8}}


@pytest.fixture(scope="module")
def run(tiny_run) -> Path:
    return tiny_run.folder


@pytest.fixture(scope="module")
def network(run, tmp_path_factory) -> Path:
    """A zero-shot network of walk_leftStance on the run's data (every style) and autoencoder: its checkpoint."""
    folder = tmp_path_factory.mktemp("zero_shot") / "network"
    path, _ = train_once(network_train_config(read_run(run), PRIMITIVE, folder, 2, NETWORK, threads=1), "network")
    return path


def checkpoints(run: Path) -> dict[str, str]:
    """The run's models of walk_leftStance: name (neutral, elderly, youthful) → checkpoint."""
    return {e["name"]: e["path"] for e in available_models(run) if e["primitive"] == PRIMITIVE}


def evaluate(run: Path, out: Path, paths, **kwargs) -> dict:
    return run_evaluation(read_run(run).data_cfg, [str(p) for p in paths], EVAL, out, seed=SEED, **kwargs)


@pytest.mark.slow  # a network trained (2 epochs), one evaluation of five models: ~1 min on a busy core
def test_a_zero_shot_network_and_the_shift_baseline_are_rows_as_computed_by_hand(run, network, tmp_path):
    models = checkpoints(run)
    results = evaluate(run, tmp_path / "report", [*models.values(), network])
    kinds = {m["name"]: m["kind"] for m in results["models"]}
    assert kinds == {"neutral": "vae", "elderly": "cvae", "youthful": "cvae", "zero_shot:elderly": "zero_shot",
                     "zero_shot:youthful": "zero_shot"}
    assert {c["name"]: c["kind"] for c in results["meta"]["checkpoints"]} == kinds
    table = results["table_5_1"][PRIMITIVE]
    # its example is the CVAE's column: a row against the columns, no second column of the same example
    assert table["models"] == ["neutral", "elderly", "youthful"]
    shared = table["shared_columns"]
    assert {n: s["column"] for n, s in shared.items()} == {"zero_shot:elderly": "elderly",
                                                          "zero_shot:youthful": "youthful"}
    for name, row in shared.items():
        assert row["row_argmin"] == table["models"][int(np.argmin(table["extra_rows"][name]))]
    for key in ("variance", "variance_ratio", "variation_vs_style", "diversity", "foot_skating_detail"):
        assert {"zero_shot:elderly", "zero_shot:youthful"} <= set(results[key][PRIMITIVE]), key
    assert results["variance"][PRIMITIVE]["zero_shot:elderly"] != results["variance"][PRIMITIVE]["elderly"]
    text = (tmp_path / "report" / "report.md").read_text()
    assert "| walk_leftStance | zero_shot:elderly | zero_shot | elderly |" in text
    assert "*zero_shot:elderly* (example of elderly)" in text

    # by hand: the network bound to the elderly CVAE's example clip(s), found in the data here; its samples (one
    # draw of the largest count, seed SEED) judged by a classifier fitted here and by Grams of the run's autoencoder
    source, settings = read_run(run), settings_from_config(EVAL, SEED)
    judge = load_autoencoder(source.autoencoder_ckpt)
    cvae = load_model(models["elderly"], settings.neutral_style, judge)
    length = cvae.timeline_frames
    data = primitive_data(build_dataset(source.data_cfg), PRIMITIVE, length, settings.neutral_style,
                          asdict(settings.segment), source.data_cfg.get("split"))
    bound = load_generative(network).bind_example([data.find_example(r) for r in cvae.examples])
    drawn = bound.sample(60, seed=SEED)
    frames, duration = drawn.normalized_frames[:40], drawn.duration_s[:40]
    share = hand_share(data.split("train"), length, frames.numpy(), duration.numpy(), "elderly",
                       settings.classifier.components, settings.classifier.C, settings.seed)
    assert results["style_recognition"]["per_model_detail"][PRIMITIVE]["zero_shot:elderly"]["share"] == share
    with torch.no_grad():
        features = judge.encode(frames.float())
    grams = features @ features.transpose(-1, -2) / features.shape[-1]
    own = float(torch.linalg.matrix_norm(grams - example_gram(judge, data, cvae)).mean())
    column = table["models"].index("elderly")
    assert table["extra_rows"]["zero_shot:elderly"][column] == pytest.approx(own, rel=1e-4)

    # the shift baseline of each style column, by hand: the neutral VAE's samples (the same draw) moved by the
    # elderly example's mean features minus the neutral train clips' mean features, decoded, re-encoded, Grams
    assert results["extra_rows"][PRIMITIVE] == ["shift:elderly", "shift:youthful"]
    assert {"shift:elderly", "shift:youthful"} <= set(results["variance"][PRIMITIVE])
    assert "shift:elderly" not in results["style_recognition"]["per_model"]
    vae = load_model(models["neutral"], settings.neutral_style, judge).source
    examples = [data.find_example(r) for r in cvae.examples]

    def encoded(clips) -> torch.Tensor:
        return judge.encode(torch.from_numpy(np.stack([time_normalize(c.frames, length) for c in clips])).float())

    with torch.no_grad():
        shift = encoded(examples).mean(0) - encoded(data.training_data()).mean(0)
        features = judge.encode(judge.decode(vae.sample(60, seed=SEED).features[:40] + shift, length).float())
    grams = features @ features.transpose(-1, -2) / features.shape[-1]
    own = float(torch.linalg.matrix_norm(grams - example_gram(judge, data, cvae)).mean())
    assert table["extra_rows"]["shift:elderly"][column] == pytest.approx(own, rel=1e-4)
    assert "*shift:elderly* (shift baseline)" in text and "| shift:elderly |" in text
    # a baseline whose example is the neutral train clips themselves does not move: the neutral samples
    training = motions_from_clips(data.training_data(), length)
    same = ShiftBaseline(vae, judge, data.training_data(), training, length)
    assert float(same.shift.abs().max()) < 1e-4 and abs(same.log_duration_shift) < 1e-6
    torch.testing.assert_close(same.sample(8, seed=1).positions, vae.sample(8, seed=1).positions, atol=1e-3,
                               rtol=0)


@pytest.mark.slow  # the network of the test above, one evaluation of two models
def test_a_users_recordings_get_their_own_column(run, network, tmp_path):
    bvh, other = example_bvh(tmp_path, style="elderly"), example_bvh(tmp_path, style="elderly", fps=30.0)
    results = evaluate(run, tmp_path / "report", [checkpoints(run)["neutral"], network], example=[str(bvh), str(other)],
                       example_style="elderly")
    table = results["table_5_1"][PRIMITIVE]
    assert table["models"] == ["neutral", "zero_shot:elderly"] and "shared_columns" not in table
    (model,) = [m for m in results["models"] if m["kind"] == "zero_shot"]
    assert model["style"] == "elderly" and model["examples"]
    # the steps of both recordings, pooled; at the data's 30 fps, and where they lie in each file
    assert {r["file"] for r in model["examples"]} == {str(bvh), str(other)}
    assert all(r["take"] == Path(r["file"]).stem and r["file_frames"][0] == r["start"] * r["file_fps"] / 30
               for r in model["examples"])
    assert len(table["example_clips"]["zero_shot:elderly"]) == len(model["examples"])
    assert all(bvh.stem in clip or other.stem in clip for clip in table["example_clips"]["zero_shot:elderly"])
    assert results["style_recognition"]["per_model_detail"][PRIMITIVE]["zero_shot:elderly"]["target_style"] == \
        "elderly"


@pytest.mark.slow  # the shared tiny run (no network needed)
@pytest.mark.parametrize("kwargs, message", [
    ({"example": "{bvh}", "example_style": "elderly"}, "conditions zero-shot networks, but checkpoints= holds none"),
    ({"example_style": "elderly"}, "example_style=elderly names the style of example=, which is not given"),
    ({"example_conversion": {"joint_map": "cmu21", "unit_scale": None, "up_axis": "y"}},
     "joint_map=cmu21 reads the file of example=, which is not given"),
])
def test_an_example_without_a_network_to_bind_is_refused(run, tmp_path, kwargs, message):
    bvh = example_bvh(tmp_path, style="elderly")
    kwargs = {k: v.format(bvh=bvh) if isinstance(v, str) else v for k, v in kwargs.items()}
    with pytest.raises(MissingExampleError, match=message):
        evaluate(run, tmp_path / "report", [checkpoints(run)["neutral"]], **kwargs)
    assert not (tmp_path / "report").exists()


@pytest.mark.slow  # the network of the first test
def test_a_folder_of_zero_shot_networks_only_names_them_in_one_line(network):
    assert network.parent.name == "checkpoints"
    with pytest.raises(MissingCheckpointError, match="zero-shot networks only") as refused:
        find_checkpoints([str(network.parent.parent)])
    assert str(network) in str(refused.value) and "\n" not in str(refused.value)
    assert find_checkpoints([str(network)]) == [network]  # named, it is taken


@pytest.mark.slow  # the network of the first test; each refusal before any sample is drawn
@pytest.mark.parametrize("example, style, message", [
    ("{missing}", "elderly", "example={missing}: "),
    ("{skeleton}", "elderly", "example={skeleton}: "),
    ("{short}", "elderly", "no complete step of the run's primitives"),
    ("{bvh}", "", "needs example_style=<a style of the data>"),
    ("{skeleton}", "elderly", "joint_map=<map.yaml>"),
    ("{bvh} joint_map=cmu31", "elderly", "example={bvh}: "),
    ("{bvh} unit_scale=-3", "elderly", "example={bvh}: "),
])
def test_an_example_that_is_missing_or_does_not_fit_is_one_line(run, network, tmp_path, capsys, monkeypatch,
                                                                 example, style, message):
    (tmp_path / "short").mkdir()
    files = {"missing": tmp_path / "missing.bvh", "skeleton": tmp_path / "four_joints.bvh",
             "short": example_bvh(tmp_path / "short", style="elderly", duration_s=0.5),
             "bvh": example_bvh(tmp_path, style="elderly")}
    files["skeleton"].write_text(tiny_bvh_text())
    assert files["short"] != files["bvh"]
    (example, *conversion), message = example.format(**files).split(" "), message.format(**files)
    args = ["data=synthetic", *DATA, f"checkpoints=[{network}]", f"example={example}", *conversion, "out=report",
            "hydra.run.dir=hydra", "evaluation.samples.table_5_1=4", "evaluation.samples.variance=4",
            "evaluation.samples.metrics=4"] + ([f"example_style={style}"] if style else [])
    done = run_command("evaluate", *args, capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-eval: ") and message in line, line
    assert not (tmp_path / "report").exists()
