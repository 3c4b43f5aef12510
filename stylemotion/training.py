"""Training (what ``stylemotion-train`` runs): fit ``cfg.model`` on the DataModule ``cfg.datamodule``.

    stylemotion-train experiment=autoencoder data=bandai           # the thesis' motion autoencoder
    stylemotion-train experiment=smoke                              # seconds, on the synthetic data
    stylemotion-train experiment=smoke -m model.kernel_size=9,15,25 # a sweep (basic launcher)
    stylemotion-train ... -m hydra/launcher=joblib                  # the sweep's jobs in parallel
    stylemotion-train ... trainer=ddp trainer.devices=2             # DistributedDataParallel
    stylemotion-train ... run_id=<id of an earlier run> ckpt_path=last   # resume that run

The entry point only composes and instantiates: ``cfg.datamodule`` receives the data config
(``cfg.data``) as ``data=``; ``cfg.model`` is any LightningModule; ``cfg.trainer``, ``cfg.logger``
and ``cfg.callbacks`` are Lightning objects. Each run writes into one folder (``output_dir``): the
config as composed (``.hydra/``) and resolved (``config_resolved.yaml``), ``tensorboard/``,
``checkpoints/{best,last}.ckpt`` and ``metrics.json`` (test metrics of the best checkpoint).
"""

from __future__ import annotations

import json
import logging
import math
from pathlib import Path
from typing import Any

import lightning.pytorch as pl
import torch
from hydra.utils import instantiate
from lightning.pytorch.callbacks import ModelCheckpoint
from lightning.pytorch.trainer.states import TrainerFn
from lightning.pytorch.utilities import rank_zero_only
from omegaconf import DictConfig, OmegaConf

from stylemotion.io.atomic import atomic_write_bytes

log = logging.getLogger(__name__)


class LastCheckpoint(ModelCheckpoint):
    """``last.ckpt``: the latest state, saved on the callback's schedule (every N steps or epochs),
    when training ends, and on Ctrl+C (KeyboardInterrupt), so ``ckpt_path=last`` resumes from it.

    Configure it with ``filename="last"``, ``monitor=None`` and ``save_top_k=1`` (the latest
    replaces the previous one).
    """

    def on_train_end(self, trainer: pl.Trainer, pl_module: pl.LightningModule) -> None:
        super().on_train_end(trainer, pl_module)
        self._save_now(trainer)

    def on_exception(self, trainer: pl.Trainer, pl_module: pl.LightningModule, exception: BaseException) -> None:
        super().on_exception(trainer, pl_module, exception)
        if isinstance(exception, KeyboardInterrupt):
            self._save_now(trainer)

    def _save_now(self, trainer: pl.Trainer) -> None:
        if trainer.sanity_checking or trainer.global_step == self._last_global_step_saved:
            return
        if trainer.state.fn == TrainerFn.FITTING:
            self._save_topk_checkpoint(trainer, self._monitor_candidates(trainer))


def resolve_ckpt_path(ckpt_path: str | None, output_dir: Path) -> str | None:
    """``last`` → ``<output_dir>/checkpoints/last.ckpt`` (which must exist); other paths unchanged."""
    if ckpt_path in (None, "", "null"):
        return None
    if ckpt_path == "last":
        path = output_dir / "checkpoints" / "last.ckpt"
        if not path.is_file():
            raise FileNotFoundError(
                f"ckpt_path=last but there is no {path}; to resume a run pass its folder "
                "(run_id=<id> or hydra.run.dir=<folder>), or drop ckpt_path to start afresh"
            )
        return str(path)
    if not Path(ckpt_path).is_file():
        raise FileNotFoundError(f"ckpt_path {ckpt_path!r} is not a file")
    return str(ckpt_path)


def _instantiate_all(node: DictConfig | None) -> list[Any]:
    """Instantiate every ``_target_`` entry of a name → config mapping (None entries are skipped)."""
    if not node:
        return []
    return [instantiate(v, _convert_="all") for v in node.values() if v is not None and "_target_" in v]


def build(cfg: DictConfig) -> tuple[pl.LightningDataModule, pl.LightningModule]:
    """The DataModule (``cfg.datamodule`` given ``data=cfg.data``) and the LightningModule ``cfg.model``.

    Both receive plain Python values only, so their hyperparameters are checkpoint-safe.
    """
    data_cfg = OmegaConf.to_container(cfg.data, resolve=True)
    datamodule = instantiate(cfg.datamodule, data=data_cfg, _convert_="all")
    model = instantiate(cfg.model, _convert_="all")
    return datamodule, model


def run(cfg: DictConfig, extra_callbacks: list[pl.Callback] | None = None) -> dict[str, Any]:
    """Train (and test) as ``cfg`` says; returns ``{"trainer", "model", "datamodule", "metrics"}``."""
    output_dir = Path(cfg.output_dir)
    if cfg.get("threads"):
        torch.set_num_threads(int(cfg.threads))
    pl.seed_everything(cfg.seed, workers=True)

    datamodule, model = build(cfg)
    callbacks = _instantiate_all(cfg.get("callbacks")) + list(extra_callbacks or [])
    loggers = _instantiate_all(cfg.get("logger"))
    trainer: pl.Trainer = instantiate(cfg.trainer, callbacks=callbacks, logger=loggers or False,
                                      _convert_="all")
    # Same initial weights on every rank (seeded above); from here on each rank draws its own
    # dropout masks and noise. Data order stays in the distributed sampler's hands.
    rank_seed = int(cfg.seed) + 1_000_003 * trainer.global_rank
    torch.manual_seed(rank_seed)
    log.info("rank %d of %d: torch seed %d", trainer.global_rank, trainer.world_size, rank_seed)

    ckpt_path = resolve_ckpt_path(cfg.get("ckpt_path"), output_dir)
    _write_text(output_dir / "config_resolved.yaml", OmegaConf.to_yaml(cfg, resolve=True))
    if cfg.get("train", True):
        trainer.fit(model, datamodule=datamodule, ckpt_path=ckpt_path)
    metrics: dict[str, Any] = {"global_step": trainer.global_step, "epoch": trainer.current_epoch,
                               "data": getattr(datamodule, "summary", None)}
    best = _best_checkpoint(trainer)
    if best:
        metrics["best_checkpoint"] = best
        metrics["best_score"] = _plain(_best_score(trainer))
    if cfg.get("test", True):
        # the best checkpoint of this fit; with train=false, the checkpoint given as ckpt_path
        test_ckpt = best or (None if cfg.get("train", True) else ckpt_path)
        results = trainer.test(model, datamodule=datamodule, ckpt_path=test_ckpt)
        metrics["test"] = {k: _plain(v) for k, v in (results[0] if results else {}).items()}
    _write_metrics(output_dir / "metrics.json", metrics)
    return {"trainer": trainer, "model": model, "datamodule": datamodule, "metrics": metrics}


def _best_checkpoint(trainer: pl.Trainer) -> str | None:
    for cb in trainer.checkpoint_callbacks:
        if isinstance(cb, ModelCheckpoint) and cb.monitor and cb.best_model_path:
            return cb.best_model_path
    return None


def _best_score(trainer: pl.Trainer) -> Any:
    for cb in trainer.checkpoint_callbacks:
        if isinstance(cb, ModelCheckpoint) and cb.monitor and cb.best_model_path:
            return cb.best_model_score
    return None


def _plain(value: Any) -> Any:
    if isinstance(value, torch.Tensor):
        value = value.item()
    return value


@rank_zero_only
def _write_metrics(path: Path, metrics: dict[str, Any]) -> None:
    atomic_write_bytes(path, json.dumps(metrics, indent=2).encode())
    log.info("metrics written to %s", path)


@rank_zero_only
def _write_text(path: Path, text: str) -> None:
    atomic_write_bytes(path, text.encode())


def objective(metrics: dict[str, Any], cfg: DictConfig) -> float | None:
    """The number a sweeper minimizes: the test value of ``cfg.monitor`` (else its best val value)."""
    name = str(cfg.get("monitor") or "")
    value = metrics.get("test", {}).get(name.replace("val/", "test/"), metrics.get("best_score"))
    return None if value is None or not math.isfinite(value) else float(value)
