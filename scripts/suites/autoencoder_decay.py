"""Suite ``autoencoder_decay``: the motion autoencoder's learning-rate decay (``model.lr_gamma``, per epoch) chosen
on **validation** windows of Bandai walks, as the reproduction trains it (its autoencoder stage: epochs, precision,
data, split), before any figure is reported with it.

    python scripts/benchmarks.py run autoencoder_decay --gammas 0.85 0.9 0.94 0.97 0.99

Each candidate is trained with seed ``--choice-seed`` (not a reported seed) on the data and take split of suite
``style_bandai``'s seed-``--seeds`` reproduction (its data stage, reused or made here); the rule is the candidate's
best ``val/mpjpe`` (root-integrated, the stage's checkpoint monitor and the objective of
``hparams_search=autoencoder``). No test window is read. Finished candidates are reused (``candidate.json``).
"""

from __future__ import annotations

import argparse
import math
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path
from typing import Any

from suites import style
from suites.common import fmt, md_table, provenance_line

DESCRIPTION = "the autoencoder's learning-rate decay chosen on Bandai validation windows (candidates, scores)"
DEFAULT_SEEDS = (0,)
#: The validation figures recorded per candidate; the first decides.
METRICS = ("val/mpjpe", "val/mpjpe_local")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--data", choices=sorted(style.DATA), default="bandai",
                        help="bandai: dataset-2 walks (the reproduction's data); synthetic: a smoke run only")
    parser.add_argument("--runs", type=Path, default=style.ROOT / "runs" / "benchmarks" / "style",
                        help="folder of suite style_bandai's runs (the data stage is shared with them)")
    parser.add_argument("--gammas", type=float, nargs="+", default=[0.85, 0.9, 0.94, 0.97, 0.99], metavar="GAMMA",
                        help="candidate decays per epoch (1 = a constant learning rate)")
    parser.add_argument("--choice-seed", type=int, default=100,
                        help="training seed of the candidates (not one of the reported seeds)")
    parser.add_argument("--workers", type=int, default=1, help="candidates trained at once (one thread each)")


def train_decay_candidate(container: dict[str, Any], folder: str) -> dict[str, float]:
    """Train one candidate (a resolved ``train`` config) into ``folder``, or reuse its record; returns its
    validation figures at the best ``val/mpjpe`` epoch (metres). Runs in a worker process."""
    from omegaconf import OmegaConf

    from stylemotion.io.jsonfile import read_json_object, write_json
    from stylemotion.training.fit import run as train_run

    path = Path(folder)
    record = path / "candidate.json"
    if record.is_file():
        return dict(read_json_object(record, "a decay candidate's record", f"delete {path}")["val"])
    train_run(OmegaConf.create(container))
    metrics = read_json_object(path / "metrics.json", "a decay candidate's metrics", f"delete {path}")
    val = {m: metrics.get("val", {}).get(m) for m in METRICS}
    write_json(record, {"val": val, "epochs": metrics.get("epoch"), "steps": metrics.get("global_step")})
    return val


def choose_decay(values: dict[float, dict[str, float | None]]) -> float:
    """The candidate with the lowest finite ``val/mpjpe`` (ties: the larger γ, the gentler schedule); a failed
    candidate (missing or non-finite) is never chosen."""
    def score(gamma: float) -> float:
        value = values[gamma].get(METRICS[0])
        return float(value) if value is not None and math.isfinite(float(value)) else math.inf

    finite = [g for g in values if math.isfinite(score(g))]
    if not finite:
        raise ValueError("every decay candidate failed: no finite val/mpjpe")
    return min(finite, key=lambda g: (score(g), -g))


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from hydra.core.global_hydra import GlobalHydra
    from omegaconf import OmegaConf

    from stylemotion.training.reproduction import Reproduction, stage_train_config

    seed = seeds[0]
    base = args.runs / args.data / style.setup_tag(None, None)
    cfg = style.compose_reproduce(style.reproduce_overrides(args.data, seed, base / f"seed{seed}", 1, None, []))
    try:
        repro = Reproduction(cfg)
        repro.out.mkdir(parents=True, exist_ok=True)
        repro.data_stage()
        overrides = [o for o in OmegaConf.to_container(cfg.stages.autoencoder, resolve=True)
                     if not str(o).startswith("model.lr_gamma=")]
        jobs = {}
        for gamma in sorted(args.gammas):
            folder = base / "autoencoder_decay" / f"seed{args.choice_seed}" / f"gamma{gamma:g}"
            train_cfg = stage_train_config([*overrides, f"model.lr_gamma={gamma}"], {}, repro.data_cfg, folder,
                                           args.choice_seed, 1)
            jobs[gamma] = (OmegaConf.to_container(train_cfg, resolve=True), str(folder))
    finally:
        GlobalHydra.instance().clear()
    values: dict[float, dict[str, float | None]] = {}
    with ProcessPoolExecutor(max_workers=max(1, args.workers), mp_context=get_context("spawn")) as pool:
        futures = {gamma: pool.submit(train_decay_candidate, *job) for gamma, job in jobs.items()}
        for gamma, future in futures.items():
            values[gamma] = future.result()
            print(f"[γ {gamma:g}] " + ", ".join(f"{m} {values[gamma].get(m)}" for m in METRICS), flush=True)
    return {"data": args.data, "stage_overrides": overrides, "candidates": sorted(args.gammas),
            "seed": args.choice_seed, "data_of_seed": seed, "values": {f"{g:g}": v for g, v in values.items()},
            "chosen": choose_decay(values),
            "rule": "the lowest val/mpjpe (root-integrated, at the best epoch); ties: the larger γ",
            "splits": {"choose": "validation windows of the reproduction's take split; no test window is read",
                       "seed": f"candidates trained with seed {args.choice_seed}, not a reported seed"}}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    rows = [[f"{g:g}" + (" **(chosen)**" if g == r["chosen"] else ""),
             fmt(100 * v["val/mpjpe"], 3) if v.get("val/mpjpe") is not None else "failed",
             fmt(100 * v["val/mpjpe_local"], 3) if v.get("val/mpjpe_local") is not None else "failed"]
            for g in r["candidates"] for v in [r["values"][f"{g:g}"]]]
    edge = r["chosen"] in (min(r["candidates"]), max(r["candidates"]))
    text = (f"The autoencoder's learning-rate decay per epoch (`model.lr_gamma`) chosen on **validation** windows "
            f"({r['data']}; the reproduction's autoencoder stage: {', '.join(f'`{o}`' for o in r['stage_overrides'])};"
            f" candidates trained with seed {r['seed']}, not a reported seed). Rule: {r['rule']}. No test window is "
            f"read.\n\n"
            + md_table(["γ", "val MPJPE integrated (cm)", "val MPJPE root-local (cm)"], rows)
            + f"\n\nChosen: γ = {r['chosen']:g}"
            + (" — **an edge of the grid**: a wider grid may choose beyond it." if edge else ".")
            + f" {provenance_line(record)}")
    return {"headline": text}
