"""Suite ``morphable_joint``: Du's Algorithm 1, line 9 — every step's code of a Morphable Graph walk optimized
together after the graph walk (:mod:`stylemotion.synthesis.joint_walk`), before and after, on the S-curve, the double
S and the corner.

The stance models are suite ``morphable_variation``'s (Bandai's ``normal`` walk stances fitted on the train takes of
the seeded split; per model seed the mixture's EM), walking with ``stylemotion-generate``'s ``morphable.*`` defaults
(random starts by the walk's seed). Parts:

* **choice** — ``morphable.joint_evaluations`` (LM's budget; 0 = off) on **validation paths**, never a reported one:
  suite morphable's corner and suite synthesis's three seeded random splines, model seed ``seeds[0]``,
  ``--validation-walks`` walk seeds each. Each greedy walk is optimized with every budget. Rule (:func:`choose`):
  the lowest mean over walks of log(mean deviation ÷ the walk's best) + log(transition acceleration ratio ÷ the
  walk's best) — path accuracy and the smoothness of the joins weighed alike, as suite synthesis weighs accuracy and
  skating; among budgets within :data:`TIE` of it, the smallest.
* **test** — suite synthesis's reported paths (10 m S-curve, 14 m double S, 11 m rounded corner) × every model seed ×
  ``--walks`` walk seeds: the greedy walk and the same walk after line 9 at the chosen budget (paired), as
  ``stylemotion-generate`` writes them (rigid bones, then the foot clean-up): deviation from the path (mean, max,
  final), transition speed and acceleration ratios, raw foot skating, seconds; walks beyond 10 cm counted.
"""

from __future__ import annotations

import argparse
import time
import warnings
from dataclasses import replace
from typing import Any

import numpy as np
from suites.common import fmt, fmt_spread, md_table, provenance_line, spread, take_split_record

DESCRIPTION = ("Morphable Graph walks with every step optimized together after the walk (Du Algorithm 1, line 9): "
               "LM budget chosen on validation paths, before/after on the S-curve, double S and corner")
DEFAULT_SEEDS = (0, 1, 2)
#: LM budgets (objective evaluations) compared with 0 (the walk as searched step by step).
BUDGETS = (0, 5, 10, 20, 40, 80)
#: Scores within this of the lowest tie; the smaller budget is chosen.
TIE = 0.01
#: A walk whose largest deviation exceeds this is counted (issue 28's aim for walks that vary).
AIM_M = 0.10


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--walks", type=int, default=4, help="walk seeds per reported path and model seed")
    parser.add_argument("--validation-walks", type=int, default=2, help="walk seeds per validation path")


def validation_paths() -> dict[str, dict[str, Any]]:
    from suites.morphable import VALIDATION_PATH
    from suites.synthesis import VALIDATION_PATHS, validation_path

    return {"corner (suite morphable's)": VALIDATION_PATH,
            **{f"random spline {i}": validation_path(i) for i in range(VALIDATION_PATHS)}}


def figures(walk, record: dict[str, Any] | None, seconds: float) -> dict[str, Any]:
    """One walk's figures, its positions as ``stylemotion-generate`` writes them (rigid bones, then the foot
    clean-up); raw skating before the clean-up."""
    from stylemotion.synthesis.cleanup import clean_foot_skating
    from stylemotion.synthesis.generate import rigid_bones
    from stylemotion.synthesis.quality import skating, walk_figures

    rigid = rigid_bones(walk.positions)[0]
    raw, _ = skating(rigid, walk.fps)
    shown = clean_foot_skating(rigid, walk.fps).astype(np.float32)
    f = walk_figures(replace(walk, positions=shown))
    row = {"mean_m": f["deviation"]["mean_m"], "max_m": f["deviation"]["max_m"], "final_m": f["deviation"]["final_m"],
           "transition_speed": f["transitions"]["ratio"], "transition_accel": f["transitions"]["accel_ratio"],
           "skating_raw": raw, "steps": f["steps"], "seconds": round(seconds, 2)}
    if record is not None:
        row.update({k: record[k] for k in ("objective_before", "objective_after", "target_error_before",
                                           "target_error_after", "kept", "evaluations")})
    return row


def choose(rows: dict[int, list[dict[str, Any]]]) -> tuple[int, dict[int, dict[str, float]]]:
    """The rule of the module doc over ``rows`` (budget → its validation walks, in one order for every budget)."""
    budgets = sorted(rows)
    dev = np.array([[r["mean_m"] for r in rows[b]] for b in budgets])
    accel = np.array([[r["transition_accel"] for r in rows[b]] for b in budgets])
    score = np.log(dev / dev.min(axis=0)) + np.log(accel / accel.min(axis=0))
    scores = {b: {"score": float(score[i].mean()), "mean_m": float(dev[i].mean()),
                  "transition_accel": float(accel[i].mean()),
                  "seconds": float(np.mean([r["seconds"] for r in rows[b]]))} for i, b in enumerate(budgets)}
    best = min(s["score"] for s in scores.values())
    return min(b for b in budgets if scores[b]["score"] <= best + TIE), scores


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch
    from suites.morphable_variation import CONTENTS, STANCES, fit_stances
    from suites.synthesis import PATHS

    from stylemotion.morphable.model import refit_mixture
    from stylemotion.morphable.synthesis import MapSettings, MorphablePrimitive
    from stylemotion.synthesis.controller import follow_path
    from stylemotion.synthesis.generate import path_from_config
    from stylemotion.synthesis.graph import MotionGraph
    from stylemotion.synthesis.morphable_graph import optimize_walk
    from stylemotion.synthesis.settings import FollowSettings
    from stylemotion.synthesis.variation import walk_variation

    torch.set_num_threads(1)
    split, split_cfg, clips, fitted = fit_stances()
    follow, settings = FollowSettings(), MapSettings()
    length = fitted[STANCES[0]].length

    def graph(seed: int):
        models = {n: (fitted[n] if seed == 0 else refit_mixture(fitted[n], clips[n]["train"], seed)) for n in STANCES}
        return MotionGraph("walk", "normal", {n.replace("walk_", ""): MorphablePrimitive(m, settings)
                                              for n, m in models.items()})

    def greedy(g, path_cfg: dict[str, Any], walk_seed: int):
        began = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            walk = follow_path(g, path_from_config(path_cfg), seed=walk_seed, settings=follow)
        return walk, time.perf_counter() - began

    def joint(g, walk, budget: int):
        began = time.perf_counter()
        out, record = optimize_walk(g, walk, follow, budget)
        return out, record, time.perf_counter() - began

    out: dict[str, Any] = {"splits": {
        "takes": take_split_record(split, **split_cfg), "contents": CONTENTS,
        "models": "suite morphable_variation's stance models: fitted on the train takes' normal clips; per model seed "
                  "the mixture's EM",
        "choice": "joint_evaluations chosen on validation paths (suite morphable's corner, suite synthesis's seeded "
                  f"random splines), model seed {seeds[0]}",
        "test": "suite synthesis's reported paths (S-curve, double S, corner), every model seed"},
        "defaults": {"joint_evaluations": settings.joint_evaluations, "random_starts": settings.random_starts},
        "aim_m": AIM_M, "budgets": list(BUDGETS), "tie": TIE}

    # -- the choice on validation paths
    g = graph(seeds[0])
    rows: dict[int, list[dict[str, Any]]] = {b: [] for b in BUDGETS}
    for label, path_cfg in validation_paths().items():
        for w in range(args.validation_walks):
            walk, seconds = greedy(g, path_cfg, w)
            rows[0].append({"path": label, "walk_seed": w, **figures(walk, None, 0.0)})
            for budget in BUDGETS[1:]:
                done, record, spent = joint(g, walk, budget)
                rows[budget].append({"path": label, "walk_seed": w, **figures(done, record, spent)})
        print(f"morphable_joint: validation {label} done", flush=True)
    chosen, scores = choose(rows)
    out["choice"] = {"paths": validation_paths(), "model_seed": seeds[0], "walk_seeds": args.validation_walks,
                     "rows": {str(b): r for b, r in rows.items()}, "scores": {str(b): s for b, s in scores.items()},
                     "chosen": chosen}

    # -- before and after on the reported paths
    test: dict[str, Any] = {}
    for label, path_cfg in PATHS.items():
        pairs = []
        kept: dict[int, dict[str, list]] = {s: {"before": [], "after": []} for s in seeds}
        for s in seeds:
            g = graph(s)
            for w in range(args.walks):
                walk, seconds = greedy(g, path_cfg, w)
                before = figures(walk, None, seconds)
                after = before
                if chosen:
                    done, record, spent = joint(g, walk, chosen)
                    after = figures(done, record, spent)
                pairs.append({"model_seed": s, "walk_seed": w, "before": before, "after": after})
                kept[s]["before"].append(walk)
                kept[s]["after"].append(done if chosen else walk)
        spreads = {side: [walk_variation(kept[s][side], length)["pose_spread_m"] for s in seeds]
                   for side in ("before", "after")}
        test[label] = {"path": path_cfg, "walks": pairs, "pose_spread_m": spreads}
        print(f"morphable_joint: test {label} done", flush=True)
    out["test"] = test
    return out


# -- rendering

def _cm(values: list[float]) -> str:
    return fmt_spread(spread(100 * v for v in values))


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    prov = provenance_line(record)
    ch = r["choice"]
    chosen = ch["chosen"]
    aim = r["aim_m"]
    rows, pooled = [], {"before": [], "after": []}
    for label, t in r["test"].items():
        for side in ("before", "after"):
            walks = [p[side] for p in t["walks"]]
            pooled[side] += walks
            name = "greedy walk (lines 2–8)" if side == "before" else f"after line 9 ({chosen} evaluations)"
            rows.append([f"{label}: {name}", _cm([w["mean_m"] for w in walks]), _cm([w["max_m"] for w in walks]),
                         fmt(100 * max(w["max_m"] for w in walks)), _cm([w["final_m"] for w in walks]),
                         fmt_spread(spread(w["transition_accel"] for w in walks)),
                         fmt_spread(spread(100 * w["skating_raw"] for w in walks), 1),
                         f"{sum(w['max_m'] > aim for w in walks)} of {len(walks)}",
                         _cm(t["pose_spread_m"][side]), fmt_spread(spread(w["seconds"] for w in walks), 1)])
    seeds = len({p["model_seed"] for t in r["test"].values() for p in t["walks"]})
    walks = len({p["walk_seed"] for t in r["test"].values() for p in t["walks"]})
    header = ["path: walk", "mean dev. (cm)", "max dev. (cm)", "largest (cm)", "final dev. (cm)",
              "transition accel. ratio", "raw skating (%)", f"max > {fmt(aim * 100, 0)} cm",
              "pose spread across walk seeds (cm)", "seconds (the greedy walk; line 9 alone)"]
    kept = [p["after"].get("kept") for t in r["test"].values() for p in t["walks"]]
    crow = [[f"{b}" + (" (chosen)" if int(b) == chosen else "") + (" (off)" if int(b) == 0 else ""),
             fmt(s["mean_m"] * 100), fmt(s["transition_accel"]), fmt(s["score"], 3), fmt(s["seconds"], 1)]
            for b, s in ch["scores"].items()]
    block = (md_table(header, rows)
             + f"\n\n{seeds} model seeds (the mixture's EM) × {walks} walk seeds per path; each walk before and after "
             "line 9 (the same greedy walk, paired); mean ± sd over walks; largest: the worst walk. Positions as "
             "`stylemotion-generate` writes them (rigid bones, then the foot clean-up); raw skating before the "
             f"clean-up. Line 9 kept its result in {sum(bool(k) for k in kept)} of {len(kept)} walks (else the walk "
             "is unchanged).\n\n"
             f"`morphable.joint_evaluations` chosen on validation paths ({', '.join(ch['paths'])}), model seed "
             f"{ch['model_seed']}, {ch['walk_seeds']} walk seeds each: score = mean over walks of log(mean deviation ÷ "
             "the walk's best) + log(transition acceleration ratio ÷ the walk's best); among budgets within "
             f"{fmt(r['tie'], 2)} of the lowest, the smallest.\n\n"
             + md_table(["budget (evaluations)", "val mean dev. (cm)", "val transition accel. ratio", "score",
                         "seconds of line 9"], crow)
             + f"\n\n{prov}")
    before, after = pooled["before"], pooled["after"]
    s_curve = (r["test"].get("S-curve (10 m)") or next(iter(r["test"].values())))["pose_spread_m"]
    headline = md_table(["Morphable Graph walks, all steps optimized together (Du Algorithm 1, line 9)", "result"], [
        ["mean / max deviation over the S-curve, double S and corner: greedy walk → after line 9",
         f"{_cm([w['mean_m'] for w in before])} → {_cm([w['mean_m'] for w in after])} / "
         f"{_cm([w['max_m'] for w in before])} → {_cm([w['max_m'] for w in after])} cm"],
        ["largest deviation of any walk; walks beyond 10 cm",
         f"{fmt(100 * max(w['max_m'] for w in before))} → {fmt(100 * max(w['max_m'] for w in after))} cm; "
         f"{sum(w['max_m'] > aim for w in before)} → {sum(w['max_m'] > aim for w in after)} of {len(after)}"],
        ["transition acceleration ratio; raw foot skating",
         f"{fmt_spread(spread(w['transition_accel'] for w in before))} → "
         f"{fmt_spread(spread(w['transition_accel'] for w in after))}; "
         f"{fmt_spread(spread(100 * w['skating_raw'] for w in before), 1)} → "
         f"{fmt_spread(spread(100 * w['skating_raw'] for w in after), 1)} %"],
        ["pose spread of repeated walks (walk seeds), S-curve",
         f"{_cm(s_curve['before'])} → {_cm(s_curve['after'])} cm"],
    ]) + (f"\n\nBudget {chosen} evaluations, chosen on validation paths. Same-actor models: Bandai's normal walks. "
          f"Details: benchmarks/morphable.md. {prov}")
    return {"headline": headline, "walks": block}
