"""Benchmark: test MPJPE (cm) against training wall-clock time, as JSON lines.

Builds the datamodule and model exactly as ``stylemotion-train`` does (same Hydra config, same
overrides), trains with a Lightning Trainer on the CPU, and every ``--eval-every`` minutes of
*training* time evaluates MPJPE on the whole test split. Evaluation time is not counted on the
training clock; validation and checkpointing are off. Training uses ``trainer.precision`` from the
config (e.g. ``trainer.precision=bf16-mixed``); evaluation always runs in float32. One JSON object per line:

* ``{"kind": "setup", ...}``: command, machine, threads, data sizes, data loading time;
* ``{"kind": "baseline", ...}``: the mean-pose baseline (every frame = the train mean frame);
* ``{"kind": "point", "minutes", "step", "epoch", "windows_per_s", "test_mpjpe_cm",
  "test_mpjpe_local_cm", "test_mse", "load1", ...}``: one point of the curve (the first at minute 0,
  before any step). ``test_mpjpe_cm``: positions integrated from the origin (root drift counts);
  ``test_mpjpe_local_cm``: root-local poses only (see :mod:`stylemotion.models.autoencoder`);
* ``{"kind": "summary", ...}``: final MPJPE, throughput, minutes to reach each target.

    python scripts/train_curve.py --minutes 10 --eval-every 0.5 --out curve.jsonl -- \\
        experiment=autoencoder data=bandai
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import lightning.pytorch as pl
import torch
from hydra import compose, initialize_config_dir
from omegaconf import OmegaConf

from stylemotion.config import config_dir
from stylemotion.models.autoencoder import local_mpjpe, mpjpe
from stylemotion.training.fit import build


def cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


@torch.no_grad()
def evaluate(model, loader, fps: float) -> dict[str, float]:
    """Window-weighted test MPJPE (cm; integrated and root-local) and normalized MSE over ``loader``."""
    was_training = model.training
    model.eval()
    totals = {"test_mpjpe_cm": 0.0, "test_mpjpe_local_cm": 0.0, "test_mse": 0.0}
    count = 0
    norm = model.net.normalizer
    for frames in loader:
        recon = model(frames)
        n = frames.shape[0]
        totals["test_mpjpe_cm"] += 100 * float(mpjpe(recon, frames, fps)) * n
        totals["test_mpjpe_local_cm"] += 100 * float(local_mpjpe(recon, frames)) * n
        totals["test_mse"] += float(torch.mean((norm.normalize(recon) - norm.normalize(frames)) ** 2)) * n
        count += n
    model.train(was_training)
    return {k: v / count for k, v in totals.items()}


@torch.no_grad()
def mean_pose_baseline(model, loader, fps: float) -> dict[str, float]:
    """Test MPJPE (cm) of predicting the train split's mean frame everywhere."""
    mean = model.net.normalizer.mean
    totals, count = {"test_mpjpe_cm": 0.0, "test_mpjpe_local_cm": 0.0}, 0
    for frames in loader:
        guess, n = mean.expand_as(frames), frames.shape[0]
        totals["test_mpjpe_cm"] += 100 * float(mpjpe(guess, frames, fps)) * n
        totals["test_mpjpe_local_cm"] += 100 * float(local_mpjpe(guess, frames)) * n
        count += n
    return {k: round(v / count, 4) for k, v in totals.items()}


class Curve(pl.Callback):
    """Evaluates the test split every ``every_s`` seconds of training; stops after ``limit_s``."""

    def __init__(self, loader, fps: float, every_s: float, limit_s: float, emit, targets_cm=(1.0, 0.5)):
        self.loader, self.fps, self.every_s, self.limit_s, self.emit = loader, fps, every_s, limit_s, emit
        self.targets = {(key, t): None for key in ("test_mpjpe_cm", "test_mpjpe_local_cm") for t in targets_cm}
        self.windows = 0
        self.eval_s = 0.0
        self.last: dict = {}

    def elapsed(self) -> float:
        return time.perf_counter() - self.start - self.eval_s

    def on_train_start(self, trainer, pl_module) -> None:
        self.start = time.perf_counter()
        self.next_eval = 0.0
        self.point(trainer, pl_module)

    def on_train_batch_end(self, trainer, pl_module, outputs, batch, batch_idx) -> None:
        self.windows += batch.shape[0]
        elapsed = self.elapsed()
        if elapsed >= self.next_eval or elapsed >= self.limit_s:
            self.point(trainer, pl_module)
        if elapsed >= self.limit_s:
            trainer.should_stop = True

    def point(self, trainer, pl_module) -> None:
        train_s = self.elapsed()
        t0 = time.perf_counter()
        result = evaluate(pl_module, self.loader, self.fps)
        self.eval_s += time.perf_counter() - t0
        for (key, target), reached in self.targets.items():
            if reached is None and result[key] <= target:
                self.targets[key, target] = train_s / 60
        self.last = {"kind": "point", "minutes": round(train_s / 60, 4), "step": trainer.global_step,
                     "epoch": trainer.current_epoch, "windows": self.windows,
                     "windows_per_s": round(self.windows / train_s, 1) if train_s > 0 else None,
                     **{k: round(v, 5) for k, v in result.items()},
                     "eval_s": round(time.perf_counter() - t0, 2), "load1": round(os.getloadavg()[0], 2)}
        self.emit(self.last)
        while self.next_eval <= train_s:
            self.next_eval += self.every_s


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--minutes", type=float, default=10.0, help="training wall-clock budget")
    parser.add_argument("--eval-every", type=float, default=0.5, help="minutes of training between evaluations")
    parser.add_argument("--threads", type=int, default=None, help="torch threads (default: config / torch)")
    parser.add_argument("--out", type=Path, default=None, help="also append the JSON lines to this file")
    parser.add_argument("overrides", nargs="*", help="Hydra overrides, as for stylemotion-train")
    args = parser.parse_args(argv)

    def emit(record: dict) -> None:
        line = json.dumps(record)
        print(line, flush=True)
        if args.out:
            with args.out.open("a") as fh:
                fh.write(line + "\n")

    with initialize_config_dir(config_dir(), version_base="1.3"):
        cfg = compose("train", overrides=[*args.overrides, "output_dir=/dev/null"])
    threads = args.threads or cfg.get("threads")
    if threads:
        torch.set_num_threads(int(threads))
    pl.seed_everything(cfg.seed, workers=True, verbose=False)
    t0 = time.perf_counter()
    datamodule, model = build(cfg)
    datamodule.prepare_data()
    datamodule.setup("fit")
    datamodule.setup("test")
    model.net.normalizer.set_stats(*datamodule.normalization)
    load_s = time.perf_counter() - t0
    test_loader = datamodule.test_dataloader()
    fps = float(model.hparams.fps)
    emit({"kind": "setup", "command": " ".join([Path(sys.argv[0]).name, *sys.argv[1:]]),
          "overrides": args.overrides, "cpu": cpu_name(), "cores": os.cpu_count(),
          "torch_threads": torch.get_num_threads(), "torch": torch.__version__, "python": platform.python_version(),
          "precision": cfg.trainer.precision,
          "model": OmegaConf.to_container(cfg.model, resolve=True),
          "datamodule": {k: v for k, v in OmegaConf.to_container(cfg.datamodule).items() if k != "_target_"},
          "data": datamodule.summary, "data_load_s": round(load_s, 1), "load1": round(os.getloadavg()[0], 2)})
    emit({"kind": "baseline", "name": "mean_pose", **mean_pose_baseline(model, test_loader, fps)})

    curve = Curve(test_loader, fps, 60 * args.eval_every, 60 * args.minutes, emit)
    trainer = pl.Trainer(accelerator="cpu", devices=1, precision=cfg.trainer.precision, max_epochs=-1,
                         max_steps=-1, limit_val_batches=0,
                         num_sanity_val_steps=0, logger=False, enable_checkpointing=False,
                         enable_progress_bar=False, enable_model_summary=False, callbacks=[curve])
    trainer.fit(model, train_dataloaders=datamodule.train_dataloader())
    last = curve.last
    emit({"kind": "summary", "minutes": last["minutes"], "steps": last["step"], "epochs": last["epoch"],
          "windows_per_s": last["windows_per_s"], "final_test_mpjpe_cm": last["test_mpjpe_cm"],
          "final_test_mpjpe_local_cm": last["test_mpjpe_local_cm"],
          **{f"minutes_to_{t:g}cm" + ("_local" if "local" in key else ""): None if m is None else round(m, 3)
             for (key, t), m in curve.targets.items()},
          "load1": round(os.getloadavg()[0], 2)})


if __name__ == "__main__":
    main()
