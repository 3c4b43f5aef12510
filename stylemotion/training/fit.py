"""Training (what ``stylemotion-train`` runs): fit ``cfg.model`` on the DataModule ``cfg.datamodule``.

    stylemotion-train experiment=autoencoder data=bandai           # the thesis' motion autoencoder
    stylemotion-train experiment=smoke                              # seconds, on the synthetic data
    stylemotion-train experiment=smoke -m model.kernel_size=9,15,25 # a sweep (basic launcher)
    stylemotion-train ... -m hydra/launcher=joblib                  # the sweep's jobs in parallel
    stylemotion-train ... trainer=ddp trainer.devices=2             # DistributedDataParallel
    stylemotion-train ... hydra.run.dir=<run folder> ckpt_path=last # resume that run
    stylemotion-train ... hydra.run.dir=<run folder> ckpt_path=auto # resume if it has last.ckpt, else start

Each run writes into one folder: the resolved config, ``run.json`` (version, commit, command of
every start), TensorBoard logs, ``checkpoints/{best,last}.ckpt`` and ``metrics.json``. A folder that
holds a run's results is refused unless the run resumes (``ckpt_path=last|auto|<file>``) or
``force=true`` (which deletes the old results). The full specification (what counts as a result,
``ckpt_path`` modes, how ``last.ckpt`` is kept with Lightning's public API) is ``docs/training.md``.
"""

from __future__ import annotations

import json
import logging
import math
import signal
from collections.abc import Iterable, Mapping, Sequence
from datetime import datetime
from pathlib import Path
from typing import Any

import lightning.pytorch as pl
import torch
from hydra.utils import instantiate
from lightning.pytorch.callbacks import LearningRateMonitor, ModelCheckpoint, OnExceptionCheckpoint
from lightning.pytorch.loggers import TensorBoardLogger
from lightning.pytorch.utilities import rank_zero_only
from omegaconf import DictConfig, OmegaConf

from stylemotion.config import ConfigError, check_trainer_numbers, set_torch_threads
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.errors import UserInputError
from stylemotion.io.jsonfile import read_json, write_json
from stylemotion.io.outputs import OutputExistsError, UnsafePathError
from stylemotion.provenance import provenance

log = logging.getLogger(__name__)

#: Values of ``ckpt_path`` that mean "start afresh".
NO_CHECKPOINT = (None, "", "null", "none", "None")
#: Files a logger leaves in its folder (TensorBoard, CSV); ``hparams.yaml`` is cleared, not looked for.
LOGGER_RESULTS = ("events.out.tfevents.*", "metrics.csv")
LOGGER_FILES = (*LOGGER_RESULTS, "hparams.yaml")


class CheckpointNotFoundError(UserInputError, FileNotFoundError):
    """``ckpt_path`` names a checkpoint that does not exist."""


class CheckpointAtTrainEnd(pl.Callback):
    """Saves ``<dirpath>/<filename>.ckpt`` when fitting ends (``trainer.save_checkpoint``), so a run that
    stops between two scheduled saves (every N steps, with max_steps, max_time or early stopping in
    between) still leaves its final state in ``last.ckpt``. Not called after an exception."""

    def __init__(self, dirpath: str | Path, filename: str = "last"):
        self.dirpath, self.filename = str(dirpath), filename

    def on_train_end(self, trainer: pl.Trainer, pl_module: pl.LightningModule) -> None:
        trainer.save_checkpoint(Path(self.dirpath) / f"{self.filename}.ckpt")


def last_checkpoint(output_dir: str | Path) -> Path:
    """Where a run folder's latest checkpoint lives: ``<output_dir>/checkpoints/last.ckpt``."""
    return Path(output_dir) / "checkpoints" / "last.ckpt"


def resolve_ckpt_path(ckpt_path: str | None, output_dir: Path) -> str | None:
    """The checkpoint to resume from: ``last`` → ``<output_dir>/checkpoints/last.ckpt`` (which must
    exist); ``auto`` → the same if it exists, else None (start); other values must be files.

    Raises:
        CheckpointNotFoundError: ``last`` or a path that is not a file, naming it.
    """
    if ckpt_path in NO_CHECKPOINT:
        return None
    last = last_checkpoint(output_dir)
    if ckpt_path == "auto":
        return str(last) if last.is_file() else None
    if ckpt_path == "last":
        if not last.is_file():
            raise CheckpointNotFoundError(
                f"ckpt_path=last but there is no {last}; to resume a run pass its folder "
                "(hydra.run.dir=<folder> or output_dir=<folder>), use ckpt_path=auto to start when there is "
                "nothing to resume, or drop ckpt_path to start afresh")
        return str(last)
    if not Path(ckpt_path).is_file():
        raise CheckpointNotFoundError(f"ckpt_path {ckpt_path!r} is not a file")
    return str(ckpt_path)


def result_locations(output_dir: Path, callbacks: Iterable[pl.Callback],
                     loggers: Iterable[Any]) -> tuple[list[Path], list[Path]]:
    """The folders a run's results go to: checkpoint folders (those of the checkpoint callbacks, and
    ``<output_dir>/checkpoints``) and logger folders (each logger's ``log_dir``)."""
    ckpt_dirs = {output_dir / "checkpoints"}
    ckpt_dirs |= {Path(cb.dirpath) for cb in callbacks
                  if isinstance(cb, (ModelCheckpoint, OnExceptionCheckpoint, CheckpointAtTrainEnd)) and cb.dirpath}
    log_dirs = {Path(lg.log_dir) for lg in loggers if getattr(lg, "log_dir", None)}
    return sorted(ckpt_dirs), sorted(log_dirs)


def find_results(output_dir: Path, ckpt_dirs: Sequence[Path], log_dirs: Sequence[Path],
                 logger_patterns: Sequence[str] = LOGGER_RESULTS) -> dict[str, list[Path]]:
    """Results of an earlier run: ``{"checkpoints": [*.ckpt], "metrics": [metrics.json], "logs": [...]}``."""
    metrics = output_dir / "metrics.json"
    return {
        "checkpoints": sorted(p for d in ckpt_dirs if d.is_dir() for p in d.glob("*.ckpt")),
        "metrics": [metrics] if metrics.is_file() else [],
        "logs": sorted(p for d in log_dirs if d.is_dir() for pattern in logger_patterns for p in d.glob(pattern)),
    }


def check_no_links_out(output_dir: Path, ckpt_dirs: Sequence[Path], log_dirs: Sequence[Path]) -> None:
    """Refuse a result folder below ``output_dir`` (or a file in it) that is a link leading out of ``output_dir``:
    ``force=true`` would delete, and the run would write, the files it points to.

    Raises:
        UnsafePathError: naming the link and the folder.
    """
    root = output_dir.resolve()
    for folder in (*ckpt_dirs, *log_dirs):
        if not folder.is_relative_to(output_dir):
            continue  # a folder configured elsewhere on purpose (e.g. callbacks.*.dirpath)
        paths = [folder, *(sorted(folder.iterdir()) if folder.is_dir() else [])]
        for path in paths:
            resolved = path.resolve()
            if resolved != root and root not in resolved.parents:
                raise UnsafePathError(f"{path} is a link to {resolved}, outside the run folder {output_dir}: a run "
                                      "never writes or deletes through it; remove the link or choose another folder")


def _delete(paths: Iterable[Path], why: str) -> None:
    paths = list(paths)
    for path in paths:
        path.unlink(missing_ok=True)
    if paths:
        log.warning("%s: deleted %d file(s): %s", why, len(paths), ", ".join(str(p) for p in paths[:5])
                    + (" …" if len(paths) > 5 else ""))


def prepare_output(output_dir: Path, ckpt_path: str | None, force: bool, ckpt_dirs: Sequence[Path],
                   log_dirs: Sequence[Path]) -> str | None:
    """Check (and with ``force`` clear) the run folder; returns the checkpoint to resume from, or None.

    See the module doc for the rules. Only global rank zero looks at and clears the folder (other
    ranks start after it); every rank resolves ``ckpt_path`` alike.

    Raises:
        ConfigError: ``force=true`` together with ``ckpt_path``.
        UnsafePathError: a result folder (or a file in it) is a link out of the run folder
            (:func:`check_no_links_out`).
        OutputExistsError: the folder holds results and the run neither resumes nor forces.
        CheckpointNotFoundError: see :func:`resolve_ckpt_path`.
    """
    if force and ckpt_path not in NO_CHECKPOINT:
        raise ConfigError(f"force=true starts afresh (deleting {output_dir}'s checkpoints) and ckpt_path={ckpt_path} "
                          "resumes: pass one of them")
    check_no_links_out(output_dir, ckpt_dirs, log_dirs)
    resume = resolve_ckpt_path(ckpt_path, output_dir)
    if resume is not None or getattr(rank_zero_only, "rank", 0) != 0:
        return resume
    results = find_results(output_dir, ckpt_dirs, log_dirs)
    if force:
        cleared = find_results(output_dir, ckpt_dirs, log_dirs, LOGGER_FILES)
        _delete([p for paths in cleared.values() for p in paths], f"force=true, starting afresh in {output_dir}")
        return None
    if ckpt_path == "auto" and not results["checkpoints"] and not results["metrics"]:
        # a requeued job whose first attempt saved no checkpoint: its logs would mix with this one's
        _delete(find_results(output_dir, ckpt_dirs, log_dirs, LOGGER_FILES)["logs"],
                f"ckpt_path=auto, no {last_checkpoint(output_dir).name} to resume: starting afresh")
        return None
    found = [p for paths in results.values() for p in paths]
    if found:
        shown = ", ".join(str(p.relative_to(output_dir)) if p.is_relative_to(output_dir) else str(p)
                          for p in found[:4]) + (" …" if len(found) > 4 else "")
        hint = ("resume it with ckpt_path=last (or ckpt_path=auto)" if last_checkpoint(output_dir).is_file()
                else f"it has no {last_checkpoint(output_dir)} to resume from (ckpt_path=<checkpoint> resumes another)")
        raise OutputExistsError(
            f"{output_dir} already holds a run's results ({shown}); {hint}, pass force=true to delete them and "
            "start afresh, or choose another folder (hydra.run.dir=… on the command line, output_dir=… in Python)")
    return None


def _instantiate_all(node: DictConfig | None) -> list[Any]:
    """Instantiate every ``_target_`` entry of a name → config mapping (None entries are skipped)."""
    if not node:
        return []
    return [instantiate(v, _convert_="all") for v in node.values() if v is not None and "_target_" in v]


def build(cfg: DictConfig, datamodule_args: Mapping[str, Any] | None = None
          ) -> tuple[pl.LightningDataModule, pl.LightningModule]:
    """The DataModule (``cfg.datamodule`` given ``data=cfg.data``) and the LightningModule ``cfg.model``.

    Both receive plain Python values from the config, so their hyperparameters are checkpoint-safe.
    ``datamodule_args``: further DataModule arguments that are Python objects rather than config values
    (e.g. the user's example clips of ``stylemotion-style``); passed as they are, never through OmegaConf.
    """
    data_cfg = OmegaConf.to_container(cfg.data, resolve=True)
    if datamodule_args:
        factory = instantiate(cfg.datamodule, data=data_cfg, _convert_="all", _partial_=True)
        datamodule = factory(**datamodule_args)
    else:
        datamodule = instantiate(cfg.datamodule, data=data_cfg, _convert_="all")
    model = instantiate(cfg.model, _convert_="all")
    return datamodule, model


def hyperparameters(cfg: DictConfig) -> dict[str, Any]:
    """What TensorBoard's HPARAMS tab shows of a run: the model and DataModule settings (without
    ``_target_``), the trainer's length and precision, the seed and the data set's name."""
    def plain(node: Any) -> dict[str, Any]:
        values = OmegaConf.to_container(node, resolve=True) if node is not None else {}
        return {k: v for k, v in (values or {}).items() if k != "_target_"}

    trainer = cfg.get("trainer") or {}
    return {"model": plain(cfg.get("model")), "datamodule": plain(cfg.get("datamodule")),
            "trainer": {k: trainer.get(k) for k in ("max_epochs", "max_steps", "precision", "accumulate_grad_batches",
                                                    "gradient_clip_val")},
            "seed": cfg.get("seed"), "data": (cfg.get("data") or {}).get("name")}


class HyperparametersWithMetric(pl.Callback):
    """At the end of fitting, every TensorBoard logger gets ``params`` with the best value of the
    monitored metric as ``hp/<monitor>`` (``log_hyperparams(params, metrics=…)``), so the HPARAMS tab
    lists runs side by side with their score. (A separate tag: the metric's own curve stays clean.)"""

    def __init__(self, params: dict[str, Any], monitor: str):
        self.params, self.monitor = params, monitor

    def on_train_end(self, trainer: pl.Trainer, pl_module: pl.LightningModule) -> None:
        value = _best_score(trainer)
        if value is None:
            value = trainer.callback_metrics.get(self.monitor)
        if value is None:
            return
        for logger in trainer.loggers:
            if isinstance(logger, TensorBoardLogger):
                logger.log_hyperparams(self.params, metrics={f"hp/{self.monitor}": float(_plain(value))})


class ValidationAtBest(pl.Callback):
    """Keeps the validation metrics (every logged ``val/…`` value) of the epoch where ``monitor`` was lowest,
    and of the last validation; :func:`run` writes them to ``metrics.json`` as ``val`` and ``val_last``, the
    numbers a sweep's :func:`objective` is read from (never the test split's)."""

    def __init__(self, monitor: str):
        self.monitor = monitor
        self.best: dict[str, float] = {}
        self.last: dict[str, float] = {}

    def on_validation_end(self, trainer: pl.Trainer, pl_module: pl.LightningModule) -> None:
        if trainer.sanity_checking:
            return
        values = {k: float(_plain(v)) for k, v in trainer.callback_metrics.items() if k.startswith("val/")}
        if not values:
            return
        self.last = values
        score, best = values.get(self.monitor), self.best.get(self.monitor)
        if score is not None and math.isfinite(score) and (best is None or score < best):
            self.best = values

    def state_dict(self) -> dict[str, Any]:  # kept in checkpoints, so a resumed run knows its best epoch
        return {"best": dict(self.best), "last": dict(self.last)}

    def load_state_dict(self, state_dict: dict[str, Any]) -> None:
        self.best, self.last = dict(state_dict.get("best", {})), dict(state_dict.get("last", {}))


def run(cfg: DictConfig, extra_callbacks: list[pl.Callback] | None = None,
        datamodule_args: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Train (and test) as ``cfg`` says; returns ``{"trainer", "model", "datamodule", "metrics"}``.

    ``datamodule_args``: Python objects for the DataModule besides its config (see :func:`build`).
    Bad values (``threads``, the trainer's numbers, ``force`` with ``ckpt_path``) and a folder that
    holds another run's results are refused before any work (see the module doc).
    """
    output_dir = Path(cfg.output_dir)
    set_torch_threads(cfg.get("threads"))
    check_trainer_numbers(cfg.trainer)
    seed = cfg.get("seed")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise ConfigError(f"seed must be a whole number ≥ 0, got {seed!r}")
    callbacks = _instantiate_all(cfg.get("callbacks")) + list(extra_callbacks or [])
    validation = ValidationAtBest(str(cfg.get("monitor") or ""))
    callbacks.append(validation)
    loggers = _instantiate_all(cfg.get("logger"))
    ckpt_path = prepare_output(output_dir, cfg.get("ckpt_path"), bool(cfg.get("force", False)),
                               *result_locations(output_dir, callbacks, loggers))
    if loggers:
        callbacks.append(HyperparametersWithMetric(hyperparameters(cfg), str(cfg.get("monitor") or "")))
    else:  # nothing to log the learning rate to (Lightning refuses the monitor without a logger)
        callbacks = [cb for cb in callbacks if not isinstance(cb, LearningRateMonitor)]
    pl.seed_everything(cfg.seed, workers=True)
    datamodule, model = build(cfg, datamodule_args)
    # a resume is checked against the configured model before the run folder is touched
    resumed_at = check_resume_checkpoint(ckpt_path, model) if ckpt_path is not None else None
    finished = output_dir / "metrics.json"
    if resumed_at is not None and finished.is_file() and nothing_left_to_train(ckpt_path, cfg.trainer):
        # a finished run (a requeued job's ckpt_path=auto): not a new start, so not one of its files is touched
        log.info("%s: the run had finished at step %d and its trainer limits are reached: nothing trained, "
                 "%s kept as it is", ckpt_path, resumed_at, output_dir)
        return {"trainer": None, "model": model, "datamodule": datamodule,
                "metrics": read_json(finished, "metrics file of the finished run")}
    record = record_start(output_dir, cfg, ckpt_path)
    _write_text(output_dir / "config_resolved.yaml", OmegaConf.to_yaml(cfg, resolve=True))
    trainer: pl.Trainer = instantiate(cfg.trainer, callbacks=callbacks, logger=loggers or False,
                                      _convert_="all")
    # Same initial weights on every rank (seeded above); from here on each rank draws its own
    # dropout masks and noise. Data order stays in the distributed sampler's hands.
    rank_seed = int(cfg.seed) + 1_000_003 * trainer.global_rank
    torch.manual_seed(rank_seed)
    log.info("rank %d of %d: torch seed %d", trainer.global_rank, trainer.world_size, rank_seed)

    if cfg.get("train", True):
        # checkpoints hold tensors and plain values only, so they load without unpickling code
        _stop_on_ctrl_c(trainer, trainer.fit, model, datamodule=datamodule, ckpt_path=ckpt_path, weights_only=True)
        if resumed_at is not None and trainer.global_step == resumed_at and finished.is_file():
            log.info("%s: the run had finished at step %d and its trainer limits are reached: nothing trained, "
                     "%s kept as it is", ckpt_path, resumed_at, finished)
            return {"trainer": trainer, "model": model, "datamodule": datamodule,
                    "metrics": read_json(finished, "metrics file of the finished run")}
    metrics: dict[str, Any] = {"global_step": trainer.global_step, "epoch": trainer.current_epoch,
                               "data": getattr(datamodule, "summary", None)}
    best = _best_checkpoint(trainer)
    if best:
        metrics["best_checkpoint"] = best
        metrics["best_score"] = _plain(_best_score(trainer))
    if validation.best or validation.last:  # the validation metrics at the best epoch (what sweeps minimize)
        metrics["val"] = dict(validation.best or validation.last)
        metrics["val_last"] = dict(validation.last)
    if cfg.get("test", True):
        for cb in trainer.checkpoint_callbacks:  # a failure while testing must not save the tested weights
            if isinstance(cb, ModelCheckpoint):  # as last.ckpt
                cb.save_on_exception = False
        # the best checkpoint of this fit; with train=false, the checkpoint given as ckpt_path
        test_ckpt = best or (None if cfg.get("train", True) else ckpt_path)
        results = _stop_on_ctrl_c(trainer, trainer.test, model, datamodule=datamodule, ckpt_path=test_ckpt,
                                  weights_only=True)
        metrics["test"] = {k: _plain(v) for k, v in (results[0] if results else {}).items()}
    metrics["stylemotion_version"] = record["stylemotion_version"]
    metrics["git_commit"] = record["git_commit"]
    _write_metrics(output_dir / "metrics.json", metrics)
    return {"trainer": trainer, "model": model, "datamodule": datamodule, "metrics": metrics}


class ResumeCheckpointError(UserInputError, ValueError):
    """``ckpt_path`` names a file that is not a training checkpoint of the configured model."""


def check_resume_checkpoint(ckpt_path: str, model: pl.LightningModule) -> int:
    """The global step at which ``ckpt_path`` resumes ``model``; read (``weights_only=True``) and checked before
    anything is written: a checkpoint of the same kind of model (``on_load_checkpoint`` accepts its
    hyperparameters) whose weights have the model's shapes.

    Raises:
        ResumeCheckpointError: a missing, junk, cut-off or foreign file, another kind of model or other shapes,
            naming the file.
    """
    from stylemotion.models.checkpoints import checkpoint_kind, read_checkpoint

    where = f"ckpt_path={ckpt_path}"
    try:
        checkpoint = read_checkpoint(ckpt_path, "checkpoint")
    except (FileNotFoundError, UserInputError) as exc:
        raise ResumeCheckpointError(f"{where}: {exc}") from None
    state, step = checkpoint.get("state_dict"), checkpoint.get("global_step")
    if not isinstance(state, Mapping) or isinstance(step, bool) or not isinstance(step, int):
        raise ResumeCheckpointError(f"{where}: not a Lightning training checkpoint (it has {sorted(checkpoint)[:8]}, "
                                    "no state_dict and global_step); resume from a run's checkpoints/last.ckpt")
    saved = checkpoint.get("hyper_parameters")
    saved = dict(saved) if isinstance(saved, Mapping) else {}
    kind, configured = checkpoint_kind(saved), checkpoint_kind(dict(model.hparams))
    if kind != configured and None not in (kind, configured):
        raise ResumeCheckpointError(f"{where}: a {kind} checkpoint, but the configured model is a {configured} "
                                    f"({type(model).__name__}); resume it with its own experiment")
    try:
        model.on_load_checkpoint(dict(checkpoint))
    except UserInputError as exc:
        raise ResumeCheckpointError(f"{where}: {exc}") from None
    own = model.state_dict()
    bad = [f"{k}: checkpoint {tuple(v.shape)}, model {tuple(own[k].shape)}" for k, v in state.items()
           if k in own and isinstance(v, torch.Tensor) and tuple(v.shape) != tuple(own[k].shape)]
    if bad:
        raise ResumeCheckpointError(f"{where}: its weights do not fit the configured {type(model).__name__} — "
                                    + "; ".join(bad[:3]) + (" …" if len(bad) > 3 else ""))
    return step


def _stop_on_ctrl_c(trainer: pl.Trainer, call: Any, *args: Any, **kwargs: Any) -> Any:
    """``call(*args, **kwargs)`` (the trainer's ``fit`` or ``test``), with Ctrl-C raised again as
    :class:`KeyboardInterrupt` after Lightning's graceful shutdown (which saves ``last.ckpt`` to resume from and
    then exits with status 1), so the command ends in its one line and status 130."""
    try:
        return call(*args, **kwargs)
    except SystemExit:
        if not trainer.interrupted:
            raise
        signal.signal(signal.SIGINT, signal.default_int_handler)  # Lightning ignores further Ctrl-C
        raise KeyboardInterrupt from None


def nothing_left_to_train(ckpt_path: str, trainer_cfg: Mapping[str, Any]) -> bool:
    """True when resuming from ``ckpt_path`` would train nothing: its completed epochs reach the trainer's
    ``max_epochs``, its global step reaches ``max_steps``, or early stopping had stopped it."""
    from stylemotion.models.checkpoints import read_checkpoint

    checkpoint = read_checkpoint(ckpt_path, "checkpoint")
    step = int(checkpoint.get("global_step") or 0)
    progress = ((checkpoint.get("loops") or {}).get("fit_loop") or {}).get("epoch_progress") or {}
    epochs = int(((progress.get("current") or {}).get("completed")) or checkpoint.get("epoch") or 0)
    max_epochs, max_steps = trainer_cfg.get("max_epochs"), trainer_cfg.get("max_steps")
    if max_steps is not None and max_steps >= 0 and step >= max_steps:
        return True
    if max_epochs is not None and max_epochs >= 0 and epochs >= max_epochs:
        return True
    stopped = [state.get("stopped_epoch") for name, state in (checkpoint.get("callbacks") or {}).items()
               if str(name).startswith("EarlyStopping") and isinstance(state, Mapping)]
    return any(isinstance(e, int) and e > 0 for e in stopped)


def record_start(output_dir: Path, cfg: DictConfig, ckpt_path: str | None) -> dict[str, Any]:
    """Log what runs (version, commit, folder) and add this start to ``<output_dir>/run.json``
    (``{"run_id", "output_dir", "starts": [provenance + time + resumed_from, …]}``; a fresh start
    replaces the file). Returns this start's record."""
    start = {**provenance(), "time": datetime.now().astimezone().isoformat(timespec="seconds"),
             "resumed_from": ckpt_path}
    log.info("stylemotion %s (commit %s): %s in %s", start["stylemotion_version"], start["git_commit"],
             f"resuming from {ckpt_path}" if ckpt_path else "training", output_dir)
    _write_run_record(output_dir / "run.json", start, str(cfg.get("run_id", "")), ckpt_path is not None)
    return start


@rank_zero_only
def _write_run_record(path: Path, start: dict[str, Any], run_id: str, resumed: bool) -> None:
    record = {"run_id": run_id, "output_dir": str(path.parent), "starts": []}
    if resumed and path.is_file():
        try:
            record = json.loads(path.read_text())
        except (OSError, ValueError):
            log.warning("%s is unreadable: starting a new record", path)
    record.setdefault("starts", []).append(start)
    write_json(path, record, indent=2)


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
    write_json(path, metrics, indent=2)
    log.info("metrics written to %s", path)


@rank_zero_only
def _write_text(path: Path, text: str) -> None:
    atomic_write_bytes(path, text.encode())


def objective_names(cfg: DictConfig) -> list[str]:
    """The validation metrics a sweep minimizes: ``cfg.sweep_objective`` (a name or a list of names, for
    Optuna's multi-objective search) or else ``cfg.monitor``.

    Raises:
        ConfigError: a name that is not a validation metric (``val/…``): sweeps never choose on test data.
    """
    chosen = cfg.get("sweep_objective") or cfg.get("monitor") or ""
    names = [str(n) for n in chosen] if isinstance(chosen, (list, tuple)) or OmegaConf.is_list(chosen) \
        else [str(chosen)]
    bad = [n for n in names if not n.startswith("val/")]
    if bad or not names:
        raise ConfigError(f"sweep_objective/monitor must name validation metrics (val/…), got {bad or names}: a sweep "
                          "chooses on the validation takes, never on the test takes it reports")
    return names


def objective(metrics: dict[str, Any], cfg: DictConfig) -> float | list[float] | None:
    """The number(s) a sweeper minimizes, read from the **validation** split only: for each name of
    :func:`objective_names`, its value at the epoch where ``cfg.monitor`` was best (``metrics["val"]``; for
    the monitor itself the best checkpoint's score). Never a ``test/…`` value. One name → a float, several →
    a list (Optuna's multi-objective sweeps); None when a value is missing or not finite (a failed trial)."""
    names = objective_names(cfg)
    monitor = str(cfg.get("monitor") or "")
    at_best = metrics.get("val") or {}
    values = []
    for name in names:
        value = metrics.get("best_score") if name == monitor and metrics.get("best_score") is not None \
            else at_best.get(name)
        if value is None or not math.isfinite(float(value)):
            return None
        values.append(float(value))
    return values[0] if len(values) == 1 else values
