"""Sampling into MotionSamples, save/load without pickle, held-out reconstruction."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from stylemotion.evaluation.tables import variance_stats
from stylemotion.models.sampling import MotionSamples
from stylemotion.morphable import MorphableModel
from stylemotion.morphable.model import reconstruction_error


def test_sample_has_the_vae_structure(left_model, left_clips):
    s = left_model.sample(12, seed=3)
    assert isinstance(s, MotionSamples) and len(s) == 12
    width = s.positions.shape[1]
    assert s.positions.shape == (12, width, 21, 3) and s.frames.shape == (12, width, 66)
    assert int(s.num_frames.max()) == width and s.num_frames.dtype == torch.int64
    np.testing.assert_allclose(s.duration_s.numpy(), (s.num_frames.numpy() - 1) / 30.0, rtol=1e-6)
    assert s.normalized_frames.shape == (12, left_model.length, 66) and s.latent.shape == (12, 6)
    assert s.features.shape[0] == 12 and s.fps == 30.0
    assert torch.isfinite(s.positions).all() and torch.isfinite(s.frames).all()
    real = np.array([c.num_frames for c in left_clips["train"]])
    assert real.min() - 2 <= int(s.num_frames.min()) and int(s.num_frames.max()) <= real.max() + 2
    # the root starts near the origin; the body stands (head above hips above the feet)
    assert float(s.positions[:, 0, 0, [0, 2]].abs().max()) < 0.1
    assert bool((s.positions[:, :, 4, 1] > s.positions[:, :, 0, 1]).all())
    assert torch.equal(left_model.sample(12, seed=3).positions, s.positions)
    assert not torch.equal(left_model.sample(12, seed=4).positions, s.positions)
    stats = variance_stats(s.frames.numpy(), s.positions.numpy(), s.num_frames.numpy(), s.normalized_frames.numpy())
    assert all(np.isfinite(v) and v >= 0 for v in stats.values())  # Tables 5.2/5.3 apply unchanged


def test_save_load_round_trip_without_pickle(left_model, tmp_path):
    path = left_model.save(tmp_path / "model.npz")
    with np.load(path, allow_pickle=False) as z:
        assert {"meta_json", "pca_components", "gmm_means", "tree_latent", "offsets"} <= set(z.files)
    loaded = MorphableModel.load(tmp_path)  # a run folder holding model.npz works too
    assert loaded.meta["primitive"] == "leftStance"
    assert torch.equal(loaded.sample(8, seed=0).positions, left_model.sample(8, seed=0).positions)
    assert np.array_equal(loaded.tree.children, left_model.tree.children)
    (tmp_path / "model.npz").rename(tmp_path / "other.npz")
    with pytest.raises(FileNotFoundError, match="no morphable model"):
        MorphableModel.load(tmp_path)
    np.savez(tmp_path / "bad.npz", x=np.zeros(3))
    with pytest.raises(ValueError, match="not a morphable model"):
        MorphableModel.load(tmp_path / "bad.npz")
    with pytest.raises(ValueError, match="ends in .npz"):
        left_model.save(tmp_path / "model.pkl")


def test_held_out_clips_reconstruct(left_model, left_clips):
    train = reconstruction_error(left_model, left_clips["train"])
    test = reconstruction_error(left_model, left_clips["test"])
    assert 0 < train < 0.05 and 0 < test < 0.08


def test_the_frames_representation_samples_too(left_clips):
    from stylemotion.morphable import FitSettings, fit_primitive

    model = fit_primitive(left_clips["train"], FitSettings(representation="frames", latent_dim=4,
                                                           reduction="normalized", num_coefficients=6))
    s = model.sample(5, seed=0)
    assert s.frames.shape[-1] == 66 and torch.isfinite(s.positions).all()
    # frames are the channels themselves: the positions are their integration
    first = s.motion(0).numpy()
    assert np.linalg.norm(first[-1, 0, [0, 2]] - first[0, 0, [0, 2]]) > 0.3  # it walks forward a step
    with pytest.raises(ValueError, match="orientations need the quaternion representation"):
        model.canonical_positions(s.latent.numpy(), rotations=True)


def test_a_model_names_its_primitive_and_the_style_of_its_clips(left_model, left_clips):
    from dataclasses import replace

    from stylemotion.morphable import FitSettings, fit_primitive

    assert left_model.primitive_name == "walk_leftStance" and left_model.style_name == "normal"
    clips = list(left_clips["train"])
    mixed = [replace(c, style="elderly") if i % 2 else c for i, c in enumerate(clips)]  # two styles
    model = fit_primitive(mixed, FitSettings(latent_dim=4, reduction="fpca", num_coefficients=6))
    assert model.meta["style"] == "all" and model.style_name == "all"
