"""The zero-shot style network: it trains, its example steers its samples (towards that example's style,
for an anchored network and for an embedding-only one), its checkpoint round-trips under
``weights_only=True``, and a bound example is a sample source the evaluation takes as it is and offers what
the path-following synthesis uses of a model."""

from __future__ import annotations

import copy
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
import torch
from recognition_reference import hand_share
from vae_fixtures import (
    TINY_DATA,
    feature_module,
    fit,
    tiny_autoencoder_ckpt,
    tiny_takeset,
    user_examples,
    validate,
)

from stylemotion.datamodules.multistyle import MultiStyleDataModule
from stylemotion.evaluation.pipeline import evaluate_models
from stylemotion.evaluation.reference import primitive_data
from stylemotion.evaluation.settings import ClassifierSettings, EvalSettings, SampleCounts
from stylemotion.evaluation.tables import style_distances
from stylemotion.models.autoencoder import IncompatibleModelError
from stylemotion.models.checkpoints import (
    checkpoint_hparams,
    checkpoint_kind,
    fingerprint,
    is_model_checkpoint,
    load_autoencoder,
)
from stylemotion.models.loading import EvalModel, SampleSource, load_generative, load_model
from stylemotion.models.style import gram
from stylemotion.models.vae import prior_draws
from stylemotion.models.zero_shot import ZeroShotStyleVAE

torch.set_num_threads(1)
TINY_NET = {"embedding_dim": 8, "hidden": [64, 32], "samples_per_item": 4}


@pytest.fixture(scope="session")
def ae_ckpt(tmp_path_factory) -> Path:
    return tiny_autoencoder_ckpt(tmp_path_factory.mktemp("zero_shot_ae"))


@pytest.fixture(scope="module")
def data(ae_ckpt) -> MultiStyleDataModule:
    dm = MultiStyleDataModule(takeset=tiny_takeset(), autoencoder_ckpt=str(ae_ckpt), split=TINY_DATA["split"],
                              min_train_clips=8, batch_size=16)
    dm.setup("fit")
    return dm


@pytest.fixture(scope="module")
def trained(data) -> dict[bool, ZeroShotStyleVAE]:
    """An anchored and an embedding-only network, 300 steps each (~3 s each on one core)."""
    out = {}
    for anchor in (True, False):
        torch.manual_seed(0)
        out[anchor] = ZeroShotStyleVAE(anchor=anchor, **TINY_NET)
        out[anchor].initial_loss = validate(out[anchor], data)["val/loss"]
        fit(out[anchor], data, steps=300)
    return out


@pytest.mark.parametrize("anchor", [True, False])
def test_the_network_trains_and_its_example_sets_the_style(data, trained, anchor) -> None:
    model = trained[anchor]
    assert validate(model, data)["val/loss"] < 0.5 * model.initial_loss
    examples = {s: data.example_features(s) for s in ("elderly", "youthful")}
    grams = torch.stack([gram(examples[s]) for s in examples])
    samples = {s: model.sample(200, seed=0, example=examples[s]) for s in examples}
    # the same codes under two examples: different motions, each nearer (Table 5.1's distance, re-encoded) to
    # the Gram of its own example than to the other's
    distances = {s: style_distances(model.autoencoder, samples[s].normalized_frames, grams).mean(0) for s in examples}
    assert distances["elderly"][0] < distances["elderly"][1], distances
    assert distances["youthful"][1] < distances["youthful"][0], distances
    gap = (samples["elderly"].features.mean(0) - samples["youthful"].features.mean(0)).norm()
    spread = samples["elderly"].features.std(0).norm() / 200 ** 0.5
    assert gap > 10 * spread
    assert samples["elderly"].features.std(0).mean() > 0  # samples, not one copy


def test_the_checkpoint_round_trips_under_weights_only(data, trained, tmp_path) -> None:
    model = trained[True]
    path = tmp_path / "zero_shot.ckpt"
    fit(model, data, steps=1).save_checkpoint(path, weights_only=False)  # the trainer's checkpoint, as training saves
    hparams = checkpoint_hparams(path)  # read with torch.load(weights_only=True)
    assert checkpoint_kind(hparams) == "zero_shot" and not is_model_checkpoint(path)
    assert hparams["spec"]["excluded_styles"] == [] and hparams["spec"]["styles"] == ["elderly", "normal", "youthful"]
    assert load_autoencoder(path).hparams["hidden_units"] == model.autoencoder.hparams["hidden_units"]
    assert fingerprint(load_autoencoder(path)) == fingerprint(model.autoencoder)  # embedded in the checkpoint
    example = data.example_clip("elderly")
    expected = model.sample(50, seed=3, example=example)
    for loaded in (load_generative(path), ZeroShotStyleVAE.load_from_checkpoint(path, map_location="cpu")):
        assert isinstance(loaded, ZeroShotStyleVAE) and loaded.hparams.anchor and loaded.styles == model.styles
        for name in ("style_mean", "style_axes", "style_scale", "feature_mean"):
            assert torch.equal(getattr(loaded, name), getattr(model, name)), name
        got = loaded.eval().sample(50, seed=3, example=example)
        assert torch.allclose(got.positions, expected.positions, atol=1e-5)
    with pytest.raises(IncompatibleModelError, match="zero-shot style network: it samples only given a style example"):
        load_model(path)  # the evaluation's loader: no example, no samples


def test_a_bound_example_is_a_sample_source_of_the_evaluation(data, trained) -> None:
    model = trained[True]
    record = model.spec["style_examples_by_style"]["elderly"]
    bound = model.bind_example(data.example_clip("elderly"), style="elderly", records=[record])
    assert isinstance(bound, SampleSource) and bound.primitive == "walk_leftStance"
    assert (bound.timeline_frames, bound.fps) == (data.timeline_frames, data.fps)
    assert torch.allclose(bound.target_gram, gram(data.example_features("elderly")), atol=1e-6)
    assert torch.equal(bound.sample(20, seed=1).features, model.sample(20, seed=1, example=bound.condition).features)
    spec = model.spec
    evaluated = EvalModel("elderly", bound.primitive, "elderly", bound, [record], dict(spec["autoencoder"]), None,
                          bound.timeline_frames, bound.target_gram, spec["dataset"], "canonical")
    settings = EvalSettings(samples=SampleCounts(20, 20, 20), classifier=ClassifierSettings(components=6))
    results = evaluate_models([evaluated], tiny_takeset(), model.autoencoder, settings, split=TINY_DATA["split"])
    table = results["table_5_1"]["walk_leftStance"]
    assert table["models"] == ["elderly"] and table["samples"] == 20
    # the share recomputed by hand: the same 20 samples (the evaluation's seed), a classifier built here
    clips = primitive_data(tiny_takeset(), "walk_leftStance", bound.timeline_frames, settings.neutral_style,
                           asdict(settings.segment), TINY_DATA["split"]).split("train")
    drawn = bound.sample(20, seed=settings.seed)
    expected = hand_share(clips, bound.timeline_frames, drawn.normalized_frames.numpy(), drawn.duration_s.numpy(),
                          "elderly", settings.classifier.components, settings.classifier.C, settings.seed)
    assert results["style_recognition"]["per_model"]["elderly"] == expected


def test_a_bound_example_offers_what_the_path_following_uses_of_a_model(data, trained) -> None:
    model = trained[True]
    bound = model.bind_example(data.example_clip("elderly")).eval().requires_grad_(False)
    assert bound.hparams.latent_dim == model.hparams.latent_dim and not model.training
    assert not any(p.requires_grad for p in model.parameters())
    z = torch.randn(5, bound.hparams.latent_dim, generator=torch.Generator().manual_seed(0)).requires_grad_(True)
    features, duration = bound.denormalize(bound.net.decode(z))  # the controller's step cost, differentiable in z
    expected = bound.decode_latent(z.detach())
    assert torch.allclose(features, expected.features, atol=1e-5)
    assert torch.allclose(duration, expected.duration_s, atol=1e-5)
    features.sum().backward()
    assert z.grad is not None and z.grad.abs().sum() > 0
    other = model.bind_example(data.example_clip("youthful"))  # the bound condition is what decodes
    assert not torch.allclose(other.net.decode(z.detach()), bound.net.decode(z.detach()))


def test_sampling_needs_an_example_and_the_data_must_pair_styles(ae_ckpt, trained) -> None:
    with pytest.raises(ValueError, match="generates the style of an example"):
        trained[True].sample(4, seed=0)
    with pytest.raises(ValueError, match=r"example features must be \(32, time\)"):
        trained[True].sample(4, seed=0, example=torch.zeros(16, 9))
    with pytest.raises(ValueError, match="MultiStyleDataModule"):
        fit(ZeroShotStyleVAE(**TINY_NET), feature_module(ae_ckpt), steps=1)


@pytest.mark.parametrize("kwargs, message", [
    ({"embedding_dim": 0}, "embedding_dim must be a whole number"),
    ({"style_weight": -1.0}, "style_weight must be ≥ 0"),
    ({"style_latents": "all"}, "style_latents must be one of"),
    ({"sample_temperature": -0.5}, "sample_temperature must be a finite number ≥ 0"),
    ({"sample_temperature": float("nan")}, "sample_temperature must be a finite number ≥ 0"),
])
def test_bad_hyperparameters_are_refused(kwargs, message) -> None:
    with pytest.raises(ValueError, match=message):
        ZeroShotStyleVAE(**kwargs)


def test_an_embedding_wider_than_the_data_is_refused(data) -> None:
    with pytest.raises(ValueError, match="model.embedding_dim=500 needs at least 501 training clips"):
        fit(ZeroShotStyleVAE(**{**TINY_NET, "embedding_dim": 500}), data, steps=1)


def test_the_condition_of_k_examples_is_the_mean_embedding_and_anchor_of_all_their_clips(trained, tmp_path) -> None:
    """stylemotion-style example=[…] and stylemotion.load(…).sample(example=[…]): the network's condition is the
    mean over the clips of every example, checked against the embedding and anchor computed here in float64
    from each clip resampled and encoded; the loader pools a list of motion files the same way, and a list of
    one file is that file."""
    from stylemotion.datasets.loading import ConversionSettings
    from stylemotion.datasets.user_motion import convert_example, parse_example
    from stylemotion.io.export import write_motion_bvh
    from stylemotion.loading import Description, Model
    from stylemotion.primitives.segmentation import time_normalize
    from stylemotion.style_example.example import cut_examples

    model = trained[True].eval()
    examples = user_examples(3)
    cut = cut_examples(examples, "tired", "walk", [model.primitive], None)
    clips = cut.used[model.primitive]
    assert sorted(set(cut.origin[model.primitive])) == [0, 1, 2]
    embeddings, anchors = [], []
    mean, axes = model.style_mean.double().numpy(), model.style_axes.double().numpy()
    fmean, fstd = model.feature_mean.double().numpy(), model.feature_std.double().numpy()
    for clip in clips:
        frames = torch.from_numpy(time_normalize(clip.frames, model.timeline_frames)).float()[None]
        with torch.no_grad():
            f = model.autoencoder.encode(frames)[0].double().numpy()
        descriptor = np.concatenate([f.mean(1), f.std(1)])
        embeddings.append((descriptor - mean) @ axes.T / float(model.style_scale))
        anchors.append(np.append(((f - fmean[:, None]) / fstd[:, None]).ravel(), 0.0))
    condition = model.condition(clips)
    np.testing.assert_allclose(condition.embedding.double().numpy(), np.mean(embeddings, 0), rtol=1e-4, atol=1e-4)
    np.testing.assert_allclose(condition.anchor.double().numpy(), np.mean(anchors, 0), rtol=1e-4, atol=1e-4)
    # the loader (stylemotion.load(…).sample): a list of motion files pooled as the command pools them
    files = []
    for i, example in enumerate(examples):
        files.append(tmp_path / f"take{i}.bvh")
        write_motion_bvh(example.positions, files[-1], 30.0)
    network = Model("zero_shot", tmp_path, model, Description("zero_shot", str(tmp_path), primitive=model.primitive))
    converted = [convert_example(parse_example(str(f)), ConversionSettings(fps=model.fps)) for f in files]
    pooled = cut_examples(converted, "example", "walk", [model.primitive], None).used[model.primitive]
    assert len(pooled) == len(clips)
    assert torch.equal(network.sample(6, seed=2, example=[str(f) for f in files]).positions,
                       model.sample(6, seed=2, example=pooled).positions)
    assert torch.equal(network.sample(6, seed=2, example=[files[0]]).positions,
                       network.sample(6, seed=2, example=str(files[0])).positions)


def test_per_sample_pooling_conditions_each_sample_on_one_seeded_clip(trained) -> None:
    """``pooling=per_sample``: every sample's condition is exactly that of one of the clips, drawn with the seed."""
    from stylemotion.style_example.example import cut_examples

    model = trained[True].eval()
    clips = cut_examples(user_examples(2), "tired", "walk", [model.primitive], None).used[model.primitive]
    singles = [model.condition([c]) for c in clips]
    condition = model.per_sample_condition(clips, 40, seed=3)
    assert condition.embedding.shape == (40, model.hparams.embedding_dim)
    picks = [next(i for i, one in enumerate(singles) if torch.allclose(e, one.embedding, atol=1e-6)
                  and torch.allclose(a, one.anchor, atol=1e-6))
             for e, a in zip(condition.embedding, condition.anchor)]
    assert len(set(picks)) > 1  # the samples spread over the clips
    again = model.per_sample_condition(clips, 40, seed=3)
    assert torch.equal(again.embedding, condition.embedding)
    assert not torch.equal(model.per_sample_condition(clips, 40, seed=4).embedding, condition.embedding)
    bound = model.bind_example(clips, "tired", pooling="per_sample")
    assert torch.equal(bound.sample(40, seed=3).features, model.sample(40, seed=3, example=condition).features)
    assert torch.equal(model.bind_example(clips).sample(8, seed=3).features,
                       model.sample(8, seed=3, example=model.condition(clips)).features)
    with pytest.raises(ValueError, match="pooling must be one of"):
        model.bind_example(clips, pooling="max")


def test_the_networks_sample_pooling_is_what_bind_example_uses_and_one_clip_samples_alike(trained) -> None:
    """``sample_pooling`` (mean for the class and older checkpoints; the yaml's per_sample): the pooling of
    :meth:`bind_example` unless named, and of ``sample(example=<clips>)``; one clip gives the same samples either
    way."""
    from stylemotion.style_example.example import cut_examples

    model = trained[True].eval()
    clips = cut_examples(user_examples(2), "tired", "walk", [model.primitive], None).used[model.primitive]
    assert model.sample_pooling == "mean" and ZeroShotStyleVAE().sample_pooling == "mean"
    saved = copy.deepcopy(model)
    del saved.hparams["sample_pooling"]  # a checkpoint from before the setting
    assert saved.sample_pooling == "mean"
    try:
        model.set_sample_pooling("per_sample")
        assert model.bind_example(clips).pooling == "per_sample"
        assert torch.equal(model.bind_example(clips).sample(20, seed=3).features,
                           model.sample(20, seed=3, example=model.per_sample_condition(clips, 20, 3)).features)
        assert model.bind_example(clips, pooling="mean").pooling == "mean"
        # clips passed to sample() are bound first: the network's pooling, as stylemotion-style samples them
        assert torch.equal(model.sample(20, seed=3, example=clips).features,
                           model.bind_example(clips).sample(20, seed=3).features)
        assert not torch.equal(model.sample(20, seed=3, example=clips).features,
                               model.sample(20, seed=3, example=model.condition(clips)).features)
        one = model.bind_example(clips[:1]).sample(10, seed=5)
        model.set_sample_pooling("mean")
        assert torch.equal(one.features, model.bind_example(clips[:1]).sample(10, seed=5).features)
    finally:
        model.set_sample_pooling("mean")
    with pytest.raises(ValueError, match="sample_pooling must be one of"):
        model.set_sample_pooling("max")
    with pytest.raises(ValueError, match="sample_pooling must be one of"):
        ZeroShotStyleVAE(sample_pooling="median")


def test_centred_sampling_takes_the_variations_mean_over_the_prior_off_each_clips_samples(data, trained) -> None:
    """``sample_centred``: the centre is the decoder's mean variation over the fixed prior codes; every sample moves
    by it (one shift for all samples of one example, one per clip with per-sample pooling); only anchored networks."""
    from stylemotion.models.zero_shot import CENTRE_DRAWS
    from stylemotion.style_example.example import cut_examples

    model = trained[True].eval()
    condition = model.condition(data.example_clip("elderly"))
    draws = prior_draws(CENTRE_DRAWS, model.hparams.latent_dim, 0)
    centre = model.variation_centre(condition)
    assert torch.allclose(centre, model.net.decode(draws, condition.embedding).mean(0), atol=1e-6)
    assert centre.abs().max() > 0
    plain = model.sample(20, seed=2, example=condition).features
    try:
        model.set_sample_centred(True)
        centred = model.sample(20, seed=2, example=condition).features
        shift = centred - plain
        assert shift.abs().max() > 1e-4 and torch.allclose(shift, shift[:1].expand_as(shift), atol=1e-4)
        clips = cut_examples(user_examples(2), "tired", "walk", [model.primitive], None).used[model.primitive]
        per_sample = model.per_sample_condition(clips, 12, seed=3)
        centres = model.variation_centre(per_sample)
        singles = torch.stack([model.variation_centre(model.condition([c])) for c in clips])
        assert centres.shape == (12, centre.shape[-1])
        assert all(any(torch.allclose(c, one, atol=1e-5) for one in singles) for c in centres)
    finally:
        model.set_sample_centred(False)
    with pytest.raises(ValueError, match="sample_centred needs anchor=true"):
        trained[False].set_sample_centred(True)
    assert not ZeroShotStyleVAE(anchor=False, sample_centred=True).sample_centred  # the configs' default, unanchored


def test_the_sampling_temperature_scales_the_codes_and_is_saved_with_the_network(data, trained, tmp_path) -> None:
    """τ: the samples are the decodes of τ·z for the same draws z; τ = 0 gives every sample the prior's centre; a
    checkpoint saved before the setting existed samples at τ = 1; a set τ is saved with the network."""
    model = trained[True]
    bound = model.bind_example(data.example_clip("elderly"), style="elderly")
    draws = prior_draws(30, model.hparams.latent_dim, 5)
    assert model.sample_temperature == 1.0
    try:
        model.set_sample_temperature(0.5)
        cooled = bound.sample(30, seed=5)
        assert torch.allclose(cooled.latent, 0.5 * draws)
        assert torch.allclose(cooled.features, bound.decode_latent(0.5 * draws).features, atol=1e-6)
        model.set_sample_temperature(0)
        frozen = bound.sample(4, seed=5).features
        assert torch.allclose(frozen, frozen[:1].expand_as(frozen), atol=1e-6)
        model.set_sample_temperature(0.7)
        path = tmp_path / "cooled.ckpt"
        model.requires_grad_(True)  # an earlier test froze it, as the path-following does
        fit(model, data, steps=1).save_checkpoint(path, weights_only=False)  # last in the file: it trains
        assert checkpoint_hparams(path)["sample_temperature"] == 0.7
        assert load_generative(path).sample_temperature == 0.7
        with pytest.raises(ValueError, match="sample_temperature must be a finite number ≥ 0, got -1"):
            model.set_sample_temperature(-1)
        older = ZeroShotStyleVAE(**TINY_NET)
        del older.hparams["sample_temperature"]  # as a checkpoint saved before the setting existed
        assert older.sample_temperature == 1.0
    finally:
        model.set_sample_temperature(1.0)
