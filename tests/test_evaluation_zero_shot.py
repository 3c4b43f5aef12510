"""The leave-one-style-out evaluation on the tiny reproduce run (walks of normal, elderly and youthful): an
autoencoder and a network that never saw the left-out style, measured in the run's (judge) space; recognition
and Table 5.1 checked against figures recomputed here by hand; finished trainings reused; the generator's
normalization kept apart from the judge's (same autoencoder: the old path's figures; a planted autoencoder whose
normalization statistics differ but that computes the same function: the same figures); wrong runs refused."""

from __future__ import annotations

import copy
import json
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
import torch
from log_lines import logged_lines
from omegaconf import OmegaConf
from recognition_reference import example_gram, hand_share
from reproduce_fixtures import copy_run, reproduce, tiny_overrides

from stylemotion.cli.schemas import register_schemas
from stylemotion.datasets import build_dataset
from stylemotion.evaluation.metrics import foot_skating
from stylemotion.evaluation.reference import primitive_data
from stylemotion.evaluation.sources import MixedAutoencodersError
from stylemotion.evaluation.zero_shot import (
    ZeroShotRunError,
    autoencoder_excluded_styles,
    autoencoder_folder,
    autoencoder_train_config,
    evaluate_primitive,
    leave_one_style_out,
    load_left_out,
    model_folder,
    read_run,
    train_config,
    unseen_cvae_folder,
)
from stylemotion.io.outputs import OutputExistsError
from stylemotion.models.checkpoints import fingerprint, load_autoencoder
from stylemotion.models.loading import load_generative, load_model
from stylemotion.models.sampling import decode_features, motions_from_normalized
from stylemotion.primitives.segmentation import time_normalize

register_schemas()  # the configs composed here take structured schemas (stylemotion.cli.schemas)

torch.set_num_threads(1)
PRIMITIVE, STYLE = "walk_leftStance", "elderly"
#: The networks: tiny, two epochs.
NETWORK = ["model.hidden=[64,32]", "model.embedding_dim=8", "model.samples_per_item=4", "datamodule.min_train_clips=8",
           "trainer.enable_model_summary=false", "trainer.num_sanity_val_steps=0", "~logger"]
SAMPLES, SEED = 40, 3


@pytest.fixture(scope="module")
def run(tiny_run) -> Path:
    """The shared tiny reproduce run (conftest.py): walks of normal, elderly and youthful, CVAEs of both styles for
    both stance primitives (this evaluation takes walk_leftStance's)."""
    return tiny_run.folder


@pytest.fixture(scope="module")
def leaky(run, tmp_path_factory) -> tuple[Path, dict]:
    """The old protocol (one network without elderly on the run's autoencoder): its folder and results."""
    out = tmp_path_factory.mktemp("leaky") / "loso"
    return out, leave_one_style_out(run, out, [STYLE], [PRIMITIVE], epochs=2, samples=SAMPLES, seed=SEED,
                                    overrides=NETWORK, threads=1, shared_autoencoder=True)


def hand_row(source, judge, clips_of, frames: torch.Tensor, duration_s: torch.Tensor, style: str,
             column_gram: torch.Tensor, length: int) -> tuple[float, float]:
    """Recognition (:func:`recognition_reference.hand_share`) and the own-column Table 5.1 distance of motions,
    recomputed here: ``mean_i ‖F_i F_iᵀ / T − G‖_F`` with ``F_i`` the judge autoencoder's features of motion i."""
    classifier = source.settings.classifier
    share = hand_share(clips_of("train"), length, frames.numpy(), duration_s.numpy(), style, classifier.components,
                       classifier.C, source.settings.seed)
    with torch.no_grad():
        features = judge.encode(frames.float())
    grams = features @ features.transpose(-1, -2) / features.shape[-1]
    return share, float(torch.linalg.matrix_norm(grams - column_gram).mean())


@pytest.mark.slow  # an autoencoder and a network trained without elderly, two evaluations: ~20 s on one busy core
def test_leave_one_style_out_without_leakage_against_a_hand_computed_reference(run, tmp_path) -> None:
    out = tmp_path / "loso"
    with logged_lines("stylemotion.evaluation.zero_shot") as lines:
        results = leave_one_style_out(run, out, [STYLE], [PRIMITIVE], epochs=2, samples=SAMPLES, seed=SEED,
                                      overrides=NETWORK, threads=1)
    source = read_run(run)
    judge = load_autoencoder(source.autoencoder_ckpt)
    res = results["primitives"][PRIMITIVE]
    row = res["styles"][STYLE]
    assert res["columns"] == ["neutral", "elderly", "youthful"] and results["meta"]["leaky"] is False
    # the generator never saw elderly: its autoencoder's data and its network's data left it out
    ae_ckpt = Path(row["generator_autoencoder"]["path"])
    assert ae_ckpt.is_relative_to(autoencoder_folder(out, STYLE)) and autoencoder_excluded_styles(ae_ckpt) == [STYLE]
    assert autoencoder_excluded_styles(source.autoencoder_ckpt) == []
    network = load_generative(model_folder(out, PRIMITIVE, STYLE) / "checkpoints" / "best.ckpt")
    assert network.excluded_styles == [STYLE] and STYLE not in row["trained_styles"]
    assert network.spec["autoencoder"]["fingerprint"] == fingerprint(load_autoencoder(ae_ckpt)) \
        == row["generator_autoencoder"]["fingerprint"] != fingerprint(judge)
    # every figure recomputed by hand in the judge's space: samples drawn here (the network decoding with its own,
    # embedded autoencoder), the classifier fitted here, Grams of the judge autoencoder's features
    length = res["timeline_frames"]
    data = primitive_data(build_dataset(source.data_cfg), PRIMITIVE, length, source.settings.neutral_style,
                          asdict(source.settings.segment), source.data_cfg.get("split"))
    cvae = load_model(source.cvaes[(PRIMITIVE, STYLE)], source.settings.neutral_style, judge)
    examples = [data.find_example(e) for e in row["example"]]
    drawn = {"zero_shot": network.bind_example(examples).sample(SAMPLES, seed=SEED),
             "cvae": cvae.source.sample(SAMPLES, seed=SEED)}
    skip = {(c.take, c.start) for c in examples}
    truth = [c for c in data.style_clips(STYLE) if (c.take, c.start) not in skip]
    clips_of = data.split
    column = example_gram(judge, data, cvae)
    for kind, motions in drawn.items():
        share, own = hand_row(source, judge, clips_of, motions.normalized_frames, motions.duration_s, STYLE,
                              column, length)
        assert row[kind]["recognition"] == share, kind
        assert row[kind]["table_5_1_row"][STYLE] == pytest.approx(own, rel=1e-5), kind
    frames = torch.from_numpy(np.stack([time_normalize(c.frames, length) for c in truth]))
    share, own = hand_row(source, judge, clips_of, frames, torch.tensor([c.duration_s for c in truth]), STYLE,
                          column, length)
    assert row["real"]["recognition"] == share and row["real"]["clips"] == len(truth)
    assert row["real"]["table_5_1_row"][STYLE] == pytest.approx(own, rel=1e-5)
    with torch.no_grad():  # the same clips through the generator's autoencoder: what its features keep of the style
        rebuilt = load_autoencoder(ae_ckpt)(frames.float())
    share, own = hand_row(source, judge, clips_of, rebuilt, torch.tensor([c.duration_s for c in truth]), STYLE,
                          column, length)
    assert row["reconstructed"]["recognition"] == share
    assert row["reconstructed"]["table_5_1_row"][STYLE] == pytest.approx(own, rel=1e-5)
    assert json.loads((out / "zero_shot.json").read_text())["splits"] == results["splits"]
    assert "LEAKY" not in (out / "zero_shot.md").read_text()
    # resumed: both trainings reused, the same figures
    with logged_lines("stylemotion.evaluation.zero_shot") as resumed:
        again = leave_one_style_out(run, out, [STYLE], [PRIMITIVE], epochs=2, samples=SAMPLES, seed=SEED,
                                    overrides=NETWORK, threads=1, resume=True)
    lines += resumed
    assert again["primitives"][PRIMITIVE]["styles"][STYLE]["zero_shot"] == {**row["zero_shot"], "train_seconds": None}
    assert sum("reused" in line for line in lines) == 2 and sum(line.endswith(": training") for line in lines) == 2
    with pytest.raises(OutputExistsError):
        leave_one_style_out(run, out, [STYLE], [PRIMITIVE])
    with pytest.raises(ZeroShotRunError, match="not the leave-youthful-out network"):
        load_left_out(model_folder(out, PRIMITIVE, STYLE) / "checkpoints" / "best.ckpt", PRIMITIVE, "youthful",
                      fingerprint(judge))


def _evaluate(source, network, shared: bool = False) -> dict:
    """:func:`evaluate_primitive` of one network without elderly, as :func:`leave_one_style_out` runs it."""
    judge = load_autoencoder(source.autoencoder_ckpt)
    cvaes = [load_model(source.cvaes[(q, s)], source.settings.neutral_style, judge)
             for q, s in source.cvaes if q == PRIMITIVE]
    return evaluate_primitive(PRIMITIVE, {STYLE: network}, cvaes, build_dataset(source.data_cfg), judge,
                              source.settings, source.data_cfg.get("split"), SAMPLES, SEED,
                              shared)["styles"][STYLE]


def figures(row: dict) -> dict:
    return {kind: {k: row[kind][k] for k in ("recognition", "table_5_1_row", "pose_across_sd")}
            for kind in ("zero_shot", "cvae", "real", "reconstructed")}


@pytest.mark.slow  # one network trained (shared with the next test), three evaluations: ~15 s
def test_with_the_judge_as_generator_the_figures_are_the_old_paths(run, leaky) -> None:
    folder, results = leaky
    assert results["meta"]["leaky"] and "LEAKY" in (folder / "zero_shot.md").read_text()
    source = read_run(run)
    network = load_generative(model_folder(folder, PRIMITIVE, STYLE) / "checkpoints" / "best.ckpt")  # embedded AE
    assert network.spec["autoencoder"]["fingerprint"] == fingerprint(load_autoencoder(source.autoencoder_ckpt))
    assert figures(_evaluate(source, network)) == figures(results["primitives"][PRIMITIVE]["styles"][STYLE])


def planted_generator(network, powers_frames: torch.Tensor, powers_features: torch.Tensor):
    """``network`` and its autoencoder rewritten to other normalization statistics computing the same motions:
    the autoencoder's frame std × 2^powers_frames and its features × 2^powers_features (weights compensating; ReLU
    and pooling commute with positive scales, powers of two are exact), the network's feature statistics and
    style-embedding basis following them."""
    ae = copy.deepcopy(network.autoencoder)
    net = ae.net
    a, k = 2.0 ** powers_frames, 2.0 ** powers_features  # (66,), (C,)
    with torch.no_grad():
        net.normalizer.std.mul_(a)
        net.encoder.weight.mul_(a[None, :, None] * k[:, None, None])
        net.encoder.bias.mul_(k)
        net.decoder.weight.div_(a[:, None, None] * k[None, :, None])
        net.decoder.bias.div_(a)
    generator = copy.deepcopy(network)
    with torch.no_grad():
        generator.feature_mean.mul_(k)
        generator.feature_std.mul_(k)
        generator.style_mean.mul_(torch.cat([k, k]))
        generator.style_axes.div_(torch.cat([k, k])[None, :])
    generator.hparams.spec["autoencoder"] = {**generator.spec["autoencoder"], "fingerprint": fingerprint(ae)}
    generator.attach_autoencoder(ae)
    return generator, ae


@pytest.mark.slow
def test_a_generator_with_other_normalization_statistics_is_judged_by_its_motions(run, leaky) -> None:
    folder, results = leaky
    source = read_run(run)
    network = load_generative(model_folder(folder, PRIMITIVE, STYLE) / "checkpoints" / "best.ckpt")
    judge = network.autoencoder
    gen = torch.Generator().manual_seed(0)
    powers_frames = torch.randint(-2, 3, (judge.net.frame_dim,), generator=gen).float()
    powers_features = torch.randint(-3, 4, (judge.net.hidden_units,), generator=gen).float()
    generator, ae = planted_generator(network, powers_frames, powers_features)
    assert fingerprint(ae) != fingerprint(judge) and not torch.equal(ae.net.normalizer.std, judge.net.normalizer.std)
    assert not torch.allclose(generator.feature_std, network.feature_std)
    # the same function: the figures of the run's network, with the generator's statistics undone before the judge's
    assert figures(_evaluate(source, generator)) == figures(results["primitives"][PRIMITIVE]["styles"][STYLE])
    # a generator decoding with the judge's autoencoder (its statistics) is refused; its motions would differ
    wrong = copy.deepcopy(generator)
    object.__setattr__(wrong, "_autoencoder", judge)
    with pytest.raises(MixedAutoencodersError, match="not the one it was trained on"):
        _evaluate(source, wrong)
    condition = generator.condition(torch.randn(judge.net.hidden_units, int(network.spec["feature_steps"]),
                                                generator=gen))
    z = torch.randn(4, network.hparams.latent_dim, generator=gen)
    assert not torch.allclose(wrong.decode_latent(z, example=condition).frames,
                              generator.decode_latent(z, example=condition).frames, atol=1e-3)


@pytest.mark.slow  # an autoencoder, a network and a CVAE trained without elderly, one evaluation
def test_the_cvae_on_the_autoencoder_without_the_style_is_a_row_beside_the_network(run, tmp_path) -> None:
    """``cvae_unseen``: the run's CVAE stage (its settings, its example clips) on the generator's autoencoder, which
    never saw the style: its recognition recomputed by hand; variation figures on every row; reused when resumed."""
    out = tmp_path / "loso"
    results = leave_one_style_out(run, out, [STYLE], [PRIMITIVE], epochs=2, samples=SAMPLES, seed=SEED,
                                  overrides=NETWORK, threads=1, cvae_unseen=True)
    source = read_run(run)
    row = results["primitives"][PRIMITIVE]["styles"][STYLE]
    ae_ckpt = Path(row["generator_autoencoder"]["path"])
    unseen = load_model(unseen_cvae_folder(out, PRIMITIVE, STYLE) / "checkpoints" / "best.ckpt",
                        source.settings.neutral_style)
    run_cvae = load_model(source.cvaes[(PRIMITIVE, STYLE)], source.settings.neutral_style)
    assert unseen.source.spec["autoencoder"]["fingerprint"] == fingerprint(load_autoencoder(ae_ckpt))
    assert run_cvae.source.spec["autoencoder"]["fingerprint"] != unseen.source.spec["autoencoder"]["fingerprint"]
    assert [e["take"] for e in unseen.examples] == [e["take"] for e in run_cvae.examples]
    stage = next(st for st in source.stages("cvae") if st["values"] == {"primitive": PRIMITIVE, "style": STYLE})
    assert unseen.source.hparams.style_weight == run_cvae.source.hparams.style_weight and stage["overrides"]
    judge = load_autoencoder(source.autoencoder_ckpt)
    length = results["primitives"][PRIMITIVE]["timeline_frames"]
    data = primitive_data(build_dataset(source.data_cfg), PRIMITIVE, length, source.settings.neutral_style,
                          asdict(source.settings.segment), source.data_cfg.get("split"))
    drawn = unseen.source.sample(SAMPLES, seed=SEED)  # decoded by its own autoencoder, judged in the run's space
    share, own = hand_row(source, judge, data.split, drawn.normalized_frames, drawn.duration_s, STYLE,
                          example_gram(judge, data, run_cvae), length)
    assert row["cvae_unseen"]["recognition"] == share
    assert row["cvae_unseen"]["table_5_1_row"][STYLE] == pytest.approx(own, rel=1e-5)
    for kind in ("zero_shot", "cvae", "cvae_unseen", "real"):
        assert set(row[kind]["variation"]) == {"pose_sd", "v_sd", "step_sd", "diversity"}
        assert all(v > 0 for v in row[kind]["variation"].values()), kind
    assert results["summary"]["cvae_unseen"]["rows"] == 1 and results["meta"]["cvae_unseen"] is True
    with logged_lines("stylemotion.evaluation.zero_shot") as resumed:
        again = leave_one_style_out(run, out, [STYLE], [PRIMITIVE], epochs=2, samples=SAMPLES, seed=SEED,
                                    overrides=NETWORK, threads=1, resume=True, cvae_unseen=True)
    assert sum("reused" in line for line in resumed) == 3
    assert again["primitives"][PRIMITIVE]["styles"][STYLE]["cvae_unseen"] == {**row["cvae_unseen"],
                                                                              "train_seconds": None}
    assert row["cvae_unseen"]["train_seconds"] > 0
    # an arm with other networks on the same stages: the autoencoder and the CVAE reused, only the network trained
    with logged_lines("stylemotion.evaluation.zero_shot") as arm_lines:
        arm = leave_one_style_out(run, tmp_path / "arm", [STYLE], [PRIMITIVE], epochs=1, samples=SAMPLES, seed=SEED,
                                  overrides=NETWORK, threads=1, cvae_unseen=True, stages=out)
    assert sum("reused" in line for line in arm_lines) == 2
    assert not (tmp_path / "arm" / "autoencoders").exists() and arm["meta"]["stages"] == str(out.resolve())
    arm_row = arm["primitives"][PRIMITIVE]["styles"][STYLE]
    assert arm_row["cvae_unseen"] == {**row["cvae_unseen"], "train_seconds": None}
    assert arm_row["generator_autoencoder"]["path"] == row["generator_autoencoder"]["path"]
    assert arm_row["zero_shot"]["train_seconds"] > 0
    # an arm that samples those networks at another temperature: nothing trained, the network's samples scaled
    with logged_lines("stylemotion.evaluation.zero_shot") as cool_lines:
        cool = leave_one_style_out(run, tmp_path / "cool", [STYLE], [PRIMITIVE], epochs=1, samples=SAMPLES,
                                   seed=SEED, overrides=NETWORK, threads=1, cvae_unseen=True, stages=out,
                                   networks=tmp_path / "arm", temperature=0.25)
    assert sum("reused" in line for line in cool_lines) == 3 and not (tmp_path / "cool" / "models").exists()
    cool_row = cool["primitives"][PRIMITIVE]["styles"][STYLE]
    assert cool_row["cvae_unseen"] == arm_row["cvae_unseen"] and cool["meta"]["temperature"] == 0.25
    assert cool_row["zero_shot"]["sample_temperature"] == 0.25 and arm_row["zero_shot"]["sample_temperature"] == 1.0
    assert cool_row["zero_shot"]["variation"]["diversity"] < arm_row["zero_shot"]["variation"]["diversity"]
    # the networks sample centred as configs/model/zero_shot.yaml says; an arm without centring moves every sample
    plain = leave_one_style_out(run, tmp_path / "plain", [STYLE], [PRIMITIVE], epochs=1, samples=SAMPLES,
                                seed=SEED, overrides=NETWORK, threads=1, cvae_unseen=True, stages=out,
                                networks=tmp_path / "arm", centred=False)
    plain_row = plain["primitives"][PRIMITIVE]["styles"][STYLE]["zero_shot"]
    assert arm_row["zero_shot"]["sample_centred"] and not plain_row["sample_centred"]
    assert plain["meta"]["centred"] is False and plain_row["sample_temperature"] == 1.0
    assert plain_row["table_5_1_row"] != arm_row["zero_shot"]["table_5_1_row"]


@pytest.mark.slow  # a second report of the tiny run (every stage reused), two evaluations of one network
def test_a_test_report_judges_against_the_styles_test_clips_and_every_row_measures_raw_skating(
        tiny_run, leaky, tmp_path) -> None:
    """``read_run(run, "report_test")``: the judge takes that report's settings (``heldout_splits=[test]``,
    ``style_truth=heldout``), so the ``real`` row holds the style's test clips only; every row's raw foot skating is
    the report's measure (:func:`foot_skating`) of exactly its motions: the samples drawn, the real clips (as the
    test report measured them)."""
    folder, _ = leaky
    copy = copy_run(tiny_run, tmp_path / "run")
    reproduce(tiny_overrides(copy) + ["report=report_test", "evaluation.heldout_splits=[test]",
                                      "evaluation.style_truth=heldout"], [])
    source, every = read_run(copy, "report_test"), read_run(copy)
    assert source.report_name == "report_test" and list(source.settings.heldout_splits) == ["test"]
    network = load_generative(model_folder(folder, PRIMITIVE, STYLE) / "checkpoints" / "best.ckpt")
    row, all_clips = _evaluate(source, network), _evaluate(every, network)
    length = load_generative(source.cvaes[(PRIMITIVE, STYLE)]).timeline_frames
    data = primitive_data(build_dataset(source.data_cfg), PRIMITIVE, length, source.settings.neutral_style,
                          asdict(source.settings.segment), source.data_cfg.get("split"))
    skip = {(e["take"], e["start"]) for e in row["example"]}
    test = [c for c in data.split("test", STYLE) if (c.take, c.start) not in skip]
    assert 0 < row["real"]["clips"] == len(test) < all_clips["real"]["clips"]
    # the style's real clips skate as the test report measured them for the CVAE of the style (the same clips)
    report = json.loads((copy / "report_test" / "report.json").read_text())
    assert row["real"]["foot_skating"] == report["foot_skating_detail"][PRIMITIVE][STYLE]["real"]
    assert row["real"]["foot_skating"]["motions"] == len(test)
    for kind in ("zero_shot", "cvae", "real"):
        skating = row[kind]["foot_skating"]
        assert 0 <= skating["skating_frames"] <= skating["contact_frames"] <= skating["foot_frames"], kind
        assert skating["ratio"] == pytest.approx(skating["skating_frames"] / skating["contact_frames"]), kind
    drawn = network.bind_example([data.find_example(e) for e in row["example"]]).sample(SAMPLES, seed=SEED)
    hand = foot_skating(drawn.positions.numpy(), drawn.num_frames.numpy(), drawn.fps, data.rest_heights,
                        data.stance_foot, source.settings.skate_speed_mps)
    assert row["zero_shot"]["foot_skating"] == hand.as_dict() == all_clips["zero_shot"]["foot_skating"]
    assert row["zero_shot"]["foot_skating"]["motions"] == SAMPLES
    # the real clips through the generator's autoencoder (the leaky network's: the run's), at their durations
    features = network.autoencoder.encode(torch.from_numpy(np.stack([time_normalize(c.frames, length) for c in test])))
    rebuilt = decode_features(network.autoencoder, features, torch.tensor([c.duration_s for c in test]), length,
                              data.fps)
    hand = foot_skating(rebuilt.positions.numpy(), rebuilt.num_frames.numpy(), data.fps, data.rest_heights,
                        data.stance_foot, source.settings.skate_speed_mps)
    assert row["reconstructed"]["foot_skating"] == hand.as_dict()
    # the same clips only resampled to the canonical timeline and back (no autoencoder)
    normalized = torch.from_numpy(np.stack([time_normalize(c.frames, length) for c in test]))
    played = motions_from_normalized(normalized, torch.tensor([c.duration_s for c in test]), data.fps)
    hand = foot_skating(played.positions.numpy(), played.num_frames.numpy(), data.fps, data.rest_heights,
                        data.stance_foot, source.settings.skate_speed_mps)
    assert row["reconstructed"]["foot_skating_timeline"] == hand.as_dict()
    assert row["reconstructed"]["foot_skating_timeline"] != row["reconstructed"]["foot_skating"]
    # the leaky network decodes with the judge's own autoencoder: its reconstruction is the judge's
    assert row["reconstructed"]["foot_skating_judge"] == row["reconstructed"]["foot_skating"]


@pytest.mark.slow  # an autoencoder and a network trained without elderly and youthful, one evaluation: ~20 s
def test_a_group_left_out_together_trains_one_generator_that_never_saw_any_of_its_styles(run, tmp_path) -> None:
    """``groups`` (e.g. an actor's styles): one autoencoder and one network per primitive without every style of the
    group, serving each of its styles; each row judged against its own style's clips and example."""
    group = ["youthful", "elderly"]
    out = tmp_path / "loso"
    with logged_lines("stylemotion.evaluation.zero_shot") as lines:
        results = leave_one_style_out(run, out, group, [PRIMITIVE], epochs=2, samples=SAMPLES, seed=SEED,
                                      overrides=NETWORK, threads=1, groups={s: group for s in group})
    assert sum(line.endswith(": training") for line in lines) == 2  # one autoencoder, one network
    rows = results["primitives"][PRIMITIVE]["styles"]
    assert set(rows) == {"elderly", "youthful"} and results["meta"]["left_out_groups"] == {
        "elderly": ["elderly", "youthful"], "youthful": ["elderly", "youthful"]}
    ae_ckpt = Path(rows["elderly"]["generator_autoencoder"]["path"])
    assert ae_ckpt.is_relative_to(autoencoder_folder(out, group)) and autoencoder_folder(out, group).name == \
        "without_elderly+youthful"
    assert sorted(autoencoder_excluded_styles(ae_ckpt)) == ["elderly", "youthful"]
    assert rows["youthful"]["generator_autoencoder"]["path"] == str(ae_ckpt)
    network = load_generative(model_folder(out, PRIMITIVE, group) / "checkpoints" / "best.ckpt")
    assert sorted(network.excluded_styles) == ["elderly", "youthful"]
    for style, row in rows.items():
        assert row["left_out"] == ["elderly", "youthful"] and not set(row["trained_styles"]) & {"elderly", "youthful"}
        assert row["zero_shot"]["table_5_1_row"].keys() == row["real"]["table_5_1_row"].keys()
        assert row["example"] == [dict(e) for e in load_model(read_run(run).cvaes[(PRIMITIVE, style)]).examples]
    assert rows["elderly"]["zero_shot"]["checkpoint"] == rows["youthful"]["zero_shot"]["checkpoint"]
    assert rows["elderly"]["zero_shot"]["table_5_1_row"] != rows["youthful"]["zero_shot"]["table_5_1_row"]


def test_groups_without_their_style_or_with_the_neutral_style_are_refused_before_any_work(run, tmp_path) -> None:
    with pytest.raises(ZeroShotRunError, match="the group of left-out style 'elderly' is \\['youthful'\\]"):
        leave_one_style_out(run, tmp_path / "x", [STYLE], [PRIMITIVE], groups={STYLE: ["youthful"]})
    with pytest.raises(ZeroShotRunError, match="holds the neutral style 'normal'"):
        leave_one_style_out(run, tmp_path / "x", [STYLE], [PRIMITIVE], groups={STYLE: [STYLE, "normal"]})
    assert not (tmp_path / "x").exists()


def test_the_train_configs_leave_the_style_out_of_the_runs_data(run, tmp_path) -> None:
    source = read_run(run)
    cfg = train_config(source, PRIMITIVE, STYLE, tmp_path / "m", epochs=7, overrides=["model.style_weight=5"],
                       autoencoder_ckpt=tmp_path / "ae.ckpt", seed=4)
    assert cfg.trainer.max_epochs == 7 and cfg.model.style_weight == 5 and cfg.model.anchor
    assert list(cfg.datamodule.exclude_styles) == [STYLE] and cfg.datamodule.primitive == PRIMITIVE
    assert cfg.autoencoder_ckpt == str(tmp_path / "ae.ckpt") and cfg.seed == 4
    assert OmegaConf.to_container(cfg.data) == source.data_cfg
    assert cfg.datamodule._target_ == "stylemotion.datamodules.multistyle.MultiStyleDataModule"
    default = train_config(source, PRIMITIVE, STYLE, tmp_path / "d")
    assert default.autoencoder_ckpt == str(source.autoencoder_ckpt) and default.seed == source.seed
    ae = autoencoder_train_config(source, STYLE, tmp_path / "ae", seed=4)
    stage = source.stages("autoencoder")[0]
    assert list(ae.datamodule.exclude_styles) == [STYLE] and ae.seed == 4 and ae.ckpt_path == "auto"
    assert ae.datamodule._target_ == "stylemotion.datamodules.windows.MotionWindowDataModule"
    assert ae.trainer.max_steps == 40 and ae.model.hidden_units == 32 and "trainer.max_steps=40" in stage["overrides"]
    assert OmegaConf.to_container(ae.data) == source.data_cfg and ae.output_dir == str((tmp_path / "ae").resolve())


def test_bad_runs_and_styles_are_refused(run, tmp_path) -> None:
    with pytest.raises(ZeroShotRunError, match="it has no reproduce.json"):
        read_run(tmp_path)
    with pytest.raises(ZeroShotRunError, match=r"it has no report \(report_test/report.json\)"):
        read_run(run, "report_test")
    with pytest.raises(ZeroShotRunError, match=r"report='../report' is not the name of a report folder"):
        read_run(run, "../report")
    with pytest.raises(ZeroShotRunError, match=r"has no CVAE of walk_leftStance for style\(s\) \['feminine'\]"):
        leave_one_style_out(run, tmp_path / "x", styles=["feminine"])
    assert not (tmp_path / "x").exists()
    (tmp_path / "stages").write_text("not a folder")
    with pytest.raises(ZeroShotRunError, match="stages=.* is a file, not a folder of trainings"):
        leave_one_style_out(run, tmp_path / "y", stages=tmp_path / "stages")
    with pytest.raises(ZeroShotRunError, match="networks=.* is a file, not a folder of trainings"):
        leave_one_style_out(run, tmp_path / "y", networks=tmp_path / "stages")
    with pytest.raises(ValueError, match="sample_temperature must be a finite number ≥ 0, got -1"):
        leave_one_style_out(run, tmp_path / "y", temperature=-1)
    assert not (tmp_path / "y").exists()
