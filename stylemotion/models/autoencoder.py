"""The convolutional motion autoencoder: the motion manifold of thesis §5.3.1 (eq. 5.1–5.2).

After Holden et al. 2016, one 1D convolution over time:

* encoder ``Φ(X) = Ψ(ReLU(X * W + b))``: Conv1d(66 → 256, kernel 15, same padding), ReLU,
  pooling ×2 over time (average by default, max as an option);
* decoder ``Φ'(Y)``: depooling ×2 (each feature step repeated twice), Conv1d(256 → 66, kernel 15).

:class:`ConvAutoencoder` is the plain network (with its normalization buffers);
:class:`MotionAutoencoder` is the Lightning module that trains it by reconstruction: MSE in the
normalized space, optionally with input dropout (denoising), an L1 penalty on the hidden units and
the foot-contact velocity loss (:mod:`stylemotion.models.contact_loss`, ``contact_weight``), and logs
MPJPE in metres on positions recovered through the inverse representation.

Shapes (``T`` frames at the model's fps, ``H`` hidden units):

* ``encode(frames)``: ``(batch, T, 66)`` raw frames → ``(batch, H, ceil(T / 2))`` features;
* ``decode(features, num_frames)``: ``(batch, H, T')`` → ``(batch, 2 T', 66)`` raw frames, cut to
  ``num_frames`` when given (an odd ``T`` pools its last frame alone and is cut back on decode).

Unbatched ``(T, 66)`` / ``(H, T')`` inputs work too. The Gram matrices of §5.3.3 are taken on
``encode`` output, so ``encode``/``decode`` are the stable API of this module.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import partial
from typing import Any

import lightning.pytorch as pl
import torch
import torch.nn.functional as F
from torch import nn

from stylemotion.io.errors import UserInputError
from stylemotion.models.contact_loss import contact_velocity_loss, window_contacts
from stylemotion.models.normalization import Normalizer
from stylemotion.representation import (
    FRAME_DIM,
    JOINT_DIMS,
    REPRESENTATION,
    VELOCITY_DIMS,
    YAW_RATE_DIM,
    frames_to_positions,
)
from stylemotion.skeleton import CANONICAL_JOINTS, CANONICAL_PARENTS, NUM_JOINTS

POOLING = ("avg", "max")


class IncompatibleModelError(UserInputError, ValueError):
    """A model (or checkpoint) does not fit the data or code it is used with."""


class NonFiniteLossError(FloatingPointError):
    """The training loss became NaN or infinite."""


class ConvAutoencoder(nn.Module):
    """Single-layer convolutional autoencoder over time, working on raw (un-normalized) frames.

    Args:
        frame_dim: values per frame (66).
        hidden_units: convolution kernels, i.e. feature channels ``H`` (256 in the thesis).
        kernel_size: temporal width of both convolutions, frames (15 = a quarter of 60 frames).
        pooling: ``"avg"`` (thesis) or ``"max"``; depooling always repeats each step twice.
        input_dropout: probability of zeroing a normalized input value while training
            (:meth:`corrupt`); 0 disables it.
    """

    def __init__(self, frame_dim: int = FRAME_DIM, hidden_units: int = 256, kernel_size: int = 15,
                 pooling: str = "avg", input_dropout: float = 0.0):
        super().__init__()
        if pooling not in POOLING:
            raise ValueError(f"pooling must be one of {POOLING}, got {pooling!r}")
        for name, value in (("frame_dim", frame_dim), ("hidden_units", hidden_units),
                            ("kernel_size", kernel_size)):
            if not isinstance(value, int) or isinstance(value, bool) or value < 1:
                raise ValueError(f"{name} must be a positive integer, got {value!r}")
        if not 0.0 <= input_dropout < 1.0:
            raise ValueError(f"input_dropout must be in [0, 1), got {input_dropout!r}")
        self.frame_dim, self.hidden_units, self.pooling = frame_dim, hidden_units, pooling
        self.normalizer = Normalizer(frame_dim)
        self.encoder = nn.Conv1d(frame_dim, hidden_units, kernel_size, padding="same")
        self.decoder = nn.Conv1d(hidden_units, frame_dim, kernel_size, padding="same")
        self.dropout = nn.Dropout(input_dropout)

    # -- normalized space: (batch, T, frame_dim) z-scores
    def encode_normalized(self, z: torch.Tensor) -> torch.Tensor:
        """``(batch, T, frame_dim)`` z-scores → ``(batch, H, ceil(T/2))`` features."""
        hidden = F.relu(self.encoder(z.transpose(-1, -2)))
        if hidden.shape[-1] % 2:
            hidden = F.pad(hidden, (0, 1), mode="replicate")
        pool = F.avg_pool1d if self.pooling == "avg" else F.max_pool1d
        return pool(hidden, 2)

    def decode_normalized(self, features: torch.Tensor, num_frames: int | None = None) -> torch.Tensor:
        """``(batch, H, T')`` features → ``(batch, min(2T', num_frames), frame_dim)`` z-scores."""
        out = self.decoder(features.repeat_interleave(2, dim=-1)).transpose(-1, -2)
        return out if num_frames is None else out[..., :num_frames, :]

    def corrupt(self, z: torch.Tensor) -> torch.Tensor:
        """Input dropout on z-scores (identity in eval mode or with ``input_dropout == 0``)."""
        return self.dropout(z)

    # -- raw frames
    def encode(self, frames: torch.Tensor) -> torch.Tensor:
        """``(batch, T, frame_dim)`` or ``(T, frame_dim)`` raw frames → ``(batch, H, ceil(T/2))``."""
        self._check_frames(frames)
        z = self.normalizer.normalize(frames)
        return _unbatched(self.encode_normalized, z, frames.dim() == 2)

    def decode(self, features: torch.Tensor, num_frames: int | None = None) -> torch.Tensor:
        """``(batch, H, T')`` or ``(H, T')`` features → raw frames ``(batch, T, frame_dim)``.

        ``T = 2 T'``, or ``num_frames`` when given (e.g. the odd length that was encoded).
        """
        if features.shape[-2] != self.hidden_units:
            raise ValueError(f"features must be (batch, {self.hidden_units}, time), got {tuple(features.shape)}")
        z = _unbatched(lambda f: self.decode_normalized(f, num_frames), features, features.dim() == 2)
        return self.normalizer.denormalize(z)

    def forward(self, frames: torch.Tensor) -> torch.Tensor:
        """Reconstruction of raw ``frames`` ``(batch, T, frame_dim)``, same shape."""
        return self.decode(self.encode(frames), frames.shape[-2])

    def _check_frames(self, frames: torch.Tensor) -> None:
        if frames.dim() not in (2, 3) or frames.shape[-1] != self.frame_dim:
            raise ValueError(f"frames must be (batch, time, {self.frame_dim}) or (time, {self.frame_dim}), "
                             f"got {tuple(frames.shape)}")


#: learning-rate schedules of :class:`MotionAutoencoder`
LR_SCHEDULES = ("exponential", "cosine")


def cosine_factor(step: int, total: int, warmup: int, final: float) -> float:
    """The learning rate's factor at optimizer ``step`` of ``total``: linear from 0 to 1 over ``warmup`` steps,
    then half a cosine from 1 down to ``final`` at the last step (``final`` after it)."""
    if step < warmup:
        return (step + 1) / warmup
    span = max(1, total - warmup - 1)
    progress = min(1.0, (step - warmup) / span)
    return final + (1.0 - final) * 0.5 * (1.0 + math.cos(math.pi * progress))


def weighted_mse(recon: torch.Tensor, target: torch.Tensor, root_weight: float) -> torch.Tensor:
    """MSE of ``(..., T, 66)`` frames with the root velocity and yaw-rate channels weighted ``root_weight``
    (the others 1), divided by the mean weight; ``root_weight`` 1 is :func:`torch.nn.functional.mse_loss`."""
    if root_weight == 1.0:
        return F.mse_loss(recon, target)
    weights = torch.ones(recon.shape[-1], dtype=recon.dtype, device=recon.device)
    weights[VELOCITY_DIMS] = root_weight
    weights[YAW_RATE_DIM] = root_weight
    return ((recon - target).square() * weights).mean() / weights.mean()


def _unbatched(fn, x: torch.Tensor, unbatched: bool) -> torch.Tensor:
    return fn(x.unsqueeze(0)).squeeze(0) if unbatched else fn(x)


def mpjpe(pred_frames: torch.Tensor, true_frames: torch.Tensor, fps: float) -> torch.Tensor:
    """Mean per-joint position error, metres, of two frame sequences ``(..., T, 66)``.

    Both are turned into positions by :func:`stylemotion.representation.frames_to_positions`
    from the same start (origin, facing +Z), so root drift from velocity errors counts; the mean
    runs over all leading dims, frames and the 21 joints.
    """
    pred = frames_to_positions(pred_frames, fps)
    true = frames_to_positions(true_frames, fps)
    return torch.linalg.vector_norm(pred - true, dim=-1).mean()


def local_mpjpe(pred_frames: torch.Tensor, true_frames: torch.Tensor) -> torch.Tensor:
    """Mean per-joint position error, metres, of the root-local poses of ``(..., T, 66)`` frames.

    Joints relative to the root's ground projection, facing +Z (frame values ``[0:63]``): the pose
    alone, without the root trajectory (so no drift from velocity errors).
    """
    diff = (pred_frames[..., JOINT_DIMS] - true_frames[..., JOINT_DIMS]).contiguous().unflatten(-1, (NUM_JOINTS, 3))
    return torch.linalg.vector_norm(diff, dim=-1).mean()


class MotionAutoencoder(pl.LightningModule):
    """Trains a :class:`ConvAutoencoder` by reconstructing windows of raw frames.

    Batches are raw frames ``(batch, T, 66)``. Logged per split (``train``/``val``/``test``):
    ``mse`` (normalized space), ``mpjpe`` (metres, positions integrated from the origin, see
    :func:`mpjpe`), ``mpjpe_local`` (metres, root-local pose only, see :func:`local_mpjpe`), and
    ``train/loss`` (MSE + sparsity term + contact term), and ``contact`` (m²/s²: the reconstruction's
    squared planted-foot speed on the input's contact foot-frames,
    :func:`~stylemotion.models.contact_loss.contact_velocity_loss`; on val/test always, on train when
    ``contact_weight`` > 0).

    The normalization statistics are taken from the datamodule's train split at the first
    ``setup`` (``datamodule.normalization``) unless already set (e.g. loaded from a checkpoint).

    Args:
        hidden_units, kernel_size, pooling, input_dropout: see :class:`ConvAutoencoder`.
        sparsity: weight of the L1 penalty ``mean(|features|)`` on the hidden units (0 = off).
        contact_weight: weight of the foot-contact velocity loss (m²/s², see
            :mod:`stylemotion.models.contact_loss`; 0 = off): contacts detected on each input window.
        lr: Adam learning rate. weight_decay: Adam's L2 weight decay.
        lr_gamma: with ``lr_schedule="exponential"``, the learning rate is multiplied by this after every
            epoch (1 = constant).
        lr_schedule: ``exponential`` (per epoch, ``lr_gamma``) or ``cosine``: per step, a linear warm-up over
            ``warmup_epochs`` from 0 to ``lr``, then half a cosine down to ``lr × lr_final`` at the last step
            of ``trainer.max_epochs`` (a schedule that fits the epochs it is given; docs/style.md).
        warmup_epochs, lr_final: the cosine schedule's warm-up length (epochs, may be fractional) and final
            learning rate as a share of ``lr``.
        root_weight: weight of the root's ground velocity and yaw-rate channels in the training MSE, relative to
            the other channels (1 = plain MSE, the thesis'); the loss is divided by the mean weight, so its scale
            stays. Those three channels integrate into the whole trajectory (the root-integrated MPJPE).
        fps: frame rate of the frames the model is trained on (velocities are per second).
        frame_dim: values per frame. representation: frame layout id (see
            :data:`stylemotion.representation.REPRESENTATION`).
        joint_names, joint_parents: the skeleton the frames describe (canonical 21 joints).

    All arguments are plain values and are saved as hyperparameters, so
    ``MotionAutoencoder.load_from_checkpoint(path)`` works under ``torch.load(weights_only=True)``.
    """

    def __init__(
        self,
        hidden_units: int = 256,
        kernel_size: int = 15,
        pooling: str = "avg",
        input_dropout: float = 0.0,
        sparsity: float = 0.0,
        contact_weight: float = 0.0,
        lr: float = 1e-3,
        weight_decay: float = 0.0,
        lr_gamma: float = 1.0,
        lr_schedule: str = "exponential",
        warmup_epochs: float = 0.0,
        lr_final: float = 0.01,
        root_weight: float = 1.0,
        fps: float = 30.0,
        frame_dim: int = FRAME_DIM,
        representation: str = REPRESENTATION,
        joint_names: Sequence[str] = CANONICAL_JOINTS,
        joint_parents: Sequence[int] = CANONICAL_PARENTS,
    ):
        super().__init__()
        if representation != REPRESENTATION or frame_dim != FRAME_DIM:
            raise IncompatibleModelError(
                f"this model was built for frame representation {representation!r} with {frame_dim} values "
                f"per frame, but this code computes {REPRESENTATION!r} with {FRAME_DIM}; retrain it on data "
                "prepared by the current stylemotion.representation"
            )
        if list(joint_names) != list(CANONICAL_JOINTS) or list(joint_parents) != list(CANONICAL_PARENTS):
            raise IncompatibleModelError(
                f"this model was built for a skeleton with joints {list(joint_names)} (parents "
                f"{list(joint_parents)}), not the canonical 21-joint skeleton {list(CANONICAL_JOINTS)}"
            )
        if not contact_weight >= 0:
            raise ValueError(f"contact_weight must be ≥ 0, got {contact_weight}")
        if not sparsity >= 0 or not lr > 0 or not weight_decay >= 0 or not fps > 0 or not 0 < lr_gamma <= 1:
            raise ValueError(f"need sparsity ≥ 0, lr > 0, weight_decay ≥ 0, 0 < lr_gamma ≤ 1, fps > 0; got "
                             f"{sparsity}, {lr}, {weight_decay}, {lr_gamma}, {fps}")
        if lr_schedule not in LR_SCHEDULES or not warmup_epochs >= 0 or not 0 <= lr_final <= 1 or not root_weight > 0:
            raise ValueError(f"need lr_schedule in {LR_SCHEDULES}, warmup_epochs ≥ 0, 0 ≤ lr_final ≤ 1, "
                             f"root_weight > 0; got {lr_schedule!r}, {warmup_epochs}, {lr_final}, {root_weight}")
        self.save_hyperparameters({
            "hidden_units": int(hidden_units), "kernel_size": int(kernel_size), "pooling": str(pooling),
            "input_dropout": float(input_dropout), "sparsity": float(sparsity),
            "contact_weight": float(contact_weight), "lr": float(lr),
            "weight_decay": float(weight_decay), "lr_gamma": float(lr_gamma), "fps": float(fps),
            "lr_schedule": str(lr_schedule), "warmup_epochs": float(warmup_epochs), "lr_final": float(lr_final),
            "root_weight": float(root_weight),
            "frame_dim": int(frame_dim),
            "representation": str(representation), "joint_names": [str(j) for j in joint_names],
            "joint_parents": [int(p) for p in joint_parents],
        })
        self.net = ConvAutoencoder(frame_dim, hidden_units, kernel_size, pooling, input_dropout)

    # -- public API on raw frames
    def encode(self, frames: torch.Tensor) -> torch.Tensor:
        """Raw frames ``(batch, T, 66)`` → features ``(batch, H, ceil(T/2))``."""
        return self.net.encode(frames)

    def decode(self, features: torch.Tensor, num_frames: int | None = None) -> torch.Tensor:
        """Features ``(batch, H, T')`` → raw frames ``(batch, num_frames or 2T', 66)``."""
        return self.net.decode(features, num_frames)

    def forward(self, frames: torch.Tensor) -> torch.Tensor:
        """Reconstruction of raw frames ``(batch, T, 66)``."""
        return self.net(frames)

    def check_compatible(self, fps: float | None = None, frame_dim: int | None = None,
                         representation: str | None = None, joint_names: Sequence[str] | None = None) -> None:
        """Raise :class:`IncompatibleModelError` naming every given property that differs from the model's."""
        hp = self.hparams
        wanted = {"fps": fps, "frame_dim": frame_dim, "representation": representation,
                  "joint_names": None if joint_names is None else list(joint_names)}
        bad = [f"{k}: model {hp[k]!r}, data {v!r}" for k, v in wanted.items()
               if v is not None and (abs(float(v) - hp[k]) > 1e-6 if k == "fps" else v != hp[k])]
        if bad:
            raise IncompatibleModelError("model and data do not match — " + "; ".join(bad))

    # -- Lightning hooks
    def setup(self, stage: str) -> None:
        datamodule = getattr(self.trainer, "datamodule", None) if self._trainer is not None else None
        if datamodule is not None:
            self.check_compatible(fps=getattr(datamodule, "fps", None),
                                  frame_dim=getattr(datamodule, "frame_dim", None),
                                  representation=getattr(datamodule, "representation", None))
        if self.net.normalizer.initialized:
            return
        if datamodule is None or not hasattr(datamodule, "normalization"):
            raise RuntimeError("MotionAutoencoder has no normalization statistics: train it with a datamodule "
                               "that provides `normalization` (e.g. MotionWindowDataModule), or call "
                               "model.net.normalizer.set_stats(mean, std) first")
        self.net.normalizer.set_stats(*datamodule.normalization)

    def on_load_checkpoint(self, checkpoint: dict[str, Any]) -> None:
        saved = checkpoint.get("hyper_parameters", {})
        keys = ("hidden_units", "kernel_size", "pooling", "fps", "frame_dim", "representation", "joint_names")
        bad = [f"{k}: checkpoint {saved[k]!r}, model {self.hparams[k]!r}" for k in keys
               if k in saved and saved[k] != self.hparams[k]]
        if bad:
            raise IncompatibleModelError("checkpoint does not match the configured model — " + "; ".join(bad))

    def configure_optimizers(self):
        optimizer = torch.optim.Adam(self.parameters(), lr=self.hparams.lr, weight_decay=self.hparams.weight_decay)
        if self.hparams.get("lr_schedule", "exponential") == "cosine":
            total = int(self.trainer.estimated_stepping_batches)
            epochs = self.trainer.max_epochs
            per_epoch = total / epochs if epochs and epochs > 0 else self.trainer.num_training_batches
            warmup = int(round(float(self.hparams.warmup_epochs) * (per_epoch if math.isfinite(per_epoch) else 0)))
            factor = partial(cosine_factor, total=total, warmup=warmup, final=float(self.hparams.lr_final))
            schedule = torch.optim.lr_scheduler.LambdaLR(optimizer, factor)
            return {"optimizer": optimizer, "lr_scheduler": {"scheduler": schedule, "interval": "step"}}
        if self.hparams.lr_gamma == 1.0:
            return optimizer
        schedule = torch.optim.lr_scheduler.ExponentialLR(optimizer, gamma=self.hparams.lr_gamma)
        return {"optimizer": optimizer, "lr_scheduler": {"scheduler": schedule, "interval": "epoch"}}

    def _step(self, frames: torch.Tensor, split: str, batch_idx: int) -> torch.Tensor:
        net = self.net
        z = net.normalizer.normalize(frames)
        features = net.encode_normalized(net.corrupt(z) if split == "train" else z)
        recon = net.decode_normalized(features, frames.shape[-2])
        mse = F.mse_loss(recon, z)
        fit = mse if split != "train" else weighted_mse(recon, z, float(self.hparams.get("root_weight", 1.0)))
        loss = fit + self.hparams.sparsity * features.abs().mean() if self.hparams.sparsity else fit
        weight = float(self.hparams.get("contact_weight", 0.0))
        contact = None
        if weight > 0 or split != "train":
            raw_recon = net.normalizer.denormalize(recon.float())  # float32 also under bf16 autocast
            contact = contact_velocity_loss(raw_recon, window_contacts(frames, self.hparams.fps), self.hparams.fps)
            if weight > 0:
                loss = loss + weight * contact
        if split == "train" and not torch.isfinite(loss):
            raise NonFiniteLossError(
                f"training loss is {loss.item()} at epoch {self.current_epoch}, batch {batch_idx} (global step "
                f"{self.global_step}); check the data of that batch, or lower the learning rate "
                f"(lr={self.hparams.lr})"
            )
        with torch.no_grad():
            raw = net.normalizer.denormalize(recon.detach().float())  # float32 also under bf16 autocast
            error, local_error = mpjpe(raw, frames, self.hparams.fps), local_mpjpe(raw, frames)
        size, train = frames.shape[0], split == "train"
        if train:
            self.log("train/loss", loss, prog_bar=True, batch_size=size, sync_dist=True)
        self.log(f"{split}/mse", mse, batch_size=size, sync_dist=True, on_epoch=True, on_step=train)
        self.log(f"{split}/mpjpe", error, batch_size=size, sync_dist=True, on_epoch=True, on_step=train,
                 prog_bar=not train)
        self.log(f"{split}/mpjpe_local", local_error, batch_size=size, sync_dist=True, on_epoch=True,
                 on_step=train)
        if contact is not None:
            self.log(f"{split}/contact", contact.detach(), batch_size=size, sync_dist=True, on_epoch=True,
                     on_step=train)
        return loss

    def training_step(self, batch: torch.Tensor, batch_idx: int) -> torch.Tensor:
        return self._step(batch, "train", batch_idx)

    def validation_step(self, batch: torch.Tensor, batch_idx: int) -> None:
        self._step(batch, "val", batch_idx)

    def test_step(self, batch: torch.Tensor, batch_idx: int) -> None:
        self._step(batch, "test", batch_idx)

    def predict_step(self, batch: torch.Tensor, batch_idx: int) -> torch.Tensor:
        return self(batch)
