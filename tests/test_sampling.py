"""Sampling: features → motions with durations (vectorized = one clip at a time), seeded
``model.sample``, padding, MPJPE over valid frames, the GIF/PNG writers and the benchmark script."""

from __future__ import annotations

import json
import runpy
import sys
from pathlib import Path

import numpy as np
import pytest
import torch
from PIL import Image
from vae_fixtures import feature_module, fit, tiny_autoencoder_ckpt

from stylemotion.models.sampling import decode_features, masked_mpjpe
from stylemotion.models.vae import PrimitiveVAE
from stylemotion.primitives.segmentation import restore_duration
from stylemotion.representation import frames_to_positions
from stylemotion.viz.animation import render_samples

torch.set_num_threads(1)
REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def ae_ckpt(tmp_path_factory) -> Path:
    return tiny_autoencoder_ckpt(tmp_path_factory.mktemp("sampling_ae"))


@pytest.fixture(scope="module")
def model(ae_ckpt) -> PrimitiveVAE:
    dm = feature_module(ae_ckpt)
    torch.manual_seed(0)
    vae = PrimitiveVAE(samples_per_item=2)
    fit(vae, dm, steps=40)
    return vae.eval()


def test_decoding_is_the_per_clip_pipeline_batched(model) -> None:
    torch.manual_seed(1)
    features = torch.rand(7, model.spec["feature_channels"], model.spec["feature_steps"])
    durations = torch.tensor([0.40, 0.55, 0.55, 0.52, 0.7, 0.41, 0.549])
    out = decode_features(model.autoencoder, features, durations, model.timeline_frames, fps=30.0, chunk_size=3)
    expected_frames = [int(round(float(d) * 30)) + 1 for d in durations]
    assert out.num_frames.tolist() == expected_frames
    assert out.positions.shape == (7, max(expected_frames), 21, 3) and out.frames.shape[:2] == out.positions.shape[:2]
    for i in range(7):  # one clip at a time, the obvious way
        normalized = model.autoencoder.decode(features[i:i + 1], model.timeline_frames)[0]
        frames = restore_duration(normalized.numpy(), float(durations[i]), 30.0)
        positions = frames_to_positions(torch.from_numpy(frames), 30.0)
        n = expected_frames[i]
        assert torch.allclose(out.normalized_frames[i], normalized, atol=1e-5)
        assert torch.allclose(out.frames[i, :n], torch.from_numpy(frames), atol=1e-5)
        assert torch.allclose(out.motion(i), positions, atol=1e-4)
        assert torch.equal(out.positions[i, n:], out.positions[i, n - 1].expand_as(out.positions[i, n:]))
    assert out.mask.sum(1).tolist() == expected_frames
    with pytest.raises(ValueError, match="one duration per sample"):
        decode_features(model.autoencoder, features, durations[:3], model.timeline_frames, 30.0)


def test_sample_is_seeded_and_has_durations(model) -> None:
    state = torch.get_rng_state()
    a, b, c = model.sample(64, seed=3), model.sample(64, seed=3), model.sample(64, seed=4)
    assert torch.equal(torch.get_rng_state(), state)  # the global generator is left alone
    assert torch.equal(a.positions, b.positions) and torch.equal(a.latent, b.latent)
    assert not torch.equal(a.latent, c.latent)
    assert a.latent.shape == (64, 32) and a.frames.shape[-1] == 66 and a.positions.shape[-2:] == (21, 3)
    assert a.features.shape == (64, model.spec["feature_channels"], model.spec["feature_steps"])
    assert a.positions[:, 0, 0, [0, 2]].abs().max() < 1e-3  # the root starts above the origin (1 mm)
    lo, hi = model.hparams.duration_range
    shortest, longest = model.duration_stats[2].item(), model.duration_stats[3].item()
    assert (a.duration_s >= shortest * lo - 1e-6).all() and (a.duration_s <= longest * hi + 1e-6).all()
    assert a.duration_s.std() > 0 and torch.equal(a.num_frames, torch.round(a.duration_s.double() * 30).long() + 1)
    heights = a.positions[..., 1]
    assert 1.2 < heights.amax(-1).median() < 2.0  # standing figures, metres


def test_masked_mpjpe_ignores_padding() -> None:
    pred = torch.zeros(2, 5, 21, 3)
    true = torch.zeros(2, 4, 21, 3)
    true[0, :3, :, 0] = 0.03  # 3 valid frames off by 3 cm
    true[1, :, :, 0] = 0.01
    pred[0, 3:] = 100.0  # padding of sample 0: must not count
    err = masked_mpjpe(pred, true, torch.tensor([3, 4]))
    assert abs(err.item() - (3 * 0.03 + 4 * 0.01) / 7) < 1e-7


def test_gif_and_last_frame_sheet(model, tmp_path) -> None:
    samples = model.sample(16, seed=0)
    gif, png = render_samples(samples, tmp_path / "out", title="test · seed 0")
    with Image.open(gif) as image:
        assert image.size[0] > 600
        durations = []
        for index in range(image.n_frames):
            image.seek(index)
            durations.append(image.info["duration"])
    # real time at 25 fps (40 ms frames), then the last poses held 0.4 s (Pillow merges identical frames)
    longest_ms = (int(samples.num_frames.max()) - 1) / 30 * 1000
    assert set(durations[:-1]) == {40} and durations[-1] >= 400
    assert longest_ms + 400 <= sum(durations) <= longest_ms + 400 + 80
    with Image.open(png) as image:
        assert image.size[0] > 800 and image.size[1] > 600
    assert not list((tmp_path / "out").glob(".*tmp*"))  # written atomically


def test_benchmark_script_prints_json(model, tmp_path, capsys, monkeypatch) -> None:
    ckpt = tmp_path / "vae.ckpt"
    torch.save({"state_dict": model.state_dict(), "hyper_parameters": dict(model.hparams),
                "pytorch-lightning_version": "2.6.6"}, ckpt)
    script = str(REPO / "scripts" / "bench_sampling.py")
    monkeypatch.setattr(sys, "argv", [script, "--ckpt", str(ckpt), "-n", "500", "--repeats", "1"])
    capsys.readouterr()
    with pytest.raises(SystemExit) as done:  # the script as `python scripts/bench_sampling.py ...` runs it
        runpy.run_path(script, run_name="__main__")
    out = capsys.readouterr()
    assert done.value.code == 0, out.err[-3000:]
    result = json.loads(out.out.strip().splitlines()[-1])
    assert result["samples"] == 500 and result["seconds"] > 0 and result["samples_per_s"] > 0
    assert result["positions_shape"][0] == 500 and np.isfinite(result["mean_duration_s"])
