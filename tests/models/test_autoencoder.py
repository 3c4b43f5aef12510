"""The convolutional motion autoencoder, its window DataModule and its Lightning module.

Toy takes (a stick figure walking and swinging its limbs, built here) keep these tests free of
any dataset; the training tests fit a real Lightning Trainer for a few steps.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import lightning.pytorch as pl
import numpy as np
import pytest
import torch
import torch.nn.functional as F
from torch.utils.data import DataLoader

from stylemotion.datamodules import (
    REPRESENTATION,
    EmptySplitError,
    MotionWindowDataModule,
    WindowDataset,
    channel_stats,
    window_starts,
)
from stylemotion.datasets import Take, TakeSet
from stylemotion.models import (
    ConvAutoencoder,
    IncompatibleModelError,
    MotionAutoencoder,
    NonFiniteLossError,
    mpjpe,
)
from stylemotion.representation import frames_to_positions
from stylemotion.skeleton import CANONICAL_JOINTS

torch.set_num_threads(1)

# A rest pose of the canonical joints (metres, Y up, facing +Z; +X is the body's left).
_REST_LEFT = {
    "Hips": (0.0, 0.95, 0.0), "Spine": (0.0, 1.05, 0.0), "Chest": (0.0, 1.25, 0.0), "Neck": (0.0, 1.45, 0.0),
    "Head": (0.0, 1.6, 0.02), "Shoulder_L": (0.05, 1.4, 0.0), "UpperArm_L": (0.18, 1.4, 0.0),
    "LowerArm_L": (0.2, 1.12, 0.0), "Hand_L": (0.21, 0.88, 0.02), "UpperLeg_L": (0.1, 0.92, 0.0),
    "LowerLeg_L": (0.1, 0.5, 0.02), "Foot_L": (0.1, 0.08, 0.0), "Toes_L": (0.1, 0.02, 0.12),
}
REST = np.array([_REST_LEFT[j] if j in _REST_LEFT else
                 np.multiply(_REST_LEFT[j.replace("_R", "_L")], (-1, 1, 1)) for j in CANONICAL_JOINTS])
SWING = np.array([0.3 if j.startswith(("Hand", "LowerArm", "Foot", "Toes", "LowerLeg")) else 0.05
                  for j in CANONICAL_JOINTS]) * np.array([1 if j.endswith("_L") else -1 for j in CANONICAL_JOINTS])


def toy_take(name: str, frames: int, seed: int, fps: float = 30.0, **labels: str) -> Take:
    """A stick figure walking forward while turning slowly, limbs swinging; ``(frames, 21, 3)``."""
    rng = np.random.default_rng(seed)
    t = np.arange(frames) / fps
    speed, turn, freq, phase = rng.uniform(0.8, 1.6), rng.uniform(-0.4, 0.4), rng.uniform(0.8, 1.2), rng.uniform(0, 6)
    yaw = rng.uniform(-np.pi, np.pi) + turn * t
    root = np.cumsum(np.stack([np.sin(yaw), np.cos(yaw)], -1) * speed / fps, axis=0)
    swing = np.sin(2 * np.pi * freq * t + phase)
    local = np.repeat(REST[None], frames, 0)
    local[:, :, 2] += swing[:, None] * SWING[None]
    local[:, :, 1] += 0.02 * np.abs(swing)[:, None]
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    pos = np.stack([c * local[..., 0] + s * local[..., 2] + root[:, None, 0], local[..., 1],
                    -s * local[..., 0] + c * local[..., 2] + root[:, None, 1]], axis=-1)
    return Take(name, pos.astype(np.float32), fps, {"content": "walk", "style": "toy", "take": name, **labels})


def toy_takeset(takes: int = 9, frames: int = 120, fps: float = 30.0, groups: int = 1) -> TakeSet:
    items = [toy_take(f"t{g}_{i:02d}", frames + 7 * i, seed=100 * g + i, fps=fps, style=f"s{g}")
             for g in range(groups) for i in range(takes)]
    return TakeSet("toy", items, fps)


def fit(model: pl.LightningModule, dm: pl.LightningDataModule | None = None, steps: int = 5,
        train_dataloaders=None, **kw) -> pl.Trainer:
    """Fit ``model`` for ``steps`` optimizer steps on the CPU, without logger or checkpoints."""
    trainer = pl.Trainer(accelerator="cpu", max_steps=steps, logger=False, enable_checkpointing=False,
                         enable_progress_bar=False, enable_model_summary=False, num_sanity_val_steps=0,
                         log_every_n_steps=1, **kw)
    trainer.fit(model, datamodule=dm, train_dataloaders=train_dataloaders)
    return trainer


# --------------------------------------------------------------------------- network

def test_architecture_matches_eq_5_1_and_5_2():
    net = ConvAutoencoder()
    assert net.encoder.weight.shape == (256, 66, 15) and net.decoder.weight.shape == (66, 256, 15)
    x = torch.randn(3, 60, 66)
    features = net.encode(x)  # identity normalization
    hidden = F.relu(F.conv1d(x.transpose(1, 2), net.encoder.weight, net.encoder.bias, padding=7))
    torch.testing.assert_close(features, hidden.reshape(3, 256, 30, 2).mean(-1))
    recon = net.decode(features)
    depooled = features.repeat_interleave(2, -1)
    expected = F.conv1d(depooled, net.decoder.weight, net.decoder.bias, padding=7).transpose(1, 2)
    torch.testing.assert_close(recon, expected)


@pytest.mark.filterwarnings("ignore:Using padding='same' with even kernel")
@pytest.mark.parametrize("kernel_size", [9, 14, 25])
@pytest.mark.parametrize("pooling", ["avg", "max"])
def test_shapes_odd_lengths_and_unbatched(kernel_size, pooling):
    net = ConvAutoencoder(hidden_units=16, kernel_size=kernel_size, pooling=pooling)
    for frames in (60, 61, 1):
        x = torch.randn(2, frames, 66)
        features = net.encode(x)
        assert features.shape == (2, 16, (frames + 1) // 2)
        assert net.decode(features, frames).shape == (2, frames, 66)
        assert net(x).shape == x.shape
        torch.testing.assert_close(net.encode(x[0]), features[0])
        torch.testing.assert_close(net.decode(features[1], frames), net(x)[1])
    # An odd length pools its last hidden step alone: appending a copy of it changes nothing.
    x = torch.randn(1, 7, 66)
    hidden_last = net.encode(x)[..., -1]
    assert hidden_last.shape == (1, 16)
    with pytest.raises(ValueError, match=r"\(batch, time, 66\)"):
        net.encode(torch.randn(2, 60, 65))
    with pytest.raises(ValueError, match="features must be"):
        net.decode(torch.randn(2, 17, 30))


def test_bad_options_are_rejected():
    with pytest.raises(ValueError, match="pooling"):
        ConvAutoencoder(pooling="median")
    with pytest.raises(ValueError, match="kernel_size"):
        ConvAutoencoder(kernel_size=0)
    with pytest.raises(ValueError, match="input_dropout"):
        ConvAutoencoder(input_dropout=1.0)
    with pytest.raises(ValueError, match="lr"):
        MotionAutoencoder(lr=-1.0)


def test_encode_decode_work_on_raw_frames():
    net = ConvAutoencoder(hidden_units=8)
    mean, std = torch.linspace(-1, 1, 66), torch.linspace(0.5, 2, 66)
    net.normalizer.set_stats(mean, std)
    x = torch.randn(2, 20, 66) * std + mean
    torch.testing.assert_close(net.encode(x), net.encode_normalized((x - mean) / std))
    features = net.encode(x)
    torch.testing.assert_close(net.decode(features), net.decode_normalized(features) * std + mean)


def test_input_dropout_only_while_training():
    net = ConvAutoencoder(hidden_units=8, input_dropout=0.5)
    z = torch.ones(4, 10, 66)
    net.train()
    assert (net.corrupt(z) == 0).float().mean() > 0.3
    net.eval()
    torch.testing.assert_close(net.corrupt(z), z)
    torch.testing.assert_close(net.encode(z), net.encode(z))


# --------------------------------------------------------------------------- metric

def test_mpjpe_is_metres_over_all_joints_and_counts_root_drift():
    frames = torch.as_tensor(toy_take("a", 40, 0).frames)
    frames[:, 65] = 0.0  # no turning, so that a velocity offset drifts along a straight line
    assert mpjpe(frames, frames, 30.0) < 1e-6
    moved = frames.clone()
    moved[:, 3 * 4] += 0.21  # the Head 21 cm to the side in every frame
    torch.testing.assert_close(mpjpe(moved, frames, 30.0), torch.tensor(0.01), atol=1e-5, rtol=0)
    faster = frames.clone()
    faster[:, 64] += 0.3  # 0.3 m/s more forward speed: the whole body drifts, 0.3 m/s × t
    t = torch.arange(40) / 30.0
    torch.testing.assert_close(mpjpe(faster, frames, 30.0), (0.3 * t).mean(), atol=1e-4, rtol=0)
    positions = frames_to_positions(frames, 30.0)
    assert positions.shape == (40, 21, 3)


# --------------------------------------------------------------------------- data

def test_window_starts():
    assert window_starts(59, 60, 30) == []
    assert window_starts(60, 60, 30) == [0]
    assert window_starts(120, 60, 30) == [0, 30, 60]
    assert window_starts(130, 60, 30) == [0, 30, 60, 70]
    assert window_starts(130, 60, 30, cover_tail=False) == [0, 30, 60]


def test_datamodule_split_by_take_stats_from_train_only():
    takeset = toy_takeset(takes=10, groups=2)
    dm = MotionWindowDataModule(takeset=takeset, batch_size=4, split={"seed": 3, "val_fraction": 0.2,
                                                                       "test_fraction": 0.2})
    dm.setup("fit")
    names = {k: {t.name for t in dm.split_takes[k]} for k in ("train", "val", "test")}
    assert names["train"].isdisjoint(names["val"]) and names["train"].isdisjoint(names["test"])
    assert sum(len(v) for v in names.values()) == 20 and len(names["val"]) == 4
    train = dm.datasets["train"]
    assert set(train.take_names) == names["train"]
    expected = sum(len(window_starts(t.num_frames, 60, 30)) for t in dm.split_takes["train"])
    assert len(train) == expected
    batch = next(iter(dm.train_dataloader()))
    assert batch.shape == (4, 60, 66) and batch.dtype == torch.float32
    mean, std = dm.normalization
    ref_mean, ref_std = channel_stats([t.frames for t in dm.split_takes["train"]])
    np.testing.assert_allclose(mean, ref_mean, atol=1e-5)
    np.testing.assert_allclose(std, ref_std, rtol=1e-4)
    all_mean, _ = channel_stats([t.frames for t in takeset.takes])
    assert not np.allclose(mean, all_mean, atol=1e-5)  # val/test frames are not used
    assert std[0] == pytest.approx(1e-3)  # the Hips' x is 0 by construction: floored std
    # the window holds the take's frames unchanged
    first = dm.split_takes["train"][0]
    torch.testing.assert_close(train[0], torch.as_tensor(first.frames[:60]))


def test_empty_split_is_a_clear_error():
    dm = MotionWindowDataModule(takeset=toy_takeset(takes=2), batch_size=4)
    with pytest.raises(EmptySplitError, match=r"'val' split of dataset 'toy'.*0 of the dataset's 2 takes"):
        dm.setup("fit")
    short = MotionWindowDataModule(takeset=toy_takeset(takes=6, frames=20), batch_size=4)
    with pytest.raises(EmptySplitError, match=r"'train' split.*shorter than one window"):
        short.setup("fit")
    no_test = MotionWindowDataModule(takeset=toy_takeset(takes=6), split={"test_fraction": 0.0})
    no_test.setup("fit")  # only train and val are needed to fit
    with pytest.raises(EmptySplitError, match="'test' split"):
        no_test.setup("test")


def test_non_finite_take_is_named():
    takes = toy_takeset(takes=3).takes
    takes[1].frames[5, 7] = np.nan
    with pytest.raises(ValueError, match=f"take '{takes[1].name}'.*non-finite"):
        WindowDataset(takes, 60, 30)


# --------------------------------------------------------------------------- training

def test_training_reduces_reconstruction_error():
    pl.seed_everything(0)
    dm = MotionWindowDataModule(takeset=toy_takeset(takes=9, groups=2), batch_size=8)
    model = MotionAutoencoder(hidden_units=32, kernel_size=9, lr=3e-3)
    trainer = pl.Trainer(accelerator="cpu", max_steps=1, logger=False, enable_checkpointing=False,
                         enable_progress_bar=False, enable_model_summary=False, limit_train_batches=0)
    before = trainer.test(model, datamodule=dm, verbose=False)[0]
    trainer = fit(model, dm, steps=60)
    logged = set(trainer.logged_metrics)
    assert {"train/loss", "train/mse_step", "train/mpjpe_epoch", "train/mpjpe_local_epoch", "val/mse", "val/mpjpe",
            "val/mpjpe_local"} <= logged
    after = trainer.test(model, datamodule=dm, verbose=False)[0]
    # test/contact: the reconstruction's planted-foot speed² on contact frames (models/contact_loss.py), logged
    # in evaluation whatever the contact weight
    assert set(after) == {"test/mse", "test/mpjpe", "test/mpjpe_local", "test/contact"}
    for key in ("test/mse", "test/mpjpe", "test/mpjpe_local"):
        assert after[key] < 0.5 * before[key], key
    assert model.net.normalizer.initialized
    np.testing.assert_allclose(model.net.normalizer.mean.numpy(), dm.normalization[0])


def test_sparsity_adds_l1_of_hidden_units_to_the_loss():
    dm = MotionWindowDataModule(takeset=toy_takeset(takes=6), batch_size=8)
    model = MotionAutoencoder(hidden_units=16, sparsity=10.0)
    trainer = fit(model, dm, steps=1)
    logged = trainer.logged_metrics
    assert logged["train/loss"] > logged["train/mse_step"] + 1e-3


def test_learning_rate_decays_per_epoch():
    dm = MotionWindowDataModule(takeset=toy_takeset(takes=6), batch_size=64)  # one batch per epoch
    model = MotionAutoencoder(hidden_units=8, lr=1e-2, lr_gamma=0.5)
    trainer = fit(model, dm, steps=3)
    assert trainer.optimizers[0].param_groups[0]["lr"] == pytest.approx(1e-2 * 0.5**3)
    with pytest.raises(ValueError, match="lr_gamma"):
        MotionAutoencoder(lr_gamma=0.0)


def test_cosine_schedule_warms_up_then_falls_to_its_final_share_at_the_last_step():
    from stylemotion.models.autoencoder import cosine_factor

    total, warmup, final = 100, 10, 0.01
    factors = [cosine_factor(step, total, warmup, final) for step in range(total)]
    assert factors[0] == pytest.approx(0.1) and factors[9] == pytest.approx(1.0)
    assert factors[10] == pytest.approx(1.0) and factors[-1] == pytest.approx(final)
    # the cosine's midpoint halfway between warm-up end and the last step
    assert cosine_factor(10 + 89 // 2, total, warmup, final) == pytest.approx(final + (1 - final) * 0.5, abs=0.02)
    assert all(a >= b for a, b in zip(factors[9:], factors[10:]))


def test_cosine_schedule_steps_per_batch_over_the_trainers_epochs():
    dm = MotionWindowDataModule(takeset=toy_takeset(takes=6), batch_size=64)  # one batch per epoch
    model = MotionAutoencoder(hidden_units=8, lr=1e-2, lr_schedule="cosine", warmup_epochs=1, lr_final=0.1)
    trainer = fit(model, dm, steps=4, max_epochs=4)  # 4 epochs of one step: warm-up 1 step, cosine over the other 3
    assert trainer.optimizers[0].param_groups[0]["lr"] == pytest.approx(1e-2 * 0.1)
    with pytest.raises(ValueError, match="lr_schedule"):
        MotionAutoencoder(lr_schedule="linear")


def test_root_weight_weighs_the_root_channels_and_keeps_the_scale():
    from stylemotion.models.autoencoder import weighted_mse
    from stylemotion.representation import VELOCITY_DIMS, YAW_RATE_DIM

    target = torch.zeros(2, 4, 66)
    recon = target.clone()
    recon[..., 0] = 1.0  # a joint channel off by 1
    assert weighted_mse(recon, target, 1.0) == pytest.approx(1 / 66)
    assert weighted_mse(recon, target, 5.0) == pytest.approx(1 / (63 + 3 * 5))  # 1 / sum of weights
    root = target.clone()
    root[..., VELOCITY_DIMS.start] = 1.0
    root[..., YAW_RATE_DIM] = 1.0
    assert weighted_mse(root, target, 5.0) == pytest.approx(10 / (63 + 15))
    with pytest.raises(ValueError, match="root_weight"):
        MotionAutoencoder(root_weight=0.0)


def test_nan_loss_stops_naming_the_batch():
    takes = toy_takeset(takes=3).takes
    windows = torch.stack([torch.as_tensor(t.frames[:60]) for t in takes for _ in range(4)])  # 12 windows
    windows[9, 10, 3] = float("nan")  # batch 2 of size 4
    model = MotionAutoencoder(hidden_units=8)
    model.net.normalizer.set_stats(*channel_stats([w.numpy() for w in windows[:8]]))
    trainer = pl.Trainer(accelerator="cpu", max_epochs=1, logger=False, enable_checkpointing=False,
                         enable_progress_bar=False, enable_model_summary=False)
    with pytest.raises(NonFiniteLossError, match=r"training loss is nan at epoch 0, batch 2 "):
        trainer.fit(model, train_dataloaders=DataLoader(windows, batch_size=4, shuffle=False))


def test_missing_normalization_is_a_clear_error():
    loader = DataLoader(torch.randn(8, 60, 66), batch_size=4)
    with pytest.raises(RuntimeError, match="no normalization statistics"):
        fit(MotionAutoencoder(hidden_units=8), steps=1, train_dataloaders=loader)


def test_data_with_another_fps_is_rejected():
    dm = MotionWindowDataModule(takeset=toy_takeset(takes=6, fps=60.0), batch_size=8)
    with pytest.raises(IncompatibleModelError, match="fps: model 30.0, data 60.0"):
        fit(MotionAutoencoder(hidden_units=8, fps=30.0), dm, steps=1)


# --------------------------------------------------------------------------- checkpoints

@pytest.fixture(scope="module")
def trained_checkpoint(tmp_path_factory):
    """A checkpoint of a tiny autoencoder trained for a few steps, and its encoding of fixed frames."""
    root = tmp_path_factory.mktemp("ckpt")
    pl.seed_everything(1)
    dm = MotionWindowDataModule(takeset=toy_takeset(takes=6), batch_size=8)
    model = MotionAutoencoder(hidden_units=16, kernel_size=5, pooling="max", fps=30.0)
    trainer = fit(model, dm, steps=3)
    path = root / "model.ckpt"
    trainer.save_checkpoint(path)
    frames = torch.as_tensor(toy_take("probe", 61, 99).frames)
    torch.save({"frames": frames, "features": model.encode(frames[None]).detach(),
                "recon": model(frames[None]).detach()}, root / "probe.pt")
    return path, root / "probe.pt"


def test_checkpoint_loads_in_a_fresh_process_with_weights_only(trained_checkpoint):
    path, probe = trained_checkpoint
    script = textwrap.dedent(f"""
        import torch
        from stylemotion.models import MotionAutoencoder
        raw = torch.load({str(path)!r}, weights_only=True)   # plain values only
        model = MotionAutoencoder.load_from_checkpoint({str(path)!r})
        model.eval()
        probe = torch.load({str(probe)!r}, weights_only=True)
        assert model.hparams.pooling == "max" and model.hparams.kernel_size == 5
        assert model.net.normalizer.initialized
        torch.testing.assert_close(model.encode(probe["frames"][None]), probe["features"])
        torch.testing.assert_close(model(probe["frames"][None]), probe["recon"])
        print("OK", type(raw["hyper_parameters"]).__name__)
    """)
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "OK dict" in done.stdout


def _edited_checkpoint(src, dst, **hparams):
    ckpt = torch.load(src, weights_only=True)
    ckpt["hyper_parameters"].update(hparams)
    torch.save(ckpt, dst)
    return dst


def test_checkpoint_of_another_representation_or_skeleton_is_rejected(trained_checkpoint, tmp_path):
    path, _ = trained_checkpoint
    other = _edited_checkpoint(path, tmp_path / "other.ckpt", representation="someone.frames72/v3",
                               frame_dim=72)
    with pytest.raises(IncompatibleModelError, match=r"'someone.frames72/v3'.*this code computes '"
                                                      + REPRESENTATION.replace(".", r"\.") + "'"):
        MotionAutoencoder.load_from_checkpoint(other)
    joints = list(CANONICAL_JOINTS)
    joints[5] = "LeftCollar"
    skel = _edited_checkpoint(path, tmp_path / "skel.ckpt", joint_names=joints)
    with pytest.raises(IncompatibleModelError, match="LeftCollar"):
        MotionAutoencoder.load_from_checkpoint(skel)
    model = MotionAutoencoder.load_from_checkpoint(path)
    with pytest.raises(IncompatibleModelError, match=r"fps: model 30.0, data 60"):
        model.check_compatible(fps=60, frame_dim=66)
    model.check_compatible(fps=30, frame_dim=66, representation=REPRESENTATION, joint_names=CANONICAL_JOINTS)


def test_resuming_into_a_different_architecture_is_rejected(trained_checkpoint):
    path, _ = trained_checkpoint
    dm = MotionWindowDataModule(takeset=toy_takeset(takes=6), batch_size=8)
    model = MotionAutoencoder(hidden_units=16, kernel_size=9, pooling="max")
    trainer = pl.Trainer(accelerator="cpu", max_steps=5, logger=False, enable_checkpointing=False,
                         enable_progress_bar=False, enable_model_summary=False)
    with pytest.raises(IncompatibleModelError, match="kernel_size: checkpoint 5, model 9"):
        trainer.fit(model, datamodule=dm, ckpt_path=str(path))
