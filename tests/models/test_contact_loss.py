"""The foot-contact velocity loss (:mod:`stylemotion.models.contact_loss`): zero for planted feet and the
squared sliding speed otherwise, root motion included; contacts carried to the canonical timeline; its gradient
reaches the decoders (not the frozen autoencoder); each model's ``contact_weight`` comes from its Hydra config;
and a tiny seeded training with weight > 0 decodes slower contact feet than with weight 0."""

from __future__ import annotations

from pathlib import Path

import lightning.pytorch as pl
import numpy as np
import pytest
import torch
from hydra import compose, initialize_config_dir
from hydra.utils import instantiate
from vae_fixtures import TINY_DATA, feature_module, fit, tiny_autoencoder_ckpt, tiny_takeset, validate

from stylemotion.config import config_dir
from stylemotion.datamodules import MotionWindowDataModule
from stylemotion.models.autoencoder import ConvAutoencoder, MotionAutoencoder
from stylemotion.models.contact_loss import (
    contact_runs,
    contact_velocity_loss,
    midstance_loss,
    own_contacts,
    planted_speed_squared,
    timeline_contacts,
    window_contacts,
)
from stylemotion.models.cvae import CONTENT_CONTACT_MAJORITY, StyleCVAE, content_contact_template
from stylemotion.models.vae import PrimitiveVAE
from stylemotion.primitives.contacts import foot_contacts
from stylemotion.representation import FRAME_DIM, VELOCITY_DIMS, frames_to_positions, positions_to_frames
from stylemotion.skeleton import FOOT_POINTS

torch.set_num_threads(1)
FPS = 30.0


@pytest.fixture(scope="session")
def ae_ckpt(tmp_path_factory) -> Path:
    return tiny_autoencoder_ckpt(tmp_path_factory.mktemp("contact_ae"))


def standing(frames: int = 12) -> torch.Tensor:
    """``(1, frames, 66)``: one pose held still (a real synthetic pose), root and heading fixed."""
    take = tiny_takeset().takes[0]
    pose, _, _ = positions_to_frames(take.positions[:2], FPS)
    out = torch.zeros(1, frames, FRAME_DIM, dtype=torch.float64)
    out[0, :, :63] = torch.as_tensor(pose[0, :63], dtype=torch.float64)
    return out


def slide_left_foot(frames: torch.Tensor, speed: float) -> torch.Tensor:
    """``frames`` with the left heel and ball moving along +X at ``speed`` m/s (root-local, no turning)."""
    out = frames.clone()
    t = torch.arange(frames.shape[1], dtype=frames.dtype) / FPS
    for joint in FOOT_POINTS[0]:
        out[0, :, 3 * joint] += speed * t
    return out


def test_still_feet_cost_nothing_and_sliding_feet_cost_their_squared_speed() -> None:
    frames = standing()
    contacts = torch.ones(1, frames.shape[1], 2, dtype=torch.bool)
    assert float(contact_velocity_loss(frames, contacts, FPS)) == pytest.approx(0.0, abs=1e-12)
    slid = slide_left_foot(frames, 0.5)
    speeds = planted_speed_squared(slid, FPS)
    assert torch.allclose(speeds[..., 0], torch.full_like(speeds[..., 0], 0.25))
    assert torch.allclose(speeds[..., 1], torch.zeros_like(speeds[..., 1]), atol=1e-12)
    # both feet in contact: the mean over contact foot-frames is half the left foot's 0.25 m²/s²
    assert float(contact_velocity_loss(slid, contacts, FPS)) == pytest.approx(0.125)
    # only the right (still) foot in contact: the sliding left foot is free
    right = contacts.clone()
    right[..., 0] = False
    assert float(contact_velocity_loss(slid, right, FPS)) == pytest.approx(0.0, abs=1e-12)
    # no contact at all: zero, not NaN
    assert float(contact_velocity_loss(slid, torch.zeros_like(contacts), FPS)) == 0.0


def test_a_foot_carried_by_the_moving_root_slides_in_world_space() -> None:
    frames = standing()
    frames[0, :, VELOCITY_DIMS.start + 1] = 1.0  # the root walks forward at 1 m/s, the pose held
    contacts = torch.ones(1, frames.shape[1], 2, dtype=torch.bool)
    assert float(contact_velocity_loss(frames, contacts, FPS)) == pytest.approx(1.0)
    # per-motion rates (a time-normalized clip's playback rate): the root's velocity channels are per second,
    # so the root's speed does not depend on the rate, but a root-local slide of so many metres per frame does
    rate = torch.tensor([FPS / 2])
    assert float(contact_velocity_loss(frames, contacts, rate)) == pytest.approx(1.0)
    slid = slide_left_foot(standing(), 0.5)
    left = contacts.clone()
    left[..., 1] = False
    assert float(contact_velocity_loss(slid, left, rate)) == pytest.approx(0.25 / 4)


def test_the_planted_point_is_the_slower_of_heel_and_ball() -> None:
    frames = standing()
    heel, ball = FOOT_POINTS[0]
    t = torch.arange(frames.shape[1], dtype=frames.dtype) / FPS
    frames[0, :, 3 * heel] += 0.4 * t  # the heel rises off and moves: the ball holds the ground
    steps = frames.shape[1] - 1
    assert torch.allclose(planted_speed_squared(frames, FPS)[..., 0], torch.zeros(1, steps, dtype=frames.dtype),
                          atol=1e-12)
    frames[0, :, 3 * ball] += 0.3 * t
    assert torch.allclose(planted_speed_squared(frames, FPS)[..., 0], torch.full((1, steps), 0.09, dtype=frames.dtype))


def test_contact_runs_are_the_maximal_runs_of_two_or_more_frames_per_foot() -> None:
    pattern = torch.tensor([[1, 0], [1, 1], [1, 1], [0, 1], [1, 0], [1, 0], [0, 0], [1, 0]], dtype=torch.bool)
    assert contact_runs(pattern) == [(0, 0, 2), (0, 4, 5), (1, 1, 3)]  # the single frame 7 is no run
    assert contact_runs(torch.zeros(5, 2, dtype=torch.bool)) == []


def inchworm(frames: torch.Tensor, step_m: float) -> torch.Tensor:
    """``frames`` whose left heel and ball take turns to move back by ``step_m`` (root-local −X): every frame
    one of them is still, so the per-frame slower point never moves, while the foot travels."""
    out = frames.clone()
    heel, ball = FOOT_POINTS[0]
    shift = torch.zeros(2, frames.shape[1], dtype=frames.dtype)
    for t in range(1, frames.shape[1]):
        shift[:, t] = shift[:, t - 1]
        shift[t % 2, t] -= step_m  # odd frames move the ball, even frames the heel
    out[0, :, 3 * heel] += shift[0]
    out[0, :, 3 * ball] += shift[1]
    return out


def test_the_midstance_term_holds_heel_and_ball_both_where_the_slower_point_can_be_cheated() -> None:
    still = standing(13)
    runs = [(0, 0, 12)]  # the left foot's run over all 13 frames: its middle half is frames 3 .. 9
    assert float(midstance_loss(still, runs, FPS)) == pytest.approx(0.0, abs=1e-12)
    walked = inchworm(still, 0.01)
    contacts = torch.zeros(1, 13, 2, dtype=torch.bool)
    contacts[..., 0] = True
    assert float(contact_velocity_loss(walked, contacts, FPS)) == pytest.approx(0.0, abs=1e-12)
    # each step one point moves 1 cm per frame (0.3 m/s, 0.09 m²/s²), the other is still: the mean is 0.045
    assert float(midstance_loss(walked, runs, FPS)) == pytest.approx(0.045)
    # outside the middle half nothing counts: a slide over frames 0 .. 3 and 9 .. 12 only
    ends = still.clone()
    heel, ball = FOOT_POINTS[0]
    for j in (heel, ball):
        ends[0, :4, 3 * j] += torch.linspace(-0.3, 0.0, 4, dtype=ends.dtype)
        ends[0, 9:, 3 * j] += torch.linspace(0.0, 0.3, 4, dtype=ends.dtype)
    assert float(midstance_loss(ends, runs, FPS)) == pytest.approx(0.0, abs=1e-12)
    assert float(midstance_loss(still, [], FPS)) == 0.0


def test_the_content_template_is_the_majority_of_the_content_clips_contacts() -> None:
    shares = torch.tensor([[1.0, CONTENT_CONTACT_MAJORITY], [0.51, 0.2]])
    assert content_contact_template(shares).tolist() == [[True, False], [True, False]]


def test_contacts_are_those_of_the_detector_carried_to_the_timeline() -> None:
    positions = tiny_takeset().takes[0].positions[:40]
    expected = foot_contacts(positions, FPS)
    p = torch.as_tensor(positions[None], dtype=torch.float32)
    same = timeline_contacts(p, torch.tensor([40]), FPS, 40)
    assert same.shape == (1, 40, 2) and bool(same.any()) and bool((~same).any())
    assert np.array_equal(same[0].numpy(), expected)
    # 40 recorded frames on a 14-frame timeline: frame j takes recorded frame round(j · 39 / 13) = 3 j
    short = timeline_contacts(p, torch.tensor([40]), FPS, 14)
    assert np.array_equal(short[0].numpy(), expected[np.arange(14) * 3])
    # padding past num_frames is ignored: the first 25 frames alone give the same contacts
    padded = timeline_contacts(p, torch.tensor([25]), FPS, 25)
    assert np.array_equal(padded[0].numpy(), foot_contacts(positions[:25], FPS))
    # window contacts go through the inverse representation: frames of the same take, the same decision
    frames, _, _ = positions_to_frames(positions, FPS)
    back = frames_to_positions(frames, FPS)
    assert np.array_equal(window_contacts(torch.as_tensor(frames[None]), FPS)[0].numpy(), foot_contacts(back, FPS))


def test_own_contacts_are_the_detectors_on_each_decoded_motion_at_its_own_rate() -> None:
    positions = tiny_takeset().takes[0].positions[:40]
    frames, _, _ = positions_to_frames(positions, FPS)
    back = frames_to_positions(frames, FPS)
    pair = torch.as_tensor(np.stack([frames, frames]))
    got = own_contacts(pair, torch.tensor([FPS, 2 * FPS]))
    assert got.shape == (2, 40, 2) and got.dtype == torch.bool
    assert np.array_equal(got[0].numpy(), foot_contacts(back, FPS))
    # the same frames read at twice the rate: the root travels and the feet move twice as fast per second
    assert np.array_equal(got[1].numpy(), foot_contacts(frames_to_positions(frames, 2 * FPS), 2 * FPS))
    assert not np.array_equal(got[0].numpy(), got[1].numpy())
    with pytest.raises(ValueError, match="one rate per motion"):
        own_contacts(pair, torch.tensor([FPS]))


def test_the_cvae_draws_contact_term_holds_their_own_planted_feet(ae_ckpt) -> None:
    """sample_contact_weight: the term is the contact velocity loss of the style term's decodes on their own
    contacts at their own durations, weighted by β; its gradient reaches the decoder, not the autoencoder."""
    dm = feature_module(ae_ckpt, style="elderly")
    pl.seed_everything(0, verbose=False)
    model = StyleCVAE(samples_per_item=2, style_latents="prior", sample_contact_weight=3.0)
    fit(model, dm, steps=100)  # until the draws plant their feet (untrained ones never do)
    model.train()
    y = model.normalize(dm.datasets["train"].features[:4], dm.datasets["train"].duration_s[:4])[None]
    terms = model._extra_losses(y.repeat(2, 1, 1), torch.Generator().manual_seed(5))
    value, weight = terms["sample_contact"]
    assert weight == 3.0 and float(value.detach()) > 0
    # by hand: the same 8 prior draws, decoded at their own durations, on their own contacts
    z = torch.randn(8, model.hparams.latent_dim, generator=torch.Generator().manual_seed(5))
    features, duration = model.denormalize(model.net.decode(z))
    length = model.timeline_frames
    frames = model.autoencoder.decode(features, length).float()
    rate = (length - 1) / duration
    expected = contact_velocity_loss(frames, own_contacts(frames, rate), rate)
    torch.testing.assert_close(value, expected, rtol=1e-4, atol=1e-7)
    grad, = torch.autograd.grad(value, model.net.decoder[-1].weight)
    assert float(grad.abs().sum()) > 0
    assert all(p.grad is None for p in model.autoencoder.parameters())
    model.hparams.sample_contact_weight = 0.0
    assert "sample_contact" not in model._extra_losses(y.repeat(2, 1, 1))
    with pytest.raises(ValueError, match="sample_contact_weight"):
        StyleCVAE(sample_contact_weight=-1.0)


def test_the_cvae_draws_content_term_uses_the_content_clips_template(ae_ckpt) -> None:
    """sample_contacts=content: the template is the majority of the content train clips' timeline contacts (a
    buffer, so it travels with the checkpoint); the term is the velocity loss on it plus the mid-stance term."""
    dm = feature_module(ae_ckpt, style="elderly")
    pl.seed_everything(0, verbose=False)
    model = StyleCVAE(samples_per_item=2, style_latents="prior", sample_contact_weight=3.0,
                      sample_contacts="content")
    fit(model, dm, steps=2)
    train = dm.datasets["train"]
    length = model.timeline_frames
    shares = timeline_contacts(train.positions, train.num_frames, model.fps, length).float().mean(0)
    torch.testing.assert_close(model.content_contacts, shares)
    template = content_contact_template(shares)
    assert bool(template.any())
    z = torch.randn(6, model.hparams.latent_dim, generator=torch.Generator().manual_seed(2))
    features, duration = model.denormalize(model.net.decode(z))
    frames = model.autoencoder.decode(features, length).float()
    rate = (length - 1) / duration.detach()
    expected = (contact_velocity_loss(frames, template.expand(6, -1, -1), rate)
                + midstance_loss(frames, contact_runs(template), rate))
    torch.testing.assert_close(model.sample_contact_term(features, duration), expected, rtol=1e-4, atol=1e-7)
    with pytest.raises(ValueError, match="sample_contacts"):
        StyleCVAE(sample_contacts="everywhere")


def test_the_gradient_reaches_the_decoder_not_only_the_output() -> None:
    torch.manual_seed(0)
    net = ConvAutoencoder(hidden_units=8)
    net.normalizer.set_stats(torch.zeros(FRAME_DIM), torch.ones(FRAME_DIM))
    frames = slide_left_foot(standing(16), 0.5).float()
    loss = contact_velocity_loss(net(frames), torch.ones(1, 16, 2, dtype=torch.bool), FPS)
    loss.backward()
    assert float(loss.detach()) > 0 and float(net.decoder.weight.grad.abs().sum()) > 0


def test_the_vae_contact_term_reaches_its_decoder_and_leaves_the_autoencoder_frozen(ae_ckpt) -> None:
    dm = feature_module(ae_ckpt)
    pl.seed_everything(0, verbose=False)
    model = PrimitiveVAE(samples_per_item=2, contact_weight=5.0)
    fit(model, dm, steps=1)  # builds the network from the data and attaches the autoencoder
    model.train()
    batch = next(iter(dm.train_dataloader()))
    model.zero_grad()
    terms = model.losses(batch)
    assert float(terms["contact"]) > 0
    grad, = torch.autograd.grad(terms["contact"], model.net.decoder[-1].weight, retain_graph=True)
    assert float(grad.abs().sum()) > 0
    terms["loss"].backward()
    assert all(p.grad is None for p in model.autoencoder.parameters())
    # the weight multiplies the logged term: the same batch and noise without it differ by exactly w · contact
    generator = torch.Generator().manual_seed(3)
    with_term = model.losses(batch, generator)
    model.hparams.contact_weight = 0.0
    generator = torch.Generator().manual_seed(3)
    without = model.losses(batch, generator)
    assert "contact" not in without  # not computed while training without it
    assert float(with_term["loss"] - without["loss"]) == pytest.approx(5.0 * float(with_term["contact"]), rel=1e-4)


@pytest.mark.parametrize(("experiment", "target", "default_weight"), [("autoencoder", "MotionAutoencoder", 0.1),
                                                               ("primitive_vae", "PrimitiveVAE", 100.0),
                                                               ("style_cvae", "StyleCVAE", 0.0),
                                                               ("zero_shot", "ZeroShotStyleVAE", 0.0)])
def test_contact_weight_flows_from_each_models_config(experiment: str, target: str, default_weight: float) -> None:
    """The configs' defaults are the weights suite contact_full confirmed (the CVAE and the zero-shot network 0)."""
    base = [f"experiment={experiment}"] + ([] if experiment == "autoencoder" else ["autoencoder_ckpt=x"])
    with initialize_config_dir(config_dir(), version_base="1.3"):
        default = compose("train", overrides=base)
        set_ = compose("train", overrides=[*base, "model.contact_weight=7"])
    assert default.model.contact_weight == default_weight
    model = instantiate(set_.model, _convert_="all")
    assert type(model).__name__ == target and model.hparams.contact_weight == 7.0


def test_the_draws_contact_weight_flows_from_the_cvae_config() -> None:
    base = ["experiment=style_cvae", "autoencoder_ckpt=x"]
    with initialize_config_dir(config_dir(), version_base="1.3"):
        default = compose("train", overrides=base)
        set_ = compose("train", overrides=[*base, "model.sample_contact_weight=7"])
    assert default.model.sample_contact_weight == 0.0
    assert instantiate(set_.model, _convert_="all").hparams.sample_contact_weight == 7.0


def decoded_contact_speed_vae(ae_ckpt: Path, weight: float, folder: Path) -> float:
    """val/contact (m²/s²) of a VAE trained for a few epochs on the tiny data with ``contact_weight`` = weight."""
    dm = feature_module(ae_ckpt)
    pl.seed_everything(0, verbose=False)
    model = PrimitiveVAE(samples_per_item=2, contact_weight=weight)
    fit(model, dm, steps=150)
    return validate(model, dm)["val/contact"]


def test_training_with_the_contact_weight_slows_the_decoded_contact_feet_vae(ae_ckpt, tmp_path) -> None:
    plain = decoded_contact_speed_vae(ae_ckpt, 0.0, tmp_path / "w0")
    held = decoded_contact_speed_vae(ae_ckpt, 200.0, tmp_path / "w200")
    assert held < 0.7 * plain, (plain, held)


def decoded_contact_speed_autoencoder(weight: float) -> float:
    """val/contact (m²/s²) of a tiny autoencoder trained for 80 steps with ``contact_weight`` = weight."""
    pl.seed_everything(0, verbose=False)
    dm = MotionWindowDataModule(takeset=tiny_takeset(), window_frames=30, stride=15, batch_size=32,
                                split=TINY_DATA["split"])
    model = MotionAutoencoder(hidden_units=16, lr=3e-3, contact_weight=weight)
    trainer = pl.Trainer(accelerator="cpu", max_steps=80, logger=False, enable_checkpointing=False,
                         enable_progress_bar=False, enable_model_summary=False, num_sanity_val_steps=0,
                         limit_val_batches=0)
    trainer.fit(model, datamodule=dm)
    return validate(model, dm)["val/contact"]


def test_training_with_the_contact_weight_slows_the_decoded_contact_feet_autoencoder() -> None:
    plain = decoded_contact_speed_autoencoder(0.0)
    held = decoded_contact_speed_autoencoder(1.0)
    assert held < 0.7 * plain, (plain, held)


def draws_contact_and_style(ae_ckpt: Path, weight: float) -> tuple[float, float]:
    """The draws' own-contact term (m²/s²) and mean style distance of 64 prior draws of a CVAE trained for 150
    steps on the tiny data with ``sample_contact_weight`` = weight."""
    dm = feature_module(ae_ckpt, style="elderly")
    pl.seed_everything(0, verbose=False)
    model = StyleCVAE(samples_per_item=2, style_weight=20.0, sample_contact_weight=weight)
    fit(model, dm, steps=150)
    z = torch.randn(64, model.hparams.latent_dim, generator=torch.Generator().manual_seed(5))
    with torch.no_grad():
        features, duration = model.denormalize(model.net.decode(z))
        return float(model.sample_contact_term(features, duration)), float(model.style_distance(features).mean())


def test_training_with_the_draws_contact_weight_slows_their_planted_feet_and_keeps_the_style(ae_ckpt) -> None:
    plain_contact, plain_style = draws_contact_and_style(ae_ckpt, 0.0)
    held_contact, held_style = draws_contact_and_style(ae_ckpt, 30.0)
    assert held_contact < 0.5 * plain_contact, (plain_contact, held_contact)
    assert held_style < 1.2 * plain_style, (plain_style, held_style)
