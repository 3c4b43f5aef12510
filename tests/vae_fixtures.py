"""Shared helpers of the VAE/CVAE tests: tiny synthetic data and a tiny autoencoder trained once.

The autoencoder is trained on the embedded synthetic data the first time a test asks for it (about a
second on one core) and cached for the rest of the pytest process, so the four test files that
use it share one training run. Each test file wraps :func:`tiny_autoencoder_ckpt` in a
session-scoped fixture.
"""

from __future__ import annotations

from pathlib import Path

import lightning.pytorch as pl
import torch

from stylemotion.datamodules import MotionWindowDataModule
from stylemotion.datamodules.features import FeatureDataModule
from stylemotion.datasets import TakeSet
from stylemotion.datasets.registry import load_synthetic
from stylemotion.models import MotionAutoencoder

#: The synthetic data of these tests: straight walks of three styles, 6 takes of 6 s per style
#: (4 train, 1 val, 1 test): about 20 training clips per stance primitive.
TINY_DATA = {"name": "synthetic", "takes_per_pair": 6, "seed": 0, "fps": 30, "duration_s": 6.0,
             "styles": ["normal", "elderly", "youthful"], "contents": ["walk"],
             "split": {"seed": 0, "val_fraction": 0.1, "test_fraction": 0.1}}
#: The same as Hydra command-line overrides.
TINY_OVERRIDES = ["data=synthetic", "data.takes_per_pair=6", "data.duration_s=6.0",
                  "data.styles=[normal,elderly,youthful]", "data.contents=[walk]", "datamodule.min_train_clips=8"]
#: Hidden units of the tiny autoencoder (the thesis' has 256).
TINY_HIDDEN = 32

_CACHE: dict[str, Path] = {}
_TAKESET: list[TakeSet] = []


def tiny_takeset() -> TakeSet:
    if not _TAKESET:
        options = {k: v for k, v in TINY_DATA.items() if k not in ("name", "split")}
        _TAKESET.append(load_synthetic(**options))
    return _TAKESET[0]


def tiny_autoencoder_ckpt(folder: Path) -> Path:
    """Path of a 32-unit autoencoder fitted for 60 steps on the tiny data (trained once per process)."""
    if "ae" not in _CACHE:
        threads = torch.get_num_threads()
        torch.set_num_threads(1)
        pl.seed_everything(0, verbose=False)
        dm = MotionWindowDataModule(takeset=tiny_takeset(), window_frames=30, stride=15, batch_size=32)
        model = MotionAutoencoder(hidden_units=TINY_HIDDEN, lr=3e-3)
        trainer = pl.Trainer(accelerator="cpu", max_steps=60, logger=False, enable_checkpointing=False,
                             enable_progress_bar=False, enable_model_summary=False, num_sanity_val_steps=0,
                             limit_val_batches=0)
        trainer.fit(model, datamodule=dm)
        folder.mkdir(parents=True, exist_ok=True)
        trainer.save_checkpoint(folder / "tiny_ae.ckpt", weights_only=False)
        torch.set_num_threads(threads)
        _CACHE["ae"] = folder / "tiny_ae.ckpt"
    return _CACHE["ae"]


def feature_module(ae_ckpt: Path, **kwargs) -> FeatureDataModule:
    """A set-up FeatureDataModule of walk_leftStance on the tiny data (kwargs override)."""
    kwargs.setdefault("primitive", "walk_leftStance")
    kwargs.setdefault("min_train_clips", 8)
    kwargs.setdefault("batch_size", 16)
    dm = FeatureDataModule(takeset=tiny_takeset(), autoencoder_ckpt=str(ae_ckpt), split=TINY_DATA["split"], **kwargs)
    dm.setup("fit")
    return dm


def fit(model: pl.LightningModule, dm: pl.LightningDataModule, steps: int, folder: Path | None = None,
        val_every: int | None = None) -> pl.Trainer:
    """Fit for ``steps`` optimizer steps on the CPU (a best-checkpoint callback when ``folder`` is given)."""
    callbacks = []
    if folder is not None:
        callbacks.append(pl.callbacks.ModelCheckpoint(dirpath=folder, filename="best", monitor="val/loss",
                                                      save_top_k=1, enable_version_counter=False))
    trainer = pl.Trainer(accelerator="cpu", max_steps=steps, logger=False, enable_checkpointing=bool(callbacks),
                         callbacks=callbacks, enable_progress_bar=False, enable_model_summary=False,
                         num_sanity_val_steps=0, check_val_every_n_epoch=val_every or 1,
                         limit_val_batches=1.0 if folder is not None or val_every else 0)
    trainer.fit(model, datamodule=dm)
    return trainer


def validate(model: pl.LightningModule, dm: pl.LightningDataModule) -> dict[str, float]:
    """Validation metrics of ``model`` as it is (e.g. untrained)."""
    trainer = pl.Trainer(accelerator="cpu", logger=False, enable_checkpointing=False, enable_progress_bar=False,
                         enable_model_summary=False)
    return {k: float(v) for k, v in trainer.validate(model, datamodule=dm, verbose=False)[0].items()}


def user_examples(count: int, style: str = "exhausted") -> list:
    """``count`` examples as ``stylemotion-style`` converts them: synthetic walks of a style the tiny data lacks."""
    from stylemotion.datasets.synthetic import generate_take
    from stylemotion.datasets.user_motion import ConvertedExample, ExampleSpec

    takes = [generate_take("walk", style, i, seed=11, fps=30.0, duration_s=3.0 + i) for i in range(count)]
    return [ConvertedExample(ExampleSpec(f"take{i}.bvh"), f"{i:064x}", 30.0, len(t.positions), 0, len(t.positions),
                             t.positions, 30.0) for i, t in enumerate(takes)]
