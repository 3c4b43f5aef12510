"""Suite ``morphable``: the Morphable Graph (Du ch. 3–4) on Bandai's ``normal`` walk stances and an arm primitive.

Every figure comes from one seeded split by take of the Bandai contents the suite loads (``--contents``; the split
``stylemotion-train experiment=morphable_graph data=bandai 'data.contents=[…]'`` uses): models are fitted on
``train``, every setting is chosen on ``val`` (or on a validation path) and figures are reported on ``test``
(or on the S-curve). Parts:

* **reductions** — joint-space RMSE of FPCA / normalized FPCA / SFPCA at the default latent size on the held-out
  test clips and on other captures (SFPCA's weights optimized on train; of its start and its optimized weights the
  one with the lower val error is kept). Deterministic given the split (no seed).
* **keyframe** — the hand of ``raise-up-left-hand`` ``raise`` driven to the held-out clips' own end positions: σ_c
  chosen among candidates on the val clips' targets, reported on the test clips' targets (median, p95, max,
  failures); per seed the mixture's EM and the tree's codes differ.
* **sampling** — pose_SD / V_SD / step_SD of samples against the training clips, per seed.
* **path** — the 10 m S-curve of ``stylemotion-generate`` with one model per stance, and the graph walk's
  look-ahead ``T`` among turn variants chosen on a validation path (a corner) and reported on the S-curve.
* **regression** — the reference figures of ``tests/morphable/test_bandai_morphable.py`` on the val split.

Library: :mod:`stylemotion.morphable.heldout` (reductions on held-out clips, keyframe solves, the σ_c choice).
"""

from __future__ import annotations

import argparse
import tempfile
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, fmt_spread, md_table, provenance_line, quantiles, spread, take_split_record

DESCRIPTION = ("Morphable Graph on Bandai normal walks: FPCA / normalized / SFPCA on test clips, keyframe σ_c chosen "
               "on val, sampling statistics, S-curve path following with look-ahead T chosen on a validation path")
DEFAULT_SEEDS = (0, 1, 2)

STANCES = ("walk_leftStance", "walk_rightStance")
TURNS = ("straight", "left", "right")
ARM_CONTENT, ARM_PRIMITIVE, ARM_JOINT = "raise-up-left-hand", "raise", "Hand_L"
SCALE_CANDIDATES_M = (0.001, 0.002, 0.005, 0.01, 0.02, 0.05)
LOOKAHEAD_CANDIDATES = (1, 2, 3)
#: The validation path of the look-ahead choice: 3 m straight, a bend of 86.5° (up to 38.5° within 0.6 m), 3 m
#: straight — a different shape from the reported S-curve.
VALIDATION_PATH = {"points": [[0.0, 0.0], [0.0, 3.0], [0.0, 4.0], [0.3, 4.7], [1.0, 5.0], [2.0, 5.0], [5.0, 5.0]]}
REPORT_PATH = {"s_curve": {"length_m": 10.0, "amplitude_m": 1.0, "waves": 1.0}}
#: The small model of the regression test (as in tests/morphable/test_bandai_morphable.py).
REGRESSION_SETTINGS = {"latent_dim": 8, "reduction": "fpca"}
REGRESSION_SCALE_M = 0.005  # σ_c of the regression test's keyframe solves (fixed, whatever the default)
HELD_OUT = ("val", "test", "other captures")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--contents", nargs="+", default=["walk", "walk-turn-left", "walk-turn-right", ARM_CONTENT],
                        help="Bandai contents loaded (the split is of these takes)")
    parser.add_argument("--samples", type=int, default=10_000, help="samples per stance and seed (sampling part)")
    parser.add_argument("--lookahead", action="store_true",
                        help="also fit each stance's turn variants and choose the look-ahead T on a validation path "
                             "(24 more trees and 12 more walks: beyond the suite's time budget on a loaded machine)")


def _clips(takeset, split: dict, action: str, primitive: str) -> dict[str, list]:
    from stylemotion.datamodules.clips import ClipDataModule

    dm = ClipDataModule(takeset=takeset, action=action, primitives=[primitive], styles=["normal"], split=split)
    dm.setup()
    return {p: list(c) for p, c in dm.clips.items()}


def _fit(clips: dict[str, list], meta: dict[str, Any]):
    from stylemotion.morphable import FitSettings, fit_primitive

    began = time.perf_counter()
    model = fit_primitive(clips["train"], FitSettings(), meta=meta, validation=clips["val"])
    return model, time.perf_counter() - began


def _seeded(model, train: list, seed: int):
    """The model with its mixture's EM and its tree's codes drawn from ``seed`` (seed 0: the fitted mixture)."""
    from stylemotion.morphable.model import refit_mixture

    model = model if seed == 0 else refit_mixture(model, train, seed)
    model.build_tree(seed=seed)
    return model


def _walk(models: dict[str, dict[str, Any]], path: dict, steps: int, seed: int, folder: Path) -> dict[str, Any]:
    from stylemotion.synthesis.controller import SharpTurnWarning
    from stylemotion.synthesis.generate import generate

    files: dict[str, Any] = {}
    for key, variants in models.items():
        names = []
        for name, model in variants.items():
            file = folder / "models" / f"{key}_{name}_seed{seed}.npz"
            if not file.is_file():
                model.save(file)
            names.append(str(file))
        files[key] = names[0] if len(names) == 1 else names
    cfg = {"model": {"family": "morphable"}, "models": files, "style": "neutral", "seed": seed, "path": path,
           "out": str(folder / "walk"), "force": True, "morphable": {"lookahead_steps": steps},
           "outputs": {"bvh": False, "gif": False}}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", SharpTurnWarning)
        s = generate(cfg)
    return {**{f"deviation_{k}": s["deviation"][k] for k in ("mean_m", "max_m", "final_m")}, "steps": s["steps"],
            "skating": s["foot_skating_ratio"], "transition_speed_ratio": s["transitions"]["ratio"],
            "sharp_turn_warnings": len(caught)}


def _part_keyframe(split: dict, seeds: list[int], defaults: dict[str, Any]) -> dict[str, Any]:
    """σ_c chosen on the val takes' raise clips' final Hand_L as targets, reported on the test takes'."""
    from stylemotion.morphable.heldout import choose_constraint_scale, keyframe_errors
    from stylemotion.primitives.arm import arm_clips
    from stylemotion.skeleton import CANONICAL_JOINTS

    # -- keyframe σ_c: the raise primitive, targets = held-out clips' own Hand_L end positions
    j = CANONICAL_JOINTS.index(ARM_JOINT)
    arm = {p: arm_clips([t for t in takes if t.content == ARM_CONTENT], ARM_CONTENT, ARM_PRIMITIVE)[0]
           for p, takes in split.items()}
    normal = {p: [c for c in v if c.style == "normal"] for p, v in arm.items()}
    arm_model, _ = _fit(normal, {"data": "bandai", "action": ARM_CONTENT, "primitive": ARM_PRIMITIVE})
    targets = {p: np.stack([c.positions[-1, j] for c in arm[p]]) for p in ("val", "test")}
    keyframe: dict[str, Any] = {"clips": {p: len(v) for p, v in arm.items()},
                                "train_clips_normal": len(normal["train"]),
                                "targets": {p: len(v) for p, v in targets.items()},
                                "candidates_m": list(SCALE_CANDIDATES_M)}
    arm_seeded = {s: _seeded(arm_model, normal["train"], s) for s in seeds}
    val_scores: dict[float, list] = {}
    for s in seeds:
        choice = choose_constraint_scale(arm_seeded[s], targets["val"], SCALE_CANDIDATES_M, ARM_JOINT)
        for row in choice["candidates"]:
            val_scores.setdefault(row["scale_m"], []).append(row)
    keyframe["validation"] = [{"scale_m": sc, "median_m": spread(r["median_m"] for r in rows),
                               "p95_m": spread(r["p95_m"] for r in rows),
                               **{k: sum(r[k] for r in rows) for k in ("missed", "off_model", "failures")}}
                              for sc, rows in val_scores.items()]
    best = min(keyframe["validation"], key=lambda r: (r["failures"], round(r["median_m"]["mean"], 5), -r["scale_m"]))
    keyframe["chosen_m"] = best["scale_m"]
    test_rows = {}
    for sc in sorted({best["scale_m"], defaults["constraint_scale_m"]}):
        per = []
        for s in seeds:
            found = keyframe_errors(arm_seeded[s], targets["test"], ARM_JOINT, sc)
            q = quantiles(found["errors_m"], (50, 95, 100))
            per.append({"seed": s, "median_m": q["p50"], "p95_m": q["p95"], "max_m": q["p100"],
                        "tree_median_m": float(np.median(found["tree_errors_m"])), "failures": found["failures"],
                        "missed": found["missed"], "off_model": found["off_model"],
                        "within_2cm": float(np.mean(np.asarray(found["errors_m"]) <= 0.02))})
        test_rows[str(sc)] = {"per_seed": per, **{k: spread(p[k] for p in per) for k in
                                                   ("median_m", "p95_m", "max_m", "tree_median_m", "within_2cm")},
                              **{k: sum(p[k] for p in per) for k in ("missed", "off_model", "failures")}}
    keyframe["test"] = test_rows
    mean_code = (arm_model.gmm.weights[:, None] * arm_model.gmm.means).sum(0)
    mean_hand = arm_model.poses_at(mean_code[None], [arm_model.length - 1])[0, 0, j]
    keyframe["mean_motion_median_m"] = {p: float(np.median(np.linalg.norm(targets[p] - mean_hand, axis=1)))
                                        for p in targets}
    return keyframe


def _part_regression(zip_path: str, split_cfg: dict, defaults: dict[str, Any]) -> dict[str, Any]:
    """The val references of tests/morphable/test_bandai_morphable.py."""
    from stylemotion.datasets.registry import load_dataset
    from stylemotion.morphable import FitSettings, fit_primitive
    from stylemotion.morphable.heldout import keyframe_errors
    from stylemotion.morphable.model import reconstruction_error
    from stylemotion.primitives.arm import arm_clips
    from stylemotion.skeleton import CANONICAL_JOINTS

    j = CANONICAL_JOINTS.index(ARM_JOINT)
    # -- the regression test's references: its own slice (raise-up-left-hand, style normal), val split only
    slice_ = load_dataset("bandai", root=zip_path, contents=[ARM_CONTENT], styles=["normal"]).split(**split_cfg)
    reg = {p: arm_clips(t, ARM_CONTENT, ARM_PRIMITIVE)[0] for p, t in slice_.items()}
    small = fit_primitive(reg["train"], FitSettings(**REGRESSION_SETTINGS))
    small.build_tree(2000, seed=0)
    val_keys = keyframe_errors(small, np.stack([c.positions[-1, j] for c in reg["val"]]), ARM_JOINT,
                               REGRESSION_SCALE_M)
    return {"slice": f"{ARM_CONTENT} takes of style normal, split seed 0 (0.1 / 0.1)",
                         "settings": REGRESSION_SETTINGS, "tree": {"samples": 2000, "seed": 0},
                         "clips": {p: len(c) for p, c in reg.items()},
                         "val_joint_rmse_m": reconstruction_error(small, reg["val"]),
                         "val_keyframe_max_m": float(max(val_keys["errors_m"])),
                         "val_keyframe_failures": val_keys["failures"]}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch

    from stylemotion.datasets.registry import load_dataset
    from stylemotion.evaluation.tables import variance_stats
    from stylemotion.models.sampling import pad_motions
    from stylemotion.morphable import FitSettings
    from stylemotion.morphable.heldout import (
        compare_reductions,
        user_motion_clips,
    )
    from stylemotion.morphable.synthesis import MapSettings
    from stylemotion.morphable.variants import select_turn
    from stylemotion.primitives.segmentation import parse_primitive, time_normalize

    torch.set_num_threads(1)
    clock, seconds_by_part = time.perf_counter(), {}

    def lap(part: str) -> None:  # loaded seconds per part (not a figure: the machine is shared)
        nonlocal clock
        seconds_by_part[part] = round(time.perf_counter() - clock, 1)
        clock = time.perf_counter()
        print(f"morphable: {part} done ({seconds_by_part[part]} s)", flush=True)

    split_cfg = {"seed": 0, "val_fraction": 0.1, "test_fraction": 0.1}
    zip_path = str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip")
    takeset = load_dataset("bandai", root=zip_path, contents=list(args.contents))
    split = takeset.split(**split_cfg)
    lap("load")
    out: dict[str, Any] = {"splits": {
        "takes": take_split_record(split, **split_cfg),
        "contents": list(args.contents),
        "reductions": "fitted on train clips (style normal); SFPCA's kept weights chosen on val; reported on test "
                      "and on other captures (the other-skeletons walks: other actors and skeletons, put on Bandai's)",
        "keyframe": "σ_c chosen on the val takes' raise clips (all styles) as targets; reported on the test takes'",
        "sampling": "samples of models fitted on train, against the train clips",
        "path": "look-ahead T chosen on a validation path (a corner, VALIDATION_PATH); reported on the 10 m S-curve",
        "regression": "the reference of tests/morphable/test_bandai_morphable.py: val clips and val targets"}}
    folder = Path(tempfile.mkdtemp(prefix="morphable_suite_"))
    (folder / "models").mkdir()
    defaults = {"constraint_scale_m": MapSettings().constraint_scale_m,
                "lookahead_steps": MapSettings().lookahead_steps,
                "latent_dim": FitSettings().latent_dim, "sfpca_iterations": FitSettings().sfpca_iterations}
    out["defaults"] = defaults

    # -- stance models, reductions on held-out clips (test takes, and other captures' walks)
    others = user_motion_clips(sorted((DATA_ROOT / "other-skeletons").glob("*.bvh")), takeset)
    clips, models, reductions = {}, {}, {}
    for name in STANCES:
        action, primitive = parse_primitive(name)
        clips[name] = _clips(takeset, split_cfg, action, primitive)
        clips[name]["other captures"] = [c for c in others if c.primitive == primitive]
        models[name], seconds = _fit(clips[name], {"data": "bandai", "variant": "all"})
        m = models[name]
        row = compare_reductions(clips[name]["train"], {p: clips[name][p] for p in HELD_OUT},
                                 [m.latent_dim], methods=("fpca", "normalized"),
                                 num_coefficients=m.basis.num_coefficients, given={"sfpca": m.reduction})
        row["fit_seconds_loaded"] = seconds
        row["sfpca_record"] = m.meta["fit"]["reduction"]
        reductions[name] = row
    out["reductions"] = reductions
    lap("stance models and reductions")

    # -- sampling statistics and the seeded models
    seeded = {s: {name: _seeded(models[name], clips[name]["train"], s) for name in STANCES} for s in seeds}
    sampling: dict[str, Any] = {}
    for name in STANCES:
        train = clips[name]["train"]
        frames, n = pad_motions([c.frames for c in train])
        positions, _ = pad_motions([c.positions for c in train])
        normalized = np.stack([time_normalize(c.frames, models[name].length) for c in train])
        real = variance_stats(frames.numpy(), positions.numpy(), n.numpy(), normalized)
        per_seed = []
        for s in seeds:
            samples = seeded[s][name].sample(args.samples, seed=s)
            fake = variance_stats(samples.frames.numpy(), samples.positions.numpy(), samples.num_frames.numpy(),
                                  samples.normalized_frames.numpy())
            per_seed.append({"seed": s, "ratio": {k: fake[k] / real[k] for k in ("pose_sd", "v_sd", "step_sd")},
                             "gmm_components": seeded[s][name].gmm.num_components})
        sampling[name] = {"training": real, "samples": args.samples, "per_seed": per_seed,
                          "ratio": {k: spread(r["ratio"][k] for r in per_seed) for k in ("pose_sd", "v_sd", "step_sd")}}
    out["sampling"] = sampling
    lap("trees and sampling")

    # -- path following: one model per stance on the S-curve; look-ahead T over turn variants
    path: dict[str, Any] = {"one_model": [dict(seed=s, **_walk({k: {"all": v} for k, v in seeded[s].items()},
                                                               REPORT_PATH, defaults["lookahead_steps"], s, folder))
                                          for s in seeds]}
    keys = ("deviation_mean_m", "deviation_max_m", "deviation_final_m", "skating", "steps")
    path["one_model_summary"] = {k: spread(w[k] for w in path["one_model"]) for k in keys}
    if args.lookahead:
        variants: dict[str, dict[str, Any]] = {}
        variant_clips: dict[str, dict[str, dict[str, list]]] = {}
        for name in STANCES:
            for turn in TURNS:
                c = {p: select_turn(clips[name][p], turn) for p in ("train", "val", "test")}
                variant_clips.setdefault(name, {})[turn] = c
                variants.setdefault(name, {})[turn], _ = _fit(c, {"data": "bandai", "variant": turn})
        graphs = {s: {name: {turn: _seeded(variants[name][turn], variant_clips[name][turn]["train"], s)
                             for turn in TURNS} for name in STANCES} for s in seeds}
        val_rows = []
        for steps in LOOKAHEAD_CANDIDATES:
            walks = [dict(seed=s, **_walk(graphs[s], VALIDATION_PATH, steps, s, folder)) for s in seeds]
            val_rows.append({"lookahead_steps": steps, "walks": walks,
                             "deviation_mean_m": spread(w["deviation_mean_m"] for w in walks)})
        chosen = min(val_rows, key=lambda r: (round(r["deviation_mean_m"]["mean"], 4), r["lookahead_steps"]))
        s_curve = [dict(seed=s, **_walk(graphs[s], REPORT_PATH, chosen["lookahead_steps"], s, folder)) for s in seeds]
        path["lookahead"] = {
            "validation_path": VALIDATION_PATH, "candidates": val_rows, "chosen": chosen["lookahead_steps"],
            "variant_clips": {n: {t: {p: len(c) for p, c in v.items()} for t, v in d.items()}
                              for n, d in variant_clips.items()},
            "s_curve": s_curve, "summary": {k: spread(w[k] for w in s_curve) for k in keys}}
    out["path"] = path
    lap("path")

    out["keyframe"] = _part_keyframe(split, seeds, defaults)
    lap("keyframe")

    out["regression"] = _part_regression(zip_path, split_cfg, defaults)
    lap("regression")
    out["seconds_by_part_loaded"] = seconds_by_part
    return out


# -- rendering

def _scaled(s: dict[str, Any], factor: float) -> dict[str, Any]:
    return {**s, **{k: s[k] * factor for k in ("mean", "sd", "min", "max") if k in s}}


def _cm(s: dict[str, Any], digits: int = 2) -> str:
    return fmt_spread(_scaled(s, 100.0), digits)


def _pct(s: dict[str, Any]) -> str:
    return fmt_spread(_scaled(s, 100.0), 1, " %")


def _reduction_table(r: dict[str, Any]) -> str:
    rows = []
    for name, res in r["reductions"].items():
        by = {row["method"]: row for row in res["rows"]}
        for part in ("train",) + HELD_OUT:
            if part not in by["fpca"]["rmse_m"]:
                continue
            vals = [by[m]["rmse_m"][part] * 100 for m in ("fpca", "normalized", "sfpca")]
            rows.append([name.replace("walk_", ""), f"{part} ({res['clips'][part]})", str(by["sfpca"]["dims"]),
                         *[(f"**{fmt(v)}**" if v == min(vals) else fmt(v)) for v in vals]])
    return md_table(["stance", "clips", "dims", "FPCA (cm)", "normalized (cm)", "SFPCA (cm)"], rows)


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    prov = provenance_line(record)
    red, k, samp, path = r["reductions"], r["keyframe"], r["sampling"], r["path"]
    chosen = k["chosen_m"]
    test = k["test"][str(chosen)]
    runs = len(test["per_seed"])
    head_rows = []
    for name, res in red.items():
        by = {row["method"]: row["rmse_m"] for row in res["rows"]}
        for part, label in (("test", "test clips"), ("other captures", "clips of other captures")):
            if part in by["fpca"]:
                head_rows.append([f"{name}: joint RMSE on {res['clips'][part]} {label}, FPCA / normalized / SFPCA "
                                  f"({res['rows'][-1]['dims']} dims)",
                                  " / ".join(fmt(by[m][part] * 100) for m in ("fpca", "normalized", "sfpca")) + " cm"])
    head_rows.append([f"Hand_L keyframe after MAP, σ_c = {fmt(chosen * 1000, 0)} mm (chosen on val), "
                      f"{k['targets']['test']} test targets: median / p95 / max; failures (missed > 5 cm or off "
                      "the model)",
                      f"{_cm(test['median_m'])} / {_cm(test['p95_m'])} / {_cm(test['max_m'])} cm; "
                      f"{test['failures']} of {k['targets']['test'] * runs}"])
    for name, s in samp.items():
        head_rows.append([f"{name}: pose_SD / V_SD / step_SD of {s['samples']:,} samples vs training",
                          " / ".join(_pct(s["ratio"][x]) for x in ("pose_sd", "v_sd", "step_sd"))])
    one = path["one_model_summary"]
    head_rows.append(["10 m S-curve, one model per stance: mean / final deviation",
                      f"{_cm(one['deviation_mean_m'])} / {_cm(one['deviation_final_m'])} cm"])
    if "lookahead" in path:
        la = path["lookahead"]
        head_rows.append([f"10 m S-curve, turn variants, look-ahead T = {la['chosen']} (chosen on a corner path): "
                          "mean / final deviation",
                          f"{_cm(la['summary']['deviation_mean_m'])} / {_cm(la['summary']['deviation_final_m'])} cm"])
    headline = (md_table(["Morphable Graph (Bandai normal walks, split by take; mean ± sd over seeds)", "result"],
                         head_rows)
                + "\n\nSame-actor figures except the other captures' row: Bandai's test clips share the training "
                f"clips' actors, contents, style and skeleton. Details: benchmarks/morphable.md. {prov}")

    def val_mse(rec: dict[str, Any], key: str) -> str:
        return fmt(rec[key] * 1e4, 2) if key in rec else "—"

    sf = "; ".join(f"{n.replace('walk_', '')}: start {res['sfpca_record']['start']}, kept "
                   f"{res['sfpca_record'].get('kept', '—')} (val MSE of the start "
                   f"{val_mse(res['sfpca_record'], 'val_mse_start')} cm², optimized "
                   f"{val_mse(res['sfpca_record'], 'val_mse_optimized')} cm²)" for n, res in red.items())
    ks = ", ".join(str(res["K"]) for res in red.values())
    timelines = ", ".join(str(res["timeline"]) for res in red.values())
    other = " / ".join(str(res["clips"].get("other captures", 0)) for res in red.values())
    reductions = (_reduction_table(r) + f"\n\nK = {ks} (1 cm cut-off on train), canonical timeline {timelines}"
                  f" frames, SFPCA {r['defaults']['sfpca_iterations']} L-BFGS-B iterations. SFPCA: {sf}. Bold: the "
                  f"lowest of the row. Other captures: the {other} "
                  f"stance clips of the three other-skeletons walks (two 21-joint 60 fps, one 31-joint 120 fps), "
                  f"read by the user-motion reader and put on Bandai's skeleton. Deterministic given the split. {prov}")

    vrows = [[f"{fmt(v['scale_m'] * 1000, 0)} mm" + (" (chosen)" if v["scale_m"] == chosen else "")
              + (" (default when run)" if v["scale_m"] == r["defaults"]["constraint_scale_m"] else ""),
              _cm(v["median_m"]), _cm(v["p95_m"]), f"{v['missed']} / {v['off_model']}",
              f"{v['failures']} of {k['targets']['val'] * runs}"] for v in k["validation"]]
    trows = [[f"{fmt(float(sc) * 1000, 0)} mm" + (" (chosen)" if float(sc) == chosen else ""),
              _cm(t["tree_median_m"]), _cm(t["median_m"]), _cm(t["p95_m"]), _cm(t["max_m"]), _pct(t["within_2cm"]),
              f"{t['missed']} / {t['off_model']}", f"{t['failures']} of {k['targets']['test'] * runs}"]
             for sc, t in k["test"].items()]
    keyblock = (f"Validation (the choice), {k['targets']['val']} targets:\n\n"
                + md_table(["σ_c", "median after MAP (cm)", "p95 (cm)", "missed (> 5 cm) / off the model",
                            "failures, all seeds"], vrows)
                + f"\n\nTest, {k['targets']['test']} targets (the mixture's mean motion misses them by "
                f"{fmt(k['mean_motion_median_m']['test'] * 100)} cm, median):\n\n"
                + md_table(["σ_c", "tree candidate, median (cm)", "median after MAP (cm)", "p95 (cm)", "max (cm)",
                            "≤ 2 cm", "missed / off the model", "failures"], trows)
                + ("\n\nThe chosen σ_c is the smallest candidate: smaller values were not tried."
                   if chosen == min(k["candidates_m"]) else "")
                + "\n\nOff the model: met by a code whose −ln p is above the 99th percentile of 10,000 of the "
                "mixture's own samples (a motion the model does not hold; a small σ_c reaches far targets that way)."
                + f"\n\nModel: {k['train_clips_normal']} normal train clips, defaults. Targets: the final Hand_L of "
                f"every style's raise clips (val {k['clips']['val']}, test {k['clips']['test']}), so some lie "
                f"outside the normal style's reach. {prov}")

    srows = [[n, str(len(s["per_seed"])), *[_pct(s["ratio"][x]) for x in ("pose_sd", "v_sd", "step_sd")],
              ", ".join(str(p["gmm_components"]) for p in s["per_seed"])] for n, s in samp.items()]
    sampling = (md_table(["stance", "seeds", "pose_SD", "V_SD", "step_SD", "GMM components per seed"], srows)
                + "\n\nRatios of the samples' statistics to the train clips'; per seed the mixture's EM and the "
                f"draws differ. {prov}")

    graphs = [("one model per stance", one)]
    if "lookahead" in path:
        graphs.append((f"turn variants, T = {path['lookahead']['chosen']}", path["lookahead"]["summary"]))
    prow = [[label, _cm(s["deviation_mean_m"]), _cm(s["deviation_max_m"]), _cm(s["deviation_final_m"]),
             _pct(s["skating"]), fmt_spread(s["steps"], 1)] for label, s in graphs]
    pathblock = md_table(["graph (S-curve, 10 m)", "mean dev. (cm)", "max dev. (cm)", "final dev. (cm)",
                          "foot skating", "steps"], prow)
    if "lookahead" in path:
        la = path["lookahead"]
        lrows = [[str(c["lookahead_steps"]) + (" (chosen)" if c["lookahead_steps"] == la["chosen"] else "")
                  + (" (default when run)" if c["lookahead_steps"] == r["defaults"]["lookahead_steps"] else ""),
                  _cm(c["deviation_mean_m"]), ", ".join(fmt(w["deviation_max_m"] * 100) for w in c["walks"])]
                 for c in la["candidates"]]
        pathblock += ("\n\nThe choice of T on the validation path (a corner: 3 m straight, an 86.5° bend, 3 m "
                      "straight):\n\n" + md_table(["T", "mean deviation (cm)", "max deviation per seed (cm)"], lrows))
    pathblock += f"\n\nSeeds change the mixture's EM and the tree's 10,000 codes. {prov}"

    reg = r["regression"]
    regblock = (f"Small raise model ({reg['settings']}; {reg['slice']}), {reg['clips']['val']} val clips: joint RMSE "
                f"{fmt(reg['val_joint_rmse_m'] * 100, 3)} cm; largest Hand_L keyframe error after MAP at σ_c = "
                f"{fmt(REGRESSION_SCALE_M * 1000, 0)} mm "
                f"{fmt(reg['val_keyframe_max_m'] * 100, 3)} cm ({reg['val_keyframe_failures']} failures). {prov}")
    return {"headline": headline, "reductions": reductions, "keyframe": keyblock, "sampling": sampling,
            "path": pathblock, "regression": regblock}
