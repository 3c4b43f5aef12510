"""Benchmark of controlled synthesis (issue 7): a 10 m S-curve, neutral and every style, several seeds.

    python scripts/bench_generate.py --run runs/reproduce/bandai --seeds 0 1 2 [--out runs/bench_generate]

For each (style, seed) it runs :func:`stylemotion.synthesis.generate.generate` (BVH written and read back,
GIF off unless ``--gif``) and prints one JSON line: path deviation (mean/max/final, m), duration,
mean speed, foot skating before/after the clean-up and of real clips of the style, transition
ratios, BVH round-trip MPJPE and the synthesis time (seconds, excluding model loading and file
writing). A last line ``{"summary": ...}`` holds the mean over seeds per style.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
import torch

from stylemotion.models.loading import NEUTRAL
from stylemotion.synthesis.controller import SharpTurnWarning
from stylemotion.synthesis.generate import generate
from stylemotion.synthesis.graph import available_models

FIELDS = ("mean_m", "max_m", "final_m")


def row(style: str, seed: int, summary: dict) -> dict:
    tr = summary["transitions"]
    return {"style": style, "seed": seed, **{f"deviation_{k}": summary["deviation"][k] for k in FIELDS},
            "duration_s": summary["duration_s"], "mean_speed_mps": summary["mean_speed_mps"], "steps": summary["steps"],
            "latent_norm": summary["latent_norm_mean"],
            "skating": summary["foot_skating_ratio"], "skating_raw": summary["foot_skating_ratio_before_cleanup"],
            "skating_real": summary["real_foot_skating_ratio"], "transition_speed_ratio": tr["ratio"],
            "transition_accel_ratio": tr["accel_ratio"], "bvh_mpjpe_m": summary.get("bvh_reimport_mpjpe_m"),
            "synthesis_s": summary["synthesis_seconds"], "warnings": len(summary["warnings"])}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", required=True, help="a finished stylemotion-reproduce folder")
    parser.add_argument("--styles", nargs="*", help="default: neutral and every style in the run")
    parser.add_argument("--seeds", nargs="*", type=int, default=[0, 1, 2])
    parser.add_argument("--length", type=float, default=10.0, help="S-curve length, metres")
    parser.add_argument("--out", help="keep the output folders here (default: a temporary folder)")
    parser.add_argument("--gif", action="store_true")
    parser.add_argument("--threads", type=int, default=1)
    args = parser.parse_args(argv)
    torch.set_num_threads(args.threads)
    styles = args.styles or sorted({e["name"] for e in available_models(args.run)}, key=lambda s: (s != NEUTRAL, s))
    rows = []
    with tempfile.TemporaryDirectory() as scratch:
        base = Path(args.out or scratch)
        for style in styles:
            for seed in args.seeds:
                cfg = {"run": args.run, "style": style, "seed": seed,
                       "path": {"s_curve": {"length_m": args.length, "amplitude_m": 1.0, "waves": 1.0}},
                       "outputs": {"bvh": True, "gif": args.gif}, "out": str(base / f"{style}_seed{seed}"),
                       "force": True}
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", SharpTurnWarning)  # counted in the row
                    rows.append(row(style, seed, generate(cfg, "scripts/bench_generate.py")))
                print(json.dumps(rows[-1]), flush=True)
    summary = {}
    for style in styles:
        mine = [r for r in rows if r["style"] == style]
        summary[style] = {k: float(np.mean([r[k] for r in mine])) for k in mine[0]
                          if k not in ("style", "seed") and mine[0][k] is not None}
    print(json.dumps({"summary": summary, "run": args.run, "seeds": args.seeds, "threads": args.threads,
                      "cpu_count": os.cpu_count(), "load_average": [round(v, 2) for v in os.getloadavg()]}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
