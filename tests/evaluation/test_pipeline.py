"""The evaluation pipeline and report on synthetic data with "oracle models" that draw real clips of
their style: what must hold when the styles are known (Table 5.1 diagonal dominance), the report
folder, and bad input (mixed autoencoders, missing style examples, an existing report folder)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch
from vae_fixtures import TINY_DATA, tiny_autoencoder_ckpt, tiny_takeset

from stylemotion.datamodules.features import describe_clip
from stylemotion.evaluation.pipeline import evaluate_models
from stylemotion.evaluation.reference import primitive_data
from stylemotion.evaluation.report import write_report
from stylemotion.evaluation.settings import ClassifierSettings, EvalSettings, SampleCounts
from stylemotion.evaluation.sources import MissingExampleError, MixedAutoencodersError, RealClipSource
from stylemotion.evaluation.tables import variance_stats
from stylemotion.io.outputs import OutputExistsError
from stylemotion.models.checkpoints import autoencoder_info, load_autoencoder
from stylemotion.models.loading import NEUTRAL, EvalModel, SampleSource

torch.set_num_threads(1)
SETTINGS = EvalSettings(samples=SampleCounts(table_5_1=120, variance=200, metrics=120),
                        classifier=ClassifierSettings(components=8))
PRIMITIVES = ("walk_leftStance", "walk_rightStance")


@pytest.fixture(scope="module")
def autoencoder(tmp_path_factory):
    path = tiny_autoencoder_ckpt(tmp_path_factory.mktemp("eval_ae"))
    ae = load_autoencoder(path)
    return ae, autoencoder_info(ae, path)


def oracle_models(info) -> list[EvalModel]:
    """Per primitive: a neutral model drawing the neutral training clips, and per other style a model
    drawing that style's clips, conditioned on the style's first clip (left out of its draws)."""
    models = []
    for primitive in PRIMITIVES:
        data = primitive_data(tiny_takeset(), primitive, 16, split=TINY_DATA["split"])
        for style in data.styles:
            if style == "normal":
                models.append(EvalModel(NEUTRAL, primitive, style, RealClipSource(data.training_data(), 16),
                                        autoencoder=info, timeline_frames=16, dataset="synthetic"))
                continue
            example, *rest = data.style_clips(style)
            models.append(EvalModel(style, primitive, style, RealClipSource(rest, 16), autoencoder=info,
                                    examples=[{**describe_clip(example), "encoded_frames": 16}], timeline_frames=16,
                                    dataset="synthetic"))
    return models


@pytest.fixture(scope="module")
def results(autoencoder):
    ae, info = autoencoder
    out = evaluate_models(oracle_models(info), tiny_takeset(), ae, SETTINGS, split=TINY_DATA["split"],
                          autoencoder_info=info)
    out["meta"] = {"data_name": "synthetic", "seed": 0, "samples": {"table_5_1": 120, "variance": 200, "metrics": 120},
                   "checkpoints": [], "autoencoder": {"path": info["path"], "fingerprint": info["fingerprint"]},
                   "git_commit": "test", "seconds": 1.0}
    return out


def test_table_5_1_is_diagonal_for_models_that_produce_their_style(results) -> None:
    """Samples of a style are closer (in Gram distance) to that style's example than to any other, and
    each example is closest to its own style's samples — for both stance primitives."""
    assert isinstance(RealClipSource(oracle_clips(), 16), SampleSource)
    for primitive in PRIMITIVES:
        table = results["table_5_1"][primitive]
        assert table["models"] == ["neutral", "elderly", "youthful"] == table["examples"]
        assert table["diagonal"]["all_rows"] and table["diagonal"]["all_columns"], table["distance"]
        assert table["samples"] == 120


def oracle_clips():
    return primitive_data(tiny_takeset(), "walk_leftStance", 16, split=TINY_DATA["split"]).training_data()


def test_results_of_real_clips_look_like_real_data(results) -> None:
    rec = results["style_recognition"]
    assert rec["classifier_heldout_accuracy"] >= 0.8 and rec["chance"] == pytest.approx(1 / 3)
    assert all(share >= 0.8 for share in rec["per_model"].values()), rec["per_model"]
    for primitive in PRIMITIVES:
        ratio = results["variance_ratio"][primitive]["neutral"]  # resampled training clips
        assert 0.9 < ratio["pose_sd"] < 1.1 and 0.8 < ratio["step_sd"] < 1.2, ratio
        # a resampled training clip is its own nearest training clip
        assert results["nearest_training"][primitive]["neutral"]["samples_median_m"] == pytest.approx(0.0, abs=1e-6)
        assert results["nearest_training"][primitive]["elderly"]["samples_median_m"] > 0.005
    for name, ratio in results["foot_skating"].items():
        assert ratio == pytest.approx(results["foot_skating_real"][name], abs=0.05)
    for primitive in PRIMITIVES:  # resampled real clips: the root follows the stance leg, as in the real clips
        for name, travel in results["stance_travel"][primitive].items():
            assert 0.9 < travel["real"]["travel_ratio"] < 1.1, (primitive, name, travel)
            assert travel["samples"]["travel_ratio"] == pytest.approx(travel["real"]["travel_ratio"], abs=0.05)
            assert travel["samples"]["foot_drift_m"] < 0.02 and travel["samples"]["motions"] == 120
    assert 0 < results["autoencoder"]["test_mpjpe_m"] < 0.5


def test_report_folder_is_complete_and_never_overwritten_silently(results, tmp_path: Path) -> None:
    out = write_report(results, tmp_path / "report")
    names = {p.name for p in out.iterdir()}
    for p in PRIMITIVES:
        assert {f"table_5_1_{p}.csv", f"table_5_1_{p}.png", f"variance_{p}.csv",
                f"classifier_confusion_{p}.png"} <= names
    assert {"report.md", "report.json", "variance.png", "style_recognition.csv", "foot_skating.csv",
            "stance_travel.csv", "variation_vs_style.csv"} <= names
    saved = json.loads((out / "report.json").read_text())
    t = saved["table_5_1"]["walk_leftStance"]
    assert len(t["distance"]) == len(t["models"]) == len(t["examples"]) == 3
    assert set(saved["variance"]["walk_rightStance"]["elderly"]) >= {"pose_sd", "v_sd", "step_sd", "pose_across_sd"}
    assert set(saved["variation_vs_style"]["walk_rightStance"]["elderly"]) == {"style", "pose_across_sd", "v_sd",
                                                                               "step_sd", "diversity"}
    assert {"classifier_heldout_accuracy", "per_model"} <= set(saved["style_recognition"])
    assert isinstance(saved["frechet"]["walk_leftStance"]["youthful"], float)
    assert isinstance(saved["foot_skating"]["neutral"], float)
    assert saved["autoencoder"]["test_mpjpe_m"] > 0
    assert {"data_name", "seed", "samples", "checkpoints", "git_commit", "seconds"} <= set(saved["meta"])
    md = (out / "report.md").read_text()
    for heading in ("## Against the thesis", "## Table 5.1", "## Tables 5.2/5.3", "## Style recognition",
                    "## Foot skating", "## Nearest training clip", "## Definitions", "pose_SD in cm",
                    "## Variation across samples", "**pose_across_sd**"):
        assert heading in md
    (out / "notes.txt").write_text("keep me")
    with pytest.raises(OutputExistsError, match="already exists"):
        write_report(results, out)
    assert (out / "notes.txt").read_text() == "keep me"
    write_report(results, out, force=True)
    assert not (out / "notes.txt").exists() and (out / "report.json").is_file()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary folder left


def test_the_same_seed_gives_the_same_tables(autoencoder, results) -> None:
    ae, info = autoencoder
    models = [m for m in oracle_models(info) if m.primitive == "walk_leftStance"]
    again = evaluate_models(models, tiny_takeset(), ae, SETTINGS, split=TINY_DATA["split"])
    assert np.allclose(again["table_5_1"]["walk_leftStance"]["distance"],
                       results["table_5_1"]["walk_leftStance"]["distance"])
    assert again["frechet"]["walk_leftStance"] == results["frechet"]["walk_leftStance"]


def test_bad_input_gets_clear_errors(autoencoder) -> None:
    ae, info = autoencoder
    by_name = {m.name: m for m in oracle_models(info) if m.primitive == "walk_leftStance"}
    models = [by_name["neutral"], by_name["elderly"], by_name["youthful"]]
    run = lambda ms, **kw: evaluate_models(ms, tiny_takeset(), ae, SETTINGS, split=TINY_DATA["split"], **kw)  # noqa: E731

    other = dict(info, fingerprint="0123456789abcdef", path="/elsewhere/ae.ckpt")
    mixed = models[:1] + [EvalModel(**{**vars(models[1]), "autoencoder": other, "checkpoint": "cvae_elderly.ckpt"})]
    with pytest.raises(MixedAutoencodersError, match="different autoencoders") as err:
        run(mixed)
    assert "0123456789abcdef" in str(err.value) and info["fingerprint"] in str(err.value)
    with pytest.raises(MixedAutoencodersError, match="another autoencoder"):
        run(models, autoencoder_info=other)

    no_example = EvalModel(**{**vars(models[1]), "examples": []})
    with pytest.raises(MissingExampleError, match="records no style example"):
        run([models[0], no_example])
    elsewhere = EvalModel(**{**vars(models[1]), "examples": [{**models[1].examples[0], "take": "no_such_take"}]})
    with pytest.raises(MissingExampleError, match="no_such_take"):
        run([models[0], elsewhere])
    wrong_gram = EvalModel(**{**vars(models[1]), "target_gram": torch.eye(32)})
    with pytest.raises(MissingExampleError, match="different Gram matrix"):
        run([models[0], wrong_gram])
    unknown_style = EvalModel(**{**vars(models[1]), "name": "proud", "style": "proud"})
    with pytest.raises(MissingExampleError, match="proud"):
        run([models[0], unknown_style])
    with pytest.raises(ValueError, match="two models of walk_leftStance/elderly"):
        run([models[1], models[1]])
    with pytest.raises(ValueError, match="no model"):
        run([])


def test_real_variance_leaves_out_a_style_without_clips_of_the_primitive():
    from types import SimpleNamespace

    from stylemotion.evaluation.pipeline import real_variance
    from stylemotion.evaluation.sources import motions_from_clips

    data = primitive_data(tiny_takeset(), "walk_leftStance", 17)
    clips = {s: data.style_clips(s) for s in data.styles}
    clips["standing_only"] = []
    real = SimpleNamespace(training=motions_from_clips(data.training_data(), 17), length=17,
                           data=SimpleNamespace(styles=[*data.styles, "standing_only"], style_clips=clips.__getitem__))
    variance = real_variance(real)
    assert set(variance.real) == set(data.styles)
    assert variance.ratio["training_data"] == {"pose_sd": 1.0, "v_sd": 1.0, "step_sd": 1.0}


def test_variation_against_the_style_is_near_one_for_real_clips_and_zero_for_a_copy(results) -> None:
    """The oracle models draw real clips of their style: their across-sample variation and diversity are
    about their style's own; a source that repeats one clip has none (while its pose_SD stays high)."""
    for primitive in PRIMITIVES:
        rows = results["variation_vs_style"][primitive]
        assert set(rows) == {"neutral", "elderly", "youthful"}
        for name, r in rows.items():
            assert r["style"] == ("normal" if name == "neutral" else name)
            assert 0.75 < r["pose_across_sd"] < 1.25 and 0.75 < r["diversity"] < 1.25, (primitive, name, r)
    data = primitive_data(tiny_takeset(), "walk_leftStance", 16, split=TINY_DATA["split"])
    copy = RealClipSource(data.style_clips("elderly")[:1], 16).sample(200, seed=0)
    stats = variance_stats(copy.frames.numpy(), copy.positions.numpy(), copy.num_frames.numpy(),
                           copy.normalized_frames.numpy())
    real = results["variance_real"]["walk_leftStance"]["elderly"]
    assert stats["pose_across_sd"] == pytest.approx(0.0, abs=1e-9) and stats["pose_sd"] > 0.5 * real["pose_sd"]


def test_heldout_splits_val_reads_no_test_clip() -> None:
    """``heldout_splits=[val]``: the held-out clips, the neutral ground truth and a style model's ground truth hold
    no test-split clip, and every clip they lose is a test clip; the default holds both splits."""
    both = primitive_data(tiny_takeset(), "walk_leftStance", 16, split=TINY_DATA["split"])
    val = primitive_data(tiny_takeset(), "walk_leftStance", 16, split=TINY_DATA["split"], heldout_splits=("val",))
    assert both.heldout_splits == ("val", "test")
    test_keys = {(c.take, c.start) for c in both.split("test")}
    assert test_keys, "the tiny data must have test clips for this test to mean anything"
    key = lambda clips: {(c.take, c.start) for c in clips}  # noqa: E731
    assert key(both.heldout()) == key(both.split("val")) | test_keys
    assert key(val.heldout()) == key(val.split("val")) and not key(val.heldout()) & test_keys
    for style in both.styles:
        model = EvalModel(NEUTRAL if style == "normal" else style, "walk_leftStance", style,
                          RealClipSource(both.training_data(), 16), timeline_frames=16)
        full, narrowed = key(both.ground_truth(model)), key(val.ground_truth(model))
        assert narrowed <= full and not narrowed & test_keys and full - narrowed <= test_keys
        assert full - narrowed, f"{style}: the default ground truth should hold test clips of the style"


def test_heldout_splits_are_checked() -> None:
    from stylemotion.config import ConfigError

    assert EvalSettings(heldout_splits=["val"]).heldout_splits == ["val"]
    for bad in (["train"], [], ["val", "val"]):
        with pytest.raises(ConfigError, match="evaluation.heldout_splits"):
            EvalSettings(heldout_splits=bad)


def test_style_truth_heldout_judges_a_style_model_on_held_out_clips_only() -> None:
    """``style_truth="heldout"`` with ``heldout_splits=[test]``: a style model's ground truth is exactly its style's
    test-split clips (no train or val clip, which a choice made on ``[val]`` read); the neutral model's is unchanged;
    the default keeps every clip of the style."""
    data = dict(split=TINY_DATA["split"], heldout_splits=("test",))
    everything = primitive_data(tiny_takeset(), "walk_leftStance", 16, **data)
    test_only = primitive_data(tiny_takeset(), "walk_leftStance", 16, **data, style_truth="heldout")
    key = lambda clips: {(c.take, c.start) for c in clips}  # noqa: E731
    for style in everything.styles:
        model = EvalModel(NEUTRAL if style == "normal" else style, "walk_leftStance", style,
                          RealClipSource(everything.training_data(), 16), timeline_frames=16)
        test_clips = key(everything.split("test", style))
        assert test_clips, f"{style}: the tiny data must have test clips of every style"
        assert key(test_only.ground_truth(model)) == test_clips
        if style != "normal":
            assert key(everything.ground_truth(model)) == key(everything.split("train", style)) | test_clips
        else:
            assert key(everything.ground_truth(model)) == test_clips


def test_style_truth_is_checked() -> None:
    from stylemotion.config import ConfigError

    assert EvalSettings(style_truth="heldout").style_truth == "heldout"
    with pytest.raises(ConfigError, match="evaluation.style_truth must be one of \\['all', 'heldout'\\], got 'test'"):
        EvalSettings(style_truth="test")
