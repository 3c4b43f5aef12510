"""Benchmark: sampling throughput of a primitive VAE / style CVAE, as one JSON line.

``model.sample(n, seed=...)`` end to end: latent draws, VAE decoder, autoencoder decoder, duration
restoration and root integration into positions (n, frames, 21, 3). The best of ``--repeats``
runs is reported, with the time of the VAE decoder alone.

    python scripts/bench_sampling.py --ckpt runs/train/primitive_vae/.../checkpoints/best.ckpt
    python scripts/bench_sampling.py            # a random stand-in with the thesis' sizes

Without ``--ckpt`` the model is a randomly initialized stand-in of the same size as a Bandai walk
stance model (a 256-unit autoencoder, an 18-frame canonical timeline, so 256 × 9 features, and
durations around 0.6 s): the compute per sample is the same as a trained model's.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import torch


def stand_in(folder: Path):
    """An untrained PrimitiveVAE (and autoencoder checkpoint) with Bandai walk-stance sizes."""
    import lightning.pytorch as pl

    from stylemotion.models.autoencoder import MotionAutoencoder
    from stylemotion.models.checkpoints import autoencoder_info
    from stylemotion.models.vae import PrimitiveVAE

    torch.manual_seed(0)
    ae = MotionAutoencoder(hidden_units=256)
    ae.net.normalizer.set_stats(torch.zeros(66), torch.full((66,), 0.2))
    trainer = pl.Trainer(accelerator="cpu", logger=False, enable_progress_bar=False, enable_model_summary=False)
    trainer.strategy.connect(ae)
    path = folder / "stand_in_ae.ckpt"
    trainer.save_checkpoint(path, weights_only=False)
    spec = {"primitive": "walk_leftStance", "action": "walk", "feature_channels": 256, "feature_steps": 9,
            "timeline_frames": 18, "fps": 30.0, "autoencoder": autoencoder_info(ae, path), "dataset": "stand-in",
            "content_styles": ["normal"], "clips": {}, "style": None, "style_examples": [], "example_length": None}
    model = PrimitiveVAE(spec=spec)
    model.duration_stats.copy_(torch.tensor([-0.55, 0.1, 0.43, 0.66]))
    model.feature_std.fill_(0.1)
    model.stats_initialized.fill_(True)
    return model


def load(path: Path):
    from stylemotion.models.loading import load_generative

    return load_generative(path)


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ckpt", type=Path, help="PrimitiveVAE/StyleCVAE checkpoint (default: random stand-in)")
    parser.add_argument("-n", type=int, default=10_000, help="samples per run")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=None, help="torch threads (default: torch's)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    if args.threads:
        torch.set_num_threads(args.threads)
    with tempfile.TemporaryDirectory() as tmp:
        model = load(args.ckpt) if args.ckpt else stand_in(Path(tmp))
        model.eval()
        _ = model.autoencoder  # load it before timing
        model.sample(16, seed=args.seed)  # warm-up
        totals, decoder = [], []
        for r in range(args.repeats):
            start = time.perf_counter()
            samples = model.sample(args.n, seed=args.seed + r)
            totals.append(time.perf_counter() - start)
            start = time.perf_counter()
            with torch.no_grad():
                model.net.decode(samples.latent)
            decoder.append(time.perf_counter() - start)
    best = min(totals)
    result = {
        "kind": "sampling", "checkpoint": str(args.ckpt) if args.ckpt else None,
        "model": type(model).__name__ if args.ckpt else "random stand-in PrimitiveVAE (256 × 9 features)",
        "primitive": model.primitive, "style": model.spec.get("style"), "samples": args.n,
        "seconds": round(best, 4), "all_seconds": [round(t, 4) for t in totals],
        "samples_per_s": round(args.n / best, 1), "vae_decoder_seconds": round(min(decoder), 4),
        "positions_shape": list(samples.positions.shape), "mean_duration_s": round(float(samples.duration_s.mean()), 4),
        "threads": torch.get_num_threads(), "cpus": os.cpu_count(), "machine": platform.machine(),
        "python": platform.python_version(), "torch": torch.__version__, "load1": round(os.getloadavg()[0], 2),
    }
    print(json.dumps(result))
    return result


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
