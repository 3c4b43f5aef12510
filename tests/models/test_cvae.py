"""The style CVAE: the Gram term pulls samples towards the example's style; which example(s) it used
is recorded; several examples average their Grams; bad style input gets clear errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch
from vae_fixtures import TINY_HIDDEN, feature_module, fit, tiny_autoencoder_ckpt, user_examples

from stylemotion.datamodules.clips import NoClipsError
from stylemotion.datamodules.features import ReceptiveFieldError, encode_examples
from stylemotion.models.autoencoder import IncompatibleModelError, MotionAutoencoder
from stylemotion.models.cvae import StyleCVAE, content_spread, margin_excess
from stylemotion.models.style import feature_style_distance, gram, mean_gram
from stylemotion.models.vae import PrimitiveVAE

torch.set_num_threads(1)


@pytest.fixture(scope="session")
def ae_ckpt(tmp_path_factory) -> Path:
    return tiny_autoencoder_ckpt(tmp_path_factory.mktemp("cvae_ae"))


@pytest.fixture(scope="module")
def elderly(ae_ckpt):
    return feature_module(ae_ckpt, style="elderly")


def _style_distances(model, target: torch.Tensor, n: int = 200) -> tuple[float, float]:
    """Mean ‖Gram(·) − target‖ over n samples: of the decoded features (what the loss sees) and of
    the sampled motions re-encoded by the autoencoder (thesis eq. 5.12)."""
    samples = model.sample(n, seed=0)
    reencoded = model.autoencoder.encode(samples.normalized_frames)
    return (feature_style_distance(samples.features, target).mean().item(),
            feature_style_distance(reencoded, target).mean().item())


def test_style_term_pulls_samples_to_the_example_and_the_example_is_recorded(elderly, tmp_path) -> None:
    target = mean_gram(elderly.style_features)
    torch.manual_seed(0)
    vae = PrimitiveVAE(samples_per_item=4)
    fit(vae, elderly, steps=100)
    torch.manual_seed(0)
    cvae = StyleCVAE(samples_per_item=4, style_weight=20.0)  # strong enough for 100 steps of this tiny test
    fit(cvae, elderly, steps=100, folder=tmp_path)
    (vae_direct, vae_motion), (cvae_direct, cvae_motion) = _style_distances(vae, target), _style_distances(cvae, target)
    # the CVAE's samples are much closer to the elderly example than the VAE's (the tiny autoencoder's
    # decode-encode round trip blurs the difference in the re-encoded motions, which are still closer)
    assert cvae_direct < 0.5 * vae_direct and cvae_motion < vae_motion, (vae_direct, cvae_direct, vae_motion,
                                                                          cvae_motion)
    assert vae.hparams.spec["style"] is None  # the plain VAE ignores the datamodule's style
    # the checkpoint says which clip the style came from, and carries the target Gram
    loaded = StyleCVAE.load_from_checkpoint(tmp_path / "best.ckpt")
    clip = elderly.clip_data.style_example("elderly")
    assert loaded.style == "elderly" and loaded.hparams.style_weight == 20.0
    [example] = loaded.style_examples
    assert (example["take"], example["start"], example["stop"]) == (clip.take, clip.start, clip.stop)
    assert example["style"] == "elderly" and example["encoded_frames"] == elderly.timeline_frames
    assert torch.allclose(loaded.style_gram, target)


def test_several_examples_of_any_length_average_their_grams(ae_ckpt) -> None:
    dm = feature_module(ae_ckpt, style="elderly", example_length="natural",
                        examples=[{}, {"pick": "index", "index": 1, "primitive": "rightStance"}])
    first, second = dm.style_examples
    assert first["primitive"] == "leftStance" and second["primitive"] == "rightStance"
    assert [f.shape[-1] for f in dm.style_features] == [(first["frames"] + 1) // 2, (second["frames"] + 1) // 2]
    model = StyleCVAE(spec=dm.model_spec())
    model._install_stats(dm)
    expected = (gram(dm.style_features[0]) + gram(dm.style_features[1])) / 2
    assert torch.allclose(model.style_gram, expected)
    assert model.style_examples[1]["take"] == second["take"] and model.spec["example_length"] == "natural"


def test_style_example_too_short_for_the_receptive_field(ae_ckpt) -> None:
    wide = MotionAutoencoder(hidden_units=TINY_HIDDEN, kernel_size=25)
    wide.net.normalizer.set_stats(torch.zeros(66), torch.ones(66))
    # the content is resampled to 30 frames (≥ 25), the example kept as recorded (about 19 frames)
    with pytest.raises(ReceptiveFieldError, match=r"has 1\d frames, fewer than the autoencoder's receptive field "
                                                   r"of 25 frames"):
        feature_module(ae_ckpt, autoencoder=wide, style="elderly", timeline=30, example_length="natural")
    # the same example resampled to the canonical 30 frames is long enough
    assert feature_module(ae_ckpt, autoencoder=wide, style="elderly", timeline=30).style_features[0].shape[-1] == 15
    # a median timeline shorter than the kernel is stretched to it (run steps: 12 frames); a fixed one is refused
    assert feature_module(ae_ckpt, autoencoder=wide).timeline_frames == 25
    with pytest.raises(ReceptiveFieldError, match="canonical length of walk_leftStance is 20 frames"):
        feature_module(ae_ckpt, autoencoder=wide, timeline=20)
    clip = feature_module(ae_ckpt).clip_data.style_example("normal")
    with pytest.raises(ReceptiveFieldError, match="receptive field of 25"):
        encode_examples(wide, [clip], length=None)


def test_style_with_no_clip(ae_ckpt) -> None:
    with pytest.raises(NoClipsError, match="style 'active' is not in dataset"):
        feature_module(ae_ckpt, style="active")
    with pytest.raises(NoClipsError, match=r"walk_leftStance/elderly needs an example clip.*no walk leftStance clip "
                                           r"of style 'elderly' from 'walk-turn-left' takes"):
        feature_module(ae_ckpt, style="elderly", examples=[{"content": "walk-turn-left"}])


def test_cvae_needs_a_style_and_keeps_it(ae_ckpt, elderly) -> None:
    plain = feature_module(ae_ckpt)
    with pytest.raises(ValueError, match="StyleCVAE needs a style"):
        StyleCVAE()._adapt_spec(plain.model_spec())
    model = StyleCVAE(spec=elderly.model_spec())
    other = feature_module(ae_ckpt, style="youthful")
    with pytest.raises(IncompatibleModelError, match="models style 'elderly', the data selects style 'youthful'"):
        model._check_spec(other.model_spec())


def test_margin_excess_is_zero_inside_the_ball_and_scale_free() -> None:
    distance = torch.tensor([0.5, 1.0, 1.5, 3.0])
    # inside (or on) the radius costs nothing; outside, the squared excess relative to the radius
    assert margin_excess(distance, 1.0).item() == pytest.approx((0.5**2 + 2.0**2) / 4)
    assert margin_excess(torch.tensor([0.2, 0.9]), 1.0).item() == 0.0
    # the same configuration in other Gram units gives the same value
    assert margin_excess(distance * 37.0, 37.0).item() == pytest.approx(margin_excess(distance, 1.0).item())


def test_content_spread_is_the_median_distance_to_the_mean_gram() -> None:
    generator = torch.Generator().manual_seed(0)
    features = torch.randn(9, 6, 5, generator=generator)
    centre = (features @ features.transpose(1, 2) / 5).mean(0)
    expected = torch.linalg.matrix_norm(features @ features.transpose(1, 2) / 5 - centre).median()
    assert content_spread(features) == pytest.approx(float(expected), rel=1e-5)
    assert content_spread(features[:1].repeat(4, 1, 1)) < 1e-3 * float(expected)  # copies: no spread


def test_margin_and_centred_terms_in_the_model(elderly) -> None:
    model = StyleCVAE(spec=elderly.model_spec(), style_term="margin", style_margin=2.0, style_centred=True)
    model._install_stats(elderly)
    train = elderly.datasets["train"].features
    centred = train - train.mean(-1, keepdim=True)
    assert model.style_radius == pytest.approx(2.0 * content_spread(centred), rel=1e-5)
    # a centred term does not see a constant offset of any channel over the clip
    shifted = train[:4] + torch.linspace(-3, 3, train.shape[1])[:, None]
    assert torch.allclose(model.style_distance(shifted), model.style_distance(train[:4]), rtol=1e-4)
    plain = StyleCVAE(spec=elderly.model_spec())
    plain._install_stats(elderly)
    assert not torch.allclose(plain.style_distance(shifted), plain.style_distance(train[:4]), rtol=1e-2)
    # the margin term is what is optimized; the distance is still logged
    terms = model._extra_losses(model.normalize(train[:3], elderly.datasets["train"].duration_s[:3])[None])
    assert terms["style"][1] == 0.0 and terms["style_excess"][1] == model.hparams.style_weight
    with pytest.raises(ValueError, match="style_term"):
        StyleCVAE(style_term="hinge")
    with pytest.raises(ValueError, match="style_margin"):
        StyleCVAE(style_margin=0.0)


def test_checkpoints_from_before_the_margin_term_and_the_contact_template_still_load(elderly, tmp_path) -> None:
    cvae = StyleCVAE(samples_per_item=2)
    fit(cvae, elderly, steps=2, folder=tmp_path)
    checkpoint = torch.load(tmp_path / "best.ckpt", weights_only=True)
    del checkpoint["state_dict"]["content_spread"]
    del checkpoint["state_dict"]["content_contacts"]
    del checkpoint["state_dict"]["style_log_duration"]
    for key in ("style_term", "style_margin", "style_centred", "sample_contacts"):
        checkpoint["hyper_parameters"].pop(key)
    torch.save(checkpoint, tmp_path / "old.ckpt")
    loaded = StyleCVAE.load_from_checkpoint(tmp_path / "old.ckpt")
    assert loaded.hparams.style_term == "distance" and torch.isnan(loaded.content_spread)
    assert loaded.content_contacts.shape == (loaded.timeline_frames, 2) and not bool(loaded.content_contacts.any())
    assert torch.isnan(loaded.style_log_duration)
    assert torch.allclose(loaded.style_gram, cvae.style_gram)


def test_the_gram_target_of_k_examples_is_the_mean_gram_of_all_their_clips(ae_ckpt) -> None:
    """stylemotion-style example=[…]: the CVAE's target is the mean Gram over the clips of every example, checked
    against the Grams computed here in float64 from each clip resampled and encoded; one example alone is the
    single-example path exactly."""
    from stylemotion.primitives.segmentation import time_normalize
    from stylemotion.style_example.example import cut_example, cut_examples

    primitive = "walk_leftStance"
    examples = user_examples(3)
    cut = cut_examples(examples, "tired", "walk", [primitive], None)
    clips = cut.used[primitive]
    assert sorted(set(cut.origin[primitive])) == [0, 1, 2] and len(clips) > 3  # several clips of every example
    dm = feature_module(ae_ckpt, style="tired", example_clips=clips, example_records=cut.records[primitive])
    model = StyleCVAE(spec=dm.model_spec())
    model._install_stats(dm)
    autoencoder = MotionAutoencoder.load_from_checkpoint(ae_ckpt, map_location="cpu").eval()
    grams = []
    for clip in clips:
        frames = torch.from_numpy(time_normalize(clip.frames, dm.timeline_frames)).float()[None]
        with torch.no_grad():
            f = autoencoder.encode(frames)[0].double().numpy()
        grams.append(f @ f.T / f.shape[1])
    expected = np.mean(grams, axis=0)
    np.testing.assert_allclose(model.style_gram.double().numpy(), expected, rtol=1e-5,
                               atol=1e-6 * np.abs(expected).max())
    assert [e["file"] for e in model.style_examples] == [examples[i].name for i in cut.origin[primitive]]
    # a list of one example: the target of that example's clips alone, as cut_example gives them
    alone = cut_example(examples[1], "tired", "walk", [primitive], None).used[primitive]
    one = feature_module(ae_ckpt, style="tired", example_clips=cut_examples([examples[1]], "tired", "walk",
                                                                             [primitive], None).used[primitive])
    single = feature_module(ae_ckpt, style="tired", example_clips=alone)
    assert torch.equal(mean_gram(one.style_features), mean_gram(single.style_features))
    first = [g for g, i in zip(grams, cut.origin[primitive]) if i == 1]
    np.testing.assert_allclose(mean_gram(single.style_features).double().numpy(), np.mean(first, axis=0),
                               rtol=1e-5, atol=1e-6 * np.abs(expected).max())


def _gram_by_hand(features: np.ndarray, normalization: str) -> np.ndarray:
    """Σ_t y_t y_tᵀ (÷ T for ``mean``) of ``(C, T)`` features, a loop over time in float64."""
    out = sum(np.outer(features[:, t], features[:, t]) for t in range(features.shape[1]))
    return out / features.shape[1] if normalization == "mean" else out


def test_the_summed_gram_option_trains_on_eq_5_9_as_written(elderly) -> None:
    """gram_normalization=sum (preset style_cvae_thesis): the target is the example's Σ_t y yᵀ and the term the
    Frobenius distance of each decode's Σ_t y yᵀ to it, both against numpy by hand; Table 5.1's recomputed Gram is
    not this matrix, so the evaluation is given none."""
    model = StyleCVAE(spec=elderly.model_spec(), gram_normalization="sum")
    model._install_stats(elderly)
    [example] = elderly.style_features
    target = _gram_by_hand(example.double().numpy().reshape(example.shape[-2], -1), "sum")
    np.testing.assert_allclose(model.style_gram.double().numpy(), target, rtol=1e-5, atol=1e-6 * np.abs(target).max())
    train = elderly.datasets["train"].features[:3]
    expected = [np.linalg.norm(_gram_by_hand(f.double().numpy(), "sum") - target) for f in train]
    np.testing.assert_allclose(model.style_distance(train).double().numpy(), expected, rtol=1e-4)
    default = StyleCVAE(spec=elderly.model_spec())
    default._install_stats(elderly)
    assert default.plain_gram and not model.plain_gram
    mean_target = _gram_by_hand(example.double().numpy().reshape(example.shape[-2], -1), "mean")
    np.testing.assert_allclose(default.style_gram.double().numpy(), mean_target, rtol=1e-5,
                               atol=1e-6 * np.abs(mean_target).max())
    with pytest.raises(ValueError, match="gram_normalization"):
        StyleCVAE(gram_normalization="max")


def test_the_pose_only_gram_leaves_root_velocity_and_yaw_rate_out(elderly) -> None:
    """style_channels=pose: the features decoded, root velocity and yaw rate zeroed, encoded again — equal to an
    encoder whose weights for those three channels are removed; the target is the Gram of the example's pose-only
    features; bad values are refused."""
    model = StyleCVAE(spec=elderly.model_spec(), style_channels="pose")
    model._install_stats(elderly)
    train = elderly.datasets["train"].features[:4]
    net = elderly.autoencoder.net
    reference = torch.nn.Conv1d(net.encoder.in_channels, net.encoder.out_channels, net.encoder.kernel_size[0],
                                padding="same")
    with torch.no_grad():
        reference.weight.copy_(net.encoder.weight)
        reference.weight[:, 63:66, :] = 0  # no weight for root ground velocity (2) and yaw rate (1)
        reference.bias.copy_(net.encoder.bias)
        frames = net.decode_normalized(train)
        expected = torch.nn.functional.avg_pool1d(torch.relu(reference(frames.transpose(-1, -2))), 2)
        got = model._style_features(train)
    torch.testing.assert_close(got, expected, rtol=1e-5, atol=1e-6)
    # changing only the root channels of the decoded frames changes nothing the pose-only encoder sees
    with torch.no_grad():
        moved = frames.clone()
        moved[..., 63:66] += 5.0
        shifted = torch.nn.functional.avg_pool1d(torch.relu(reference(moved.transpose(-1, -2))), 2)
    torch.testing.assert_close(shifted, expected)
    [example] = elderly.style_features
    with torch.no_grad():
        pose_example = model._style_features(example.reshape(1, *example.shape[-2:]))[0].double().numpy()
    target = _gram_by_hand(pose_example, "mean")
    np.testing.assert_allclose(model.style_gram.double().numpy(), target, rtol=1e-4, atol=1e-6 * np.abs(target).max())
    assert not model.plain_gram
    with pytest.raises(ValueError, match="style_channels"):
        StyleCVAE(style_channels="root")


def test_the_style_subset_takes_the_mean_over_k_random_decodes(elderly) -> None:
    """style_subset=k: the term is the mean distance of k of the decodes (the ones a seeded permutation picks);
    k ≥ their number, or 0, is every decode."""
    model = StyleCVAE(spec=elderly.model_spec(), style_latents="posterior", style_subset=3)
    model._install_stats(elderly)
    train = elderly.datasets["train"]
    y = model.normalize(train.features[:4], train.duration_s[:4])[None].repeat(2, 1, 1)  # (L=2, 4, D)
    distances = model.style_distance(model.denormalize(y.flatten(0, 1), clamp=False)[0])
    picked = torch.randperm(8, generator=torch.Generator().manual_seed(3))[:3]
    term = model._extra_losses(y, torch.Generator().manual_seed(3))["style"][0]
    torch.testing.assert_close(term, distances[picked].mean())
    every = StyleCVAE(spec=elderly.model_spec(), style_latents="posterior", style_subset=8)
    every._install_stats(elderly)
    torch.testing.assert_close(every._extra_losses(y)["style"][0], distances.mean())
    with pytest.raises(ValueError, match="style_subset"):
        StyleCVAE(style_subset=-1)


def test_the_styled_duration_term_moves_the_draws_mean_duration_to_the_examples(ae_ckpt) -> None:
    """Ground truth: the example clips are recorded as lasting 1.3× the content clips' geometric mean; with γ the
    draws' mean duration moves most of the way there (γ / (γ + w/2) of the gap, module doc), without it it stays."""
    dm = feature_module(ae_ckpt, style="elderly")
    content = dm.datasets["train"].duration_s.double().log().mean().exp().item()
    dm.style_examples = [{**e, "duration_s": 1.3 * content} for e in dm.style_examples]
    means = {}
    for gamma in (0.0, 500.0):
        torch.manual_seed(0)
        model = StyleCVAE(samples_per_item=4, style_weight=1.0, style_duration_weight=gamma)
        fit(model, dm, steps=150)
        assert model.style_log_duration.item() == pytest.approx(np.log(1.3 * content))
        means[gamma] = model.sample(400, seed=0).duration_s.double().log().mean().exp().item() / content
    assert abs(means[0.0] - 1.0) < 0.1 and means[500.0] > 1.2, means
    # the term by hand: (mean standardized log-duration − the standardized target)²
    mean, sd = model.duration_stats[0].item(), model.duration_stats[1].item()
    draws = torch.tensor([0.5, -0.5, 1.0])
    target = (np.log(1.3 * content) - mean) / sd
    assert model.style_duration_term(draws).item() == pytest.approx((1 / 3 - target) ** 2, rel=1e-5)
    assert "style_duration" not in StyleCVAE(spec=dm.model_spec())._extra_losses(
        model.normalize(dm.datasets["train"].features[:2], dm.datasets["train"].duration_s[:2])[None])
    with pytest.raises(ValueError, match="style_duration_weight"):
        StyleCVAE(style_duration_weight=-1.0)
