"""Suite ``morphable_variation``: Morphable Graph walks that vary (Du §4.6.3) — repeated walks along one path.

The stance models are those of suite ``morphable`` (Bandai's ``normal`` walk stances, fitted on the train takes of
the same seeded split). Each path step starts from the cheapest of ``morphable.random_starts`` codes drawn from the
mixture by the walk's seed; a start meeting the step within ``accept_cost`` is kept as drawn, else LM refines it
(:mod:`stylemotion.morphable.synthesis`); then, as ``stylemotion-generate`` does, all steps optimized together
(Algorithm 1, line 9) within ``morphable.joint_evaluations`` (the default, in every part, the tree's-candidate rows
included). Parts:

* **choice** — ``accept_cost`` and ``prior_centre`` chosen on a validation path (suite ``morphable``'s corner, not a
  reported path), model seed 0, :data:`VALIDATION_WALKS` walk seeds: of the candidates whose walks' mean deviation
  stays within one sd (over the walk seeds) of the walks always refined towards the mixture (eq. 4.9), the one whose
  repeated walks vary most (pose spread). Path accuracy is thus held to the deterministic walk's, and variation is
  what the rest allows.
* **variation** — on the 10 m S-curve and an 8 m straight line, ``--walks`` walk seeds per model seed (model seeds:
  the mixture's EM), with the chosen ``accept_cost``: the per-step pose spread across walks at aligned steps, the step
  length and duration SD (:mod:`stylemotion.synthesis.variation`), each walk's path deviation (mean, max, final) and
  the walks that fail to reach the end of the path; against the test takes' real stance clips (the same statistics
  across clips) and against the earlier deterministic start (the tree's candidate, ``random_starts = 0``: two walk
  seeds per path, model seed 0).
"""

from __future__ import annotations

import argparse
import time
import warnings
from dataclasses import replace
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, fmt_spread, md_table, provenance_line, spread, take_split_record

DESCRIPTION = ("Morphable Graph walks that vary (Du §4.6.3): random starts per step, accept_cost chosen on a "
               "validation path, spread of repeated walks on the S-curve and a straight line against real test steps")
DEFAULT_SEEDS = (0, 1, 2)

STANCES = ("walk_leftStance", "walk_rightStance")
CONTENTS = ["walk", "walk-turn-left", "walk-turn-right", "raise-up-left-hand"]  # suite morphable's split
#: (prior_centre, accept_cost) candidates; the first, always refined towards the mixture (eq. 4.9), is the reference.
CANDIDATES = (("mixture", 0.0), ("mixture", 0.3), ("mixture", 1.0), ("mixture", 3.0), ("start", 0.0))
#: The first run's rule (the largest accept_cost within 1 cm of always refining, candidates 0, 1, 3, 10) chose 1, whose
#: reported S-curve mean deviation then rose beyond the earlier figure's spread; recorded, not hidden.
FIRST_RUN = {"commit": "bb4562a", "rule": "largest accept_cost whose validation mean deviation is within 1 cm of 0",
             "chosen": 1.0, "s_curve_mean_m": 0.0502, "s_curve_mean_sd_m": 0.0074, "s_curve_pose_spread_m": 0.0089,
             "earlier_s_curve_mean_m": 0.0380, "earlier_s_curve_mean_sd_m": 0.0049}
VALIDATION_WALKS = 4
#: suite morphable's validation path (a corner) and its reported S-curve, plus a straight line.
VALIDATION_PATH = {"points": [[0.0, 0.0], [0.0, 3.0], [0.0, 4.0], [0.3, 4.7], [1.0, 5.0], [2.0, 5.0], [5.0, 5.0]]}
PATHS = {"S-curve (10 m)": {"s_curve": {"length_m": 10.0, "amplitude_m": 1.0, "waves": 1.0}},
         "straight (8 m)": {"points": [[0.0, 0.0], [0.0, 8.0]], "spline": False}}
#: A walk whose end is farther than this from the path's end did not reach it (the controller may stop up to half a
#: step short: ~0.35 m for these steps).
REACH_M = 0.4
AIM_M = 0.10


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--walks", type=int, default=10, help="walk seeds per path and model seed")


def _walk(models: dict, path_cfg: dict, seed: int, settings) -> tuple[Any, dict[str, Any]]:
    from stylemotion.morphable.synthesis import MorphablePrimitive
    from stylemotion.synthesis.cleanup import clean_foot_skating
    from stylemotion.synthesis.controller import follow_path
    from stylemotion.synthesis.generate import path_from_config, rigid_bones
    from stylemotion.synthesis.graph import MotionGraph
    from stylemotion.synthesis.morphable_graph import finish_walk
    from stylemotion.synthesis.quality import walk_figures
    from stylemotion.synthesis.settings import FollowSettings

    graph = MotionGraph("walk", "normal", {name.replace("walk_", ""): MorphablePrimitive(m, settings)
                                           for name, m in models.items()})
    began = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        walk = follow_path(graph, path_from_config(path_cfg), seed=seed)
    walk, _ = finish_walk(graph, walk, FollowSettings())  # Algorithm 1's line 9 where settings ask, as generate does
    seconds = time.perf_counter() - began
    shown = walk.positions  # as stylemotion-generate writes it: rigid bones, then the foot clean-up
    shown = clean_foot_skating(rigid_bones(shown)[0], walk.fps).astype(np.float32)
    figures = walk_figures(replace(walk, positions=shown))
    dev = figures["deviation"]
    refined = [s.terms.get("refined", 1.0) for s in walk.steps]
    return walk, {"seed": seed, "mean_m": dev["mean_m"], "max_m": dev["max_m"], "final_m": dev["final_m"],
                  "steps": len(walk.steps), "refined_share": float(np.mean(refined)),
                  "reached": bool(dev["final_m"] <= REACH_M), "seconds_loaded": round(seconds, 1)}


def _summary(rows: list[dict[str, Any]]) -> dict[str, Any]:
    return {"mean_m": spread(r["mean_m"] for r in rows), "max_m": spread(r["max_m"] for r in rows),
            "final_m": spread(r["final_m"] for r in rows), "refined_share": spread(r["refined_share"] for r in rows),
            "failures": sum(not r["reached"] for r in rows), "beyond_aim": sum(r["max_m"] > AIM_M for r in rows),
            "walks": len(rows)}


def fit_stances() -> tuple[dict[str, list], dict[str, Any], dict[str, dict[str, list]], dict[str, Any]]:
    """Bandai's take split (seed 0, 10 % val, 10 % test, :data:`CONTENTS`), each stance's normal clips per part and
    its model fitted on the train clips (suite morphable's settings): ``(split, split settings, clips, models)``."""
    from suites.morphable import _clips, _fit

    from stylemotion.datasets.registry import load_dataset
    from stylemotion.primitives.segmentation import parse_primitive

    split_cfg = {"seed": 0, "val_fraction": 0.1, "test_fraction": 0.1}
    takeset = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"), contents=CONTENTS)
    split = takeset.split(**split_cfg)
    clips, fitted = {}, {}
    for name in STANCES:
        action, primitive = parse_primitive(name)
        clips[name] = _clips(takeset, split_cfg, action, primitive)
        fitted[name], _ = _fit(clips[name], {"data": "bandai", "variant": "all"})
    return split, split_cfg, clips, fitted


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch

    from stylemotion.morphable.model import refit_mixture
    from stylemotion.morphable.synthesis import MapSettings
    from stylemotion.synthesis.variation import clip_variation, walk_variation

    torch.set_num_threads(1)
    clock, laps = time.perf_counter(), {}

    def lap(part: str) -> None:
        nonlocal clock
        laps[part] = round(time.perf_counter() - clock, 1)
        clock = time.perf_counter()
        print(f"morphable_variation: {part} done ({laps[part]} s)", flush=True)

    split, split_cfg, clips, fitted = fit_stances()
    models = {s: {n: (fitted[n] if s == 0 else refit_mixture(fitted[n], clips[n]["train"], s)) for n in STANCES}
              for s in seeds}
    length = fitted[STANCES[0]].length
    real = {}
    for name in STANCES:
        test = clips[name]["test"]
        real[name] = clip_variation([c.frames for c in test], [c.positions for c in test], test[0].fps,
                                    fitted[name].length)
    lap("models")
    defaults = MapSettings()
    out: dict[str, Any] = {"splits": {
        "takes": take_split_record(split, **split_cfg), "contents": CONTENTS,
        "models": "suite morphable's stance models: fitted on the train takes' normal clips; per model seed the "
                  "mixture's EM",
        "choice": "accept_cost and prior_centre chosen on a validation path (suite morphable's corner), model seed 0",
        "variation": "reported on the 10 m S-curve and an 8 m straight line; real spread: the test takes' normal "
                     "stance clips"},
        "defaults": {"random_starts": defaults.random_starts, "accept_cost": defaults.accept_cost,
                     "prior_centre": defaults.prior_centre, "joint_evaluations": defaults.joint_evaluations},
        "real": real, "reach_m": REACH_M, "aim_m": AIM_M}

    # -- the choice of accept_cost and prior_centre on the validation path
    candidates = []
    for centre, accept in CANDIDATES:
        settings = MapSettings(accept_cost=accept, prior_centre=centre)
        walks, rows = zip(*[_walk(models[seeds[0]], VALIDATION_PATH, w, settings) for w in range(VALIDATION_WALKS)])
        variation = walk_variation(list(walks), length)
        variation.pop("per_step")
        candidates.append({"prior_centre": centre, "accept_cost": accept, "walks": list(rows), **_summary(list(rows)),
                           "variation": variation})
    base = candidates[0]["mean_m"]
    bound = base["mean"] + base["sd"]
    within = [c for c in candidates if c["mean_m"]["mean"] <= bound]
    best = max(within, key=lambda c: c["variation"]["pose_spread_m"])
    chosen = {"prior_centre": best["prior_centre"], "accept_cost": best["accept_cost"]}
    out["choice"] = {"validation_path": VALIDATION_PATH, "model_seed": seeds[0], "walk_seeds": VALIDATION_WALKS,
                     "candidates": candidates, "chosen": chosen, "bound_m": bound,
                     "first_run": FIRST_RUN}
    lap("choice")

    # -- repeated walks on the reported paths
    settings = MapSettings(**chosen)
    variation: dict[str, Any] = {}
    for label, path_cfg in PATHS.items():
        per_model = []
        for s in seeds:
            walks, rows = zip(*[_walk(models[s], path_cfg, w, settings) for w in range(args.walks)])
            v = walk_variation(list(walks), length)
            per_model.append({"model_seed": s, "walks": list(rows), **{k: v[k] for k in
                              ("pose_spread_m", "step_length_sd_m", "duration_sd_s", "steps")},
                              "per_step": v["per_step"]})
        rows = [r for m in per_model for r in m["walks"]]
        variation[label] = {"path": path_cfg, "per_model_seed": per_model, **_summary(rows),
                            **{k: spread(m[k] for m in per_model)
                               for k in ("pose_spread_m", "step_length_sd_m", "duration_sd_s")}}
        print(f"morphable_variation: {label} done", flush=True)
    out["variation"] = variation
    lap("variation")

    # -- the earlier deterministic start (the tree's candidate), model seed 0
    for name in STANCES:
        models[seeds[0]][name].build_tree(seed=seeds[0])
    fixed = {}
    for label, path_cfg in PATHS.items():
        walks, rows = zip(*[_walk(models[seeds[0]], path_cfg, w, MapSettings(random_starts=0)) for w in range(2)])
        v = walk_variation(list(walks), length)
        fixed[label] = {"walks": list(rows), **_summary(list(rows)),
                        **{k: v[k] for k in ("pose_spread_m", "step_length_sd_m", "duration_sd_s")}}
    out["deterministic"] = fixed
    lap("deterministic")
    out["seconds_by_part_loaded"] = laps
    return out


# -- rendering

def _cm(s: dict[str, Any], digits: int = 2, factor: float = 100.0) -> str:
    return fmt_spread({**s, **{k: s[k] * factor for k in ("mean", "sd", "min", "max") if k in s}}, digits)


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    prov = provenance_line(record)
    ch, var, fixed, real = r["choice"], r["variation"], r["deterministic"], r["real"]
    seeds = len(next(iter(var.values()))["per_model_seed"])
    walks = len(next(iter(var.values()))["per_model_seed"][0]["walks"])
    real_pose = np.mean([v["pose_spread_m"] for v in real.values()])
    real_len = np.mean([v["step_length_sd_m"] for v in real.values()])
    real_dur = np.mean([v["duration_sd_s"] for v in real.values()])
    chosen = ch["chosen"]

    def name(c: dict[str, Any]) -> str:
        return f"accept_cost {fmt(c['accept_cost'], 1)}, prior centred on the {c['prior_centre']}"

    rows = []
    for label, v in var.items():
        rows.append([f"{label}, random starts ({name(chosen)})", _cm(v["pose_spread_m"]),
                     _cm(v["step_length_sd_m"]), _cm(v["duration_sd_s"], 1, 1000.0),
                     _cm(v["mean_m"]), _cm(v["max_m"]), f"{v['beyond_aim']} of {v['walks']}",
                     f"{v['failures']} of {v['walks']}"])
    for label, v in fixed.items():
        rows.append([f"{label}, tree's candidate (before; model seed 0)", fmt(v["pose_spread_m"] * 100),
                     fmt(v["step_length_sd_m"] * 100), fmt(v["duration_sd_s"] * 1000, 1), _cm(v["mean_m"]),
                     _cm(v["max_m"]), f"{v['beyond_aim']} of {v['walks']}", f"{v['failures']} of {v['walks']}"])
    rows.append([f"real steps: test takes' normal stance clips ({' / '.join(str(v['clips']) for v in real.values())})",
                 fmt(real_pose * 100), fmt(real_len * 100), fmt(real_dur * 1000, 1), "—", "—", "—", "—"])
    header = ["walks", "pose spread (cm)", "step length SD (cm)", "duration SD (ms)", "mean dev. (cm)",
              "max dev. (cm)", f"max dev. > {fmt(r['aim_m'] * 100, 0)} cm", "did not reach the end"]
    defaults = r["defaults"]
    crow = [[name(c) + (" (chosen)" if (c["accept_cost"], c["prior_centre"]) == (chosen["accept_cost"],
                                                                                chosen["prior_centre"]) else "")
             + (" (default when run)" if (c["accept_cost"], c["prior_centre"]) == (defaults["accept_cost"],
                                                                                   defaults["prior_centre"]) else ""),
             _cm(c["mean_m"]), _cm(c["max_m"]), fmt(c["variation"]["pose_spread_m"] * 100),
             fmt(c["refined_share"]["mean"] * 100, 0) + " %"] for c in ch["candidates"]]
    first = ch["first_run"]
    block = (md_table(header, rows)
             + f"\n\nRandom starts: {seeds} model seeds (the mixture's EM) × {walks} walk seeds per path"
             + (f", each walk then optimized as a whole (Algorithm 1, line 9, {defaults['joint_evaluations']} "
                "evaluations, as `stylemotion-generate` does)" if defaults.get("joint_evaluations") else "")
             + "; spreads are "
             "across the walks of one model seed at aligned steps, averaged over steps, then mean ± sd over model "
             "seeds; deviations mean ± sd over all walks. Pose spread: RMS distance of each step's time-normalized "
             "root-local joints to the mean step. Real steps: the same statistics across the test clips of each "
             "stance (averaged over the two stances); they come from many takes, speeds and turns, a path-free "
             f"reference. A walk did not reach the end when it stops more than {fmt(r['reach_m'] * 100, 0)} cm "
             "from the path's end.\n\nThe choice on the validation path (a corner: 3 m straight, an 86.5° bend, 3 m "
             f"straight), model seed {ch['model_seed']}, {ch['walk_seeds']} walk seeds: among the candidates "
             f"whose mean deviation is at most {fmt(ch['bound_m'] * 100)} cm (always refining towards the mixture, "
             "mean + sd), "
             "the one whose walks vary most. accept_cost: a drawn start whose step residual cost ½‖r‖² is at most "
             "this is kept without Levenberg–Marquardt; prior centred on the start: LM's prior residual pulls towards "
             "the drawn start instead of the component's mean.\n\n"
             + md_table(["candidate", "mean dev. (cm)", "max dev. (cm)", "pose spread (cm)", "steps refined"], crow)
             + f"\n\nAn earlier run (commit {first['commit']}) chose by another rule ({first['rule']}) and chose "
             f"accept_cost {fmt(first['chosen'], 0)}: its S-curve walks varied by "
             f"{fmt(first['s_curve_pose_spread_m'] * 100)} cm but deviated {fmt(first['s_curve_mean_m'] * 100)} ± "
             f"{fmt(first['s_curve_mean_sd_m'] * 100)} cm on "
             f"average, beyond the spread of suite morphable's earlier {fmt(first['earlier_s_curve_mean_m'] * 100)} ± "
             f"{fmt(first['earlier_s_curve_mean_sd_m'] * 100)} cm; the rule above holds accuracy to the deterministic "
             f"walk's instead. {prov}")
    s_curve = var.get("S-curve (10 m)") or next(iter(var.values()))
    headline = md_table(["Morphable Graph walks that vary (Du §4.6.3)", "result"], [
        ["pose spread of repeated walks on the S-curve (random starts) / real test steps",
         f"{_cm(s_curve['pose_spread_m'])} / {fmt(real_pose * 100)} cm"],
        ["S-curve mean / max deviation of those walks; max > 10 cm; did not reach the end",
         f"{_cm(s_curve['mean_m'])} / {_cm(s_curve['max_m'])} cm; {s_curve['beyond_aim']} and "
         f"{s_curve['failures']} of {s_curve['walks']}"]]) + f"\n\nDetails: benchmarks/morphable.md. {prov}"
    return {"headline": headline, "walks": block}
