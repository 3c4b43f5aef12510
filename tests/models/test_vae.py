"""The primitive VAE: network and losses (eq. 5.5–5.8), Gram matrix, feature DataModule, training,
checkpoints that load in a fresh process, and bad input (too few clips, mismatching autoencoder)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import torch
from vae_fixtures import TINY_HIDDEN, feature_module, fit, tiny_autoencoder_ckpt, tiny_takeset, validate

from stylemotion.datamodules.features import FeatureDataModule, TooFewClipsError
from stylemotion.models.autoencoder import IncompatibleModelError, MotionAutoencoder
from stylemotion.models.checkpoints import fingerprint, load_autoencoder
from stylemotion.models.style import feature_style_distance, gram, gram_factor, mean_gram, style_distance
from stylemotion.models.vae import MLPVAE, PrimitiveVAE, kl_divergence, reconstruction_loss
from stylemotion.primitives.segmentation import parse_primitive

torch.set_num_threads(1)


@pytest.fixture(scope="session")
def ae_ckpt(tmp_path_factory) -> Path:
    return tiny_autoencoder_ckpt(tmp_path_factory.mktemp("vae_ae"))


@pytest.fixture(scope="module")
def dm(ae_ckpt):
    return feature_module(ae_ckpt)


# -- network, losses, Gram


def test_mlp_vae_architecture_and_losses() -> None:
    net = MLPVAE(input_dim=40, latent_dim=32)
    widths = [(m.in_features, m.out_features) for m in net.encoder if isinstance(m, torch.nn.Linear)]
    assert widths == [(40, 512), (512, 256), (256, 128)]
    assert (net.mean.in_features, net.mean.out_features) == (128, 32) == (net.logvar.in_features, 32)
    widths = [(m.in_features, m.out_features) for m in net.decoder if isinstance(m, torch.nn.Linear)]
    assert widths == [(32, 128), (128, 256), (256, 512), (512, 40)]
    assert sum(isinstance(m, torch.nn.Tanh) for m in net.decoder) == 3  # linear output layer
    y = torch.randn(5, 40)
    recon, mean, logvar, z = net(y, samples=10, generator=torch.Generator().manual_seed(0))
    assert recon.shape == (10, 5, 40) and mean.shape == logvar.shape == (5, 32) and z.shape == (10, 5, 32)
    # eq. 5.7 by hand: 1/(2NL) ΣΣ ‖·‖²; the weights scale single values
    expected = ((recon - y) ** 2).sum(-1).sum() / (2 * 5 * 10)
    assert torch.allclose(reconstruction_loss(recon, y), expected)
    w = torch.ones(40)
    w[-1] = 3.0
    extra = ((recon - y)[..., -1] ** 2).sum() / (2 * 5 * 10) * 2.0
    assert torch.allclose(reconstruction_loss(recon, y, w), expected + extra)
    # eq. 5.8: zero for the prior itself, the closed form otherwise
    assert kl_divergence(torch.zeros(3, 32), torch.zeros(3, 32)).item() == 0.0
    mu, lv = torch.full((2, 32), 0.5), torch.full((2, 32), np.log(2.0))
    assert abs(kl_divergence(mu, lv).item() - 0.5 * 32 * (0.25 + 2 - 1 - np.log(2.0))) < 1e-4
    # reparameterization: μ + σ ε
    draws = MLPVAE.reparameterize(torch.full((1, 32), 3.0), torch.full((1, 32), np.log(4.0)), samples=4000,
                                  generator=torch.Generator().manual_seed(1))
    assert abs(draws.mean().item() - 3.0) < 0.02 and abs(draws.std().item() - 2.0) < 0.02


def test_gram_is_normalized_by_time_and_length_invariant() -> None:
    torch.manual_seed(0)
    f = torch.randn(2, 6, 5)  # (batch, channels, time)
    g = gram(f)
    assert g.shape == (2, 6, 6)
    by_hand = sum(torch.outer(f[1, :, t], f[1, :, t]) for t in range(5)) / 5
    assert torch.allclose(g[1], by_hand, atol=1e-6)
    assert torch.allclose(gram(f.repeat(1, 1, 3)), g, atol=1e-6)  # the same motion, three times as long
    assert torch.allclose(mean_gram([f[0], f[1, :, :2]]), (g[0] + gram(f[1, :, :2])) / 2)
    d = style_distance(g[0], g[1])
    assert torch.isclose(d, torch.sqrt(((g[0] - g[1]) ** 2).sum()))
    assert torch.allclose(feature_style_distance(f, g[1]), torch.stack([d, torch.tensor(0.0)]), atol=1e-5)
    # the training loss' factored form equals the definition on autoencoder-sized features
    big, target = torch.rand(64, 256, 9), gram(torch.rand(256, 11))
    direct = style_distance(gram(big), target)
    assert torch.allclose(feature_style_distance(big, target), direct, rtol=1e-4)
    assert gram_factor(target).shape == (256, 11)
    with pytest.raises(ValueError, match="different channel counts"):
        mean_gram([f[0], torch.randn(3, 4)])


# -- the feature DataModule


def test_features_are_the_autoencoders_encoding_of_time_normalized_clips(dm: FeatureDataModule, ae_ckpt) -> None:
    ae = load_autoencoder(ae_ckpt)
    train = dm.datasets["train"]
    length = dm.timeline_frames
    assert train.features.shape == (len(train), TINY_HIDDEN, (length + 1) // 2)
    clip_frames = dm.clip_data.datasets["train"].frames
    assert torch.allclose(train.features, ae.encode(clip_frames), atol=1e-6)
    assert torch.allclose(train.duration_s, torch.tensor([c.duration_s for c in train.clips]))
    first = train.clips[0]
    assert torch.allclose(train.positions[0, : first.num_frames], torch.from_numpy(first.positions))
    assert int(train.num_frames[0]) == first.num_frames
    assert torch.allclose(train.positions[0, first.num_frames:], train.positions[0, first.num_frames - 1])
    spec = dm.model_spec()
    assert spec["autoencoder"]["fingerprint"] == fingerprint(ae) and spec["autoencoder"]["path"] == str(ae_ckpt)
    assert spec["clips"]["train"] == len(train) >= 8 and spec["style"] is None
    flat = (train.features - dm.feature_mean[:, None]) / dm.feature_std[:, None]
    assert flat.transpose(1, 2).reshape(-1, TINY_HIDDEN).mean(0).abs().max() < 1e-4


# -- training


def test_vae_fits_and_its_checkpoint_loads_in_a_fresh_process(dm, tmp_path) -> None:
    torch.manual_seed(0)
    model = PrimitiveVAE(samples_per_item=4)
    untrained = validate(model, dm)
    before, before_loss = untrained["val/mpjpe"], untrained["val/loss"]
    trainer = fit(model, dm, steps=120, folder=tmp_path)
    after, after_loss = trainer.callback_metrics["val/mpjpe"].item(), trainer.callback_metrics["val/loss"].item()
    # untrained: ~9 cm (every clip decodes to about the mean motion) and loss ~140; after: ~3.5 cm, ~35
    assert after_loss < 0.6 * before_loss and 0 < after < 0.6 * before, (before, after, before_loss, after_loss)
    spec = model.hparams.spec
    assert spec["primitive"] == "walk_leftStance" and spec["timeline_frames"] == dm.timeline_frames
    assert spec["style"] is None and spec["clips"] == dm.model_spec()["clips"]
    ckpt = tmp_path / "best.ckpt"
    loaded = torch.load(ckpt, weights_only=True)  # plain values and tensors only
    assert loaded["hyper_parameters"]["spec"]["autoencoder"]["fingerprint"] == spec["autoencoder"]["fingerprint"]
    assert torch.equal(loaded["state_dict"]["feature_std"], dm.feature_std)
    best = PrimitiveVAE.load_from_checkpoint(ckpt)
    expected = best.sample(3, seed=7)
    script = textwrap.dedent(f"""
        import torch
        from stylemotion.models.vae import PrimitiveVAE
        m = PrimitiveVAE.load_from_checkpoint({str(ckpt)!r})   # torch's default weights_only=True
        s = m.sample(3, seed=7)
        torch.save({{k: getattr(s, k) for k in ("positions", "num_frames", "latent")}}, {str(tmp_path / "s.pt")!r})
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    fresh = torch.load(tmp_path / "s.pt", weights_only=True)
    assert torch.equal(fresh["num_frames"], expected.num_frames) and torch.equal(fresh["latent"], expected.latent)
    assert torch.allclose(fresh["positions"], expected.positions, atol=1e-5)


# -- bad input


def test_too_few_clips_says_how_many_are_needed(ae_ckpt) -> None:
    with pytest.raises(TooFewClipsError, match=r"needs at least 500 training clips.*min_train_clips"):
        feature_module(ae_ckpt, min_train_clips=500)


def test_unknown_primitive_and_missing_autoencoder(ae_ckpt, tmp_path) -> None:
    with pytest.raises(ValueError, match="walk_leftStance"):
        parse_primitive("walk_leftstep")
    with pytest.raises(ValueError, match="autoencoder_ckpt"):
        FeatureDataModule(takeset=tiny_takeset())
    with pytest.raises(FileNotFoundError, match="experiment=autoencoder"):
        feature_module(tmp_path / "nope.ckpt")


def _edited_checkpoint(src: Path, dst: Path, **hparams) -> Path:
    ckpt = torch.load(src, weights_only=True)
    ckpt["hyper_parameters"].update(hparams)
    torch.save(ckpt, dst)
    return dst


def test_autoencoder_that_does_not_match_the_data(ae_ckpt, tmp_path, dm) -> None:
    other = _edited_checkpoint(ae_ckpt, tmp_path / "v0.ckpt", representation="stylemotion.frames66/v0")
    with pytest.raises(IncompatibleModelError, match=r"v0\.ckpt.*representation 'stylemotion.frames66/v0'"):
        feature_module(other)
    slow = _edited_checkpoint(ae_ckpt, tmp_path / "fps60.ckpt", fps=60.0)
    with pytest.raises(IncompatibleModelError, match=r"fps: model 60.0, data 30.0"):
        feature_module(slow)
    # a checkpoint of another kind of model
    model = PrimitiveVAE(spec=dm.model_spec())
    torch.save({"state_dict": model.state_dict(), "hyper_parameters": dict(model.hparams)}, tmp_path / "vae.ckpt")
    with pytest.raises(IncompatibleModelError, match="not a MotionAutoencoder checkpoint"):
        feature_module(tmp_path / "vae.ckpt")


def test_model_refuses_an_autoencoder_other_than_its_own(dm) -> None:
    model = PrimitiveVAE(spec=dm.model_spec())
    other = MotionAutoencoder(hidden_units=TINY_HIDDEN)
    with pytest.raises(IncompatibleModelError, match="not the one the model was trained with"):
        model.attach_autoencoder(other)
    model.attach_autoencoder(dm.autoencoder)  # the right one is accepted
    assert model.autoencoder is dm.autoencoder
