"""Suite ``style``: the style models of Du ch. 5 (per-primitive VAEs, Gram-matrix style CVAEs), over seeds.

For each seed, ``stylemotion-reproduce seed=<k> out=runs/benchmarks/style/<data>/seed<k>`` runs through its library
entry (:func:`stylemotion.training.reproduction.reproduce`, stages reused when that folder already finished them, an
interrupted one resumed) and the suite reads its ``report/report.json``: Table 5.1's diagonal (rows and columns whose
nearest model/example is their own), the style classifier's recognition of the samples, and the variation figures
(pose/V/step SD relative to the training data, pose_across_SD and the models' variation relative to real clips of
their own style). Figures are mean ± sd and min–max over seeds; the seed changes the models' initialization, batches
and samples, not the data or its split (``data.split``: by take, seeded separately and recorded).

``--data synthetic`` (default) is the embedded synthetic set: a smoke test of the pipeline, never evidence that the
method works. ``--data bandai`` runs Bandai dataset-2's walks (30–60 min per seed on 2 cores).
"""

from __future__ import annotations

import argparse
from collections.abc import Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from pathlib import Path
from typing import Any

from suites.common import DATA_ROOT, fmt, fmt_range, fmt_spread, md_table, progress_printed, provenance_line, spread

DESCRIPTION = "style VAEs/CVAEs (Du ch. 5): Table 5.1 diagonal, recognition and variation over seeds"
DEFAULT_SEEDS = (0, 1, 2)
ROOT = Path(__file__).resolve().parents[2]
#: The reproduction's data overrides per ``--data``.
DATA = {
    "synthetic": ["data=synthetic"],
    "bandai": ["data=bandai", f"data.root={DATA_ROOT / 'bandai-namco-motion-2' / 'data.zip'}",
               "data.contents=[walk,walk-turn-left,walk-turn-right]"],
    # suite primitive_vaes (Du Fig. 5.4): runs and an arm action
    "bandai_run_arm": ["data=bandai", f"data.root={DATA_ROOT / 'bandai-namco-motion-2' / 'data.zip'}",
                       "data.contents=[run,raise-up-right-hand]"],
}
#: ``--report-on``: the report's folder in the run and the ``reproduce`` overrides that make it.
REPORTS = {"all": ("report", []),
           "test": ("report_test", ["report=report_test", "evaluation.heldout_splits=[test]",
                                    "evaluation.style_truth=heldout"])}
#: Variation figures of the report (``variance_ratio``: model / training data; ``variation_vs_style``: model /
#: real clips of its own style).
RATIOS = ("pose_sd", "v_sd", "step_sd")
VS_STYLE = ("pose_across_sd", "v_sd", "step_sd", "diversity")
#: Raw foot skating in the report (``foot_skating_detail``, of a model's samples and of its ground-truth real clips):
#: the share of contact foot-frames that slide, the share of motions whose stance foot never plants, and the stance
#: foot's speed over the middle half of the motion (m/s).
SKATING = ("ratio", "no_plant_share", "planted_mid_mps")
#: The autoencoder's test figures in the report: MPJPE integrated from the root and root-local (m), windows.
AUTOENCODER = ("test_mpjpe_m", "test_local_mpjpe_m", "test_windows", "window_frames")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--data", choices=sorted(DATA), default="synthetic",
                        help="synthetic: the embedded set (smoke evidence only); bandai: dataset-2 walks (slow)")
    parser.add_argument("--runs", type=Path, default=ROOT / "runs" / "benchmarks" / "style",
                        help="folder of the per-seed reproduction runs (reused and resumed)")
    parser.add_argument("--workers", type=int, default=2, help="training stages at once (the reproduction's workers)")
    parser.add_argument("--primitives", nargs="+", default=None,
                        help="stance primitives (default: the reproduction's, both walk stances)")
    parser.add_argument("--sample-styles", type=int, default=None, metavar="K",
                        help="train CVAEs for K styles only, a seeded choice (numpy default_rng(0)) fixed across seeds "
                             "(default: every style, as the thesis)")
    parser.add_argument("--report-on", choices=sorted(REPORTS), default="all",
                        help="all: the run's report (a style model judged against every clip of its style but its "
                             "example); test: a second report of the same stages (report_test) that reads test-split "
                             "clips only (classifier held-out accuracy, ground truths)")
    parser.add_argument("--alphas", type=float, nargs="+", default=None, metavar="ALPHA",
                        help="choose the style weight α among these on validation clips first "
                             "(stylemotion/training/style_weight.py), then report every seed with the choice "
                             "(default: no choice, the config's α)")
    parser.add_argument("--alpha-styles", type=int, default=2, metavar="K",
                        help="styles the α candidates are trained for (a seeded choice, numpy default_rng(1))")
    parser.add_argument("--alpha-seed", type=int, default=100,
                        help="training seed of the α candidates (not one of the reported seeds)")


def compose_reproduce(overrides: list[str]):
    """The ``reproduce`` config composed with ``overrides`` (Hydra's global config search left initialized)."""
    from hydra import compose, initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    from stylemotion.cli.schemas import register_schemas_for
    from stylemotion.config import config_dir

    register_schemas_for("reproduce")
    GlobalHydra.instance().clear()
    initialize_config_dir(config_dir(), version_base="1.3")
    return compose("reproduce", overrides=overrides)


def sample_styles(data: str, k: int | None) -> list[str] | None:
    """``k`` of the data's non-neutral styles, a seeded choice (``default_rng(0)``, the same for every seed),
    sorted; None (every style) when ``k`` is None or not smaller than their number."""
    if k is None:
        return None
    import numpy as np
    from omegaconf import OmegaConf

    from stylemotion.datasets import build_dataset

    cfg = compose_reproduce(DATA[data])
    styles = [s for s in build_dataset(OmegaConf.to_container(cfg.data, resolve=True)).label_values("style")
              if s != cfg.evaluation.neutral_style]
    if k >= len(styles):
        return None
    return sorted(np.random.default_rng(0).choice(styles, k, replace=False).tolist())


def setup_tag(primitives: list[str] | None, styles: list[str] | None) -> str:
    """The run folder's name for a setup: ``full``, or the primitives and styles it was narrowed to."""
    parts = [*(primitives or []), *(styles or [])]
    return "_".join(parts) if parts else "full"


def reproduce_overrides(data: str, seed: int, out: Path, workers: int, primitives: list[str] | None = None,
                        styles: list[str] | None = None, alpha: float | None = None) -> list[str]:
    """The ``reproduce`` overrides of one seed's run (``alpha``: the CVAEs' style weight, else the config's)."""
    overrides = [*DATA[data], f"seed={seed}", f"out={out}", f"workers={workers}", "threads=1"]
    if primitives:
        overrides.append(f"primitives=[{','.join(primitives)}]")
    if styles is not None:
        overrides.append(f"styles=[{','.join(styles)}]")
    if alpha is not None:
        overrides.append(f"budget.cvae.style_weight={alpha}")
    return overrides


def reproduce_seed(data: str, seed: int, out: Path, workers: int, primitives: list[str] | None = None,
                   styles: list[str] | None = None, alpha: float | None = None, extra: Sequence[str] = (),
                   stages: Mapping[str, Sequence[str]] | None = None) -> dict[str, Any]:
    """Run (or reuse) ``stylemotion-reproduce`` for ``seed`` into ``out``; returns its ``report.json``.
    ``extra``: more ``reproduce`` overrides (e.g. ``evaluation.*``); ``stages``: stage kind (``autoencoder``,
    ``vae``, ``cvae``) → ``train`` overrides appended to that kind's (``stages.<kind>``)."""
    from hydra.core.global_hydra import GlobalHydra

    from stylemotion.io.jsonfile import read_json_object
    from stylemotion.training.reproduction import reproduce

    cfg = compose_reproduce([*reproduce_overrides(data, seed, out, workers, primitives, styles, alpha), *extra])
    for kind, overrides in (stages or {}).items():
        cfg.stages[kind].extend(overrides)
    try:
        with progress_printed(f"[seed {seed}]"):
            reproduce(cfg)
    finally:
        GlobalHydra.instance().clear()
    return read_json_object(out / str(cfg.report) / "report.json", "the reproduction's report", "rerun the suite")


def stage_minutes(stages: Sequence[Mapping[str, Any]], kind: str | None = None) -> float:
    """Training minutes summed over a reproduction's recorded stages (``reproduce.json``'s ``stages``), of one
    ``kind`` (``autoencoder``, ``vae``, ``cvae``) or all; a reused stage counts the seconds it took when trained."""
    return sum(float(st.get("seconds") or 0) for st in stages if kind is None or st.get("kind") == kind) / 60


def train_candidate(container: dict[str, Any], folder: str) -> dict[str, float]:
    """Train one α candidate (a resolved ``train`` config) into ``folder``, or reuse its recorded result; returns
    its validation metrics at the best ``val/loss`` epoch (``metrics.json``'s ``val``). Runs in a worker process."""
    from omegaconf import OmegaConf

    from stylemotion.io.jsonfile import read_json_object, write_json
    from stylemotion.training.fit import run as train_run
    from stylemotion.training.style_weight import prior_sample_figures

    path = Path(folder)
    record = path / "candidate.json"
    if record.is_file():
        val = dict(read_json_object(record, "an α candidate's record", f"delete {path}")["val"])
    else:
        train_run(OmegaConf.create(container))
        val = dict(read_json_object(path / "metrics.json", "an α candidate's metrics", f"delete {path}").get("val")
                   or {})
    if "samples/pose_across_sd" in val and "samples/style" in val:
        return val
    # trained now, or recorded before the rules read the prior samples' figures
    val.update(prior_sample_figures(path / "checkpoints" / "best.ckpt", seed=int(container.get("seed", 0))))
    write_json(record, {"val": val})
    return val


def choose_alpha(args: argparse.Namespace, seed: int, primitives: list[str] | None,
                 styles: list[str] | None) -> dict[str, Any]:
    """Choose α among ``args.alphas`` on validation clips (stylemotion/training/style_weight.py): CVAEs of
    ``args.alpha_styles`` seeded styles, trained with seed ``args.alpha_seed`` on the autoencoder of the reported
    ``seed``'s run (trained here first, the same stage the seed's reproduction then reuses)."""
    from stylemotion.training.style_weight import METRICS

    candidates = {float(a): [f"model.style_weight={a}"] for a in sorted(args.alphas)}
    choice = choose_cvae_setting(args, seed, primitives, styles, candidates, "alpha", METRICS,
                                 folder=lambda a: f"alpha{a:g}")
    return {**choice, "candidates": sorted(args.alphas),
            "values": {f"{a:g}": v for a, v in choice["values"].items()},
            "scores": {f"{a:g}": choice["scores"][a] for a in sorted(choice["scores"])},
            "rule": "min over α of the mean over styles of log(val/style ÷ min) + log(val/mpjpe ÷ min) + "
                    "log(max ÷ samples/pose_across_sd) (stylemotion/training/style_weight.py)"}


def candidate_overrides(stage: list[str], candidate: list[str]) -> list[str]:
    """The reproduction's CVAE stage overrides with the candidate's keys replaced by its values, and no sample GIFs
    (nothing reads them when choosing)."""
    keys = {o.split("=", 1)[0] for o in [*candidate, "callbacks.samples=null"]}
    return [o for o in stage if o.split("=", 1)[0] not in keys] + [*candidate, "callbacks.samples=null"]


def choose_cvae_setting(args: argparse.Namespace, seed: int, primitives: list[str] | None,
                        styles: list[str] | None, candidates: dict[Any, list[str]], subfolder: str,
                        metrics: dict[str, bool], folder: Any = str) -> dict[str, Any]:
    """Choose among CVAE settings on validation clips by :func:`~stylemotion.training.style_weight.
    choose_style_weight` over ``metrics``: each candidate (name → ``model.*`` overrides) trains CVAEs of
    ``args.alpha_styles`` seeded styles with seed ``args.alpha_seed`` on the autoencoder of the reported ``seed``'s
    run (trained here first, the same stage the seed's reproduction then reuses), into
    ``<runs>/<setup>/<subfolder>/seed<alpha_seed>/<folder(name)>/<primitive>_<style>`` (finished ones reused)."""
    import numpy as np
    from hydra.core.global_hydra import GlobalHydra
    from omegaconf import OmegaConf

    from stylemotion.training.reproduction import Reproduction, stage_train_config
    from stylemotion.training.style_weight import choose_style_weight, style_weight_scores

    base = args.runs / args.data / setup_tag(primitives, styles)
    cfg = compose_reproduce(reproduce_overrides(args.data, seed, base / f"seed{seed}", 1, primitives, []))
    try:
        repro = Reproduction(cfg)
        repro.out.mkdir(parents=True, exist_ok=True)
        repro.data_stage()
        autoencoder = repro.stages[0]
        repro.run_stage(2, autoencoder)
        pool = styles or [s for s in repro.data_summary["styles"] if s != str(cfg.evaluation.neutral_style)]
        chosen_styles = sorted(np.random.default_rng(1).choice(pool, min(args.alpha_styles, len(pool)),
                                                               replace=False).tolist())
        stage = [str(o) for o in OmegaConf.to_container(cfg.stages.cvae, resolve=True)]
        jobs = {}
        for name, overrides in candidates.items():
            for primitive in repro.primitives:
                for style in chosen_styles:
                    out = base / subfolder / f"seed{args.alpha_seed}" / folder(name) / f"{primitive}_{style}"
                    train_cfg = stage_train_config(candidate_overrides(stage, overrides),
                                                   {"primitive": primitive, "style": style},
                                                   repro.data_cfg, out, args.alpha_seed, 1, str(autoencoder.checkpoint))
                    jobs[(name, f"{primitive}/{style}")] = (OmegaConf.to_container(train_cfg, resolve=True), str(out))
    finally:
        GlobalHydra.instance().clear()
    values: dict[Any, dict[str, dict[str, float]]] = {}
    with ProcessPoolExecutor(max_workers=max(1, args.workers), mp_context=get_context("spawn")) as pool:
        futures = {key: pool.submit(train_candidate, *job) for key, job in jobs.items()}
        for (name, clip), future in futures.items():
            val = future.result()
            print(f"[{subfolder} {folder(name)}] {clip}: " + ", ".join(f"{m} {val.get(m)}" for m in metrics),
                  flush=True)
            values.setdefault(name, {})[clip] = {m: val.get(m) for m in metrics}
    return {"styles": chosen_styles, "seed": args.alpha_seed, "autoencoder_of_seed": seed, "values": values,
            "scores": style_weight_scores(values, metrics), "chosen": choose_style_weight(values, metrics)}


def seed_figures(report: dict[str, Any]) -> dict[str, Any]:
    """The figures of one seed's report: per primitive, Table 5.1's diagonal counts, recognition, variation."""
    out: dict[str, Any] = {"primitives": {}}
    for primitive, table in report["table_5_1"].items():
        diag = table["diagonal"]
        models = list(table["models"])
        rows, columns = len(diag["rows"]), len(diag["columns"])  # names whose row / column minimum is their own
        out["primitives"][primitive] = {
            "models": len(models), "diagonal_rows": rows, "diagonal_columns": columns,
            "recognition": {m: d["share"]
                            for m, d in report["style_recognition"]["per_model_detail"][primitive].items()},
            "classifier": {k: report["style_recognition"]["per_primitive"][primitive][k]
                           for k in ("heldout_accuracy", "heldout_clips", "train_clips")},
            "variance_ratio": {m: {k: v[k] for k in RATIOS} for m, v in report["variance_ratio"][primitive].items()
                               if m != "training_data"},
            "variation_vs_style": {m: {k: v.get(k) for k in VS_STYLE}
                                   for m, v in report["variation_vs_style"][primitive].items()},
            "foot_skating": {m: {side: {k: (d.get(side) or {}).get(k) for k in SKATING} for side in ("samples", "real")}
                             for m, d in (report.get("foot_skating_detail") or {}).get(primitive, {}).items()},
        }
    out["recognition_per_model"] = dict(report["style_recognition"]["per_model"])
    out["classifier_heldout_accuracy"] = report["style_recognition"]["classifier_heldout_accuracy"]
    out["autoencoder"] = {k: report["autoencoder"].get(k) for k in AUTOENCODER}
    out["split"] = report["meta"]["data"].get("split")
    return out


def skating_spread(figures: list[dict[str, dict[str, float | None]]]) -> dict[str, Any]:
    """Spreads over seeds of one model's skating figures (:data:`SKATING` of its samples and its real clips) and of
    its samples' sliding share over its real clips' (``times_real``; None where the real clips never slide)."""
    out = {f"{side}_{k}": spread(f[side][k] for f in figures) for side in ("samples", "real") for k in SKATING}
    out["times_real"] = spread(f["samples"]["ratio"] / f["real"]["ratio"] if f["samples"]["ratio"] is not None
                               and f["real"]["ratio"] else None for f in figures)
    return out


def skating_line(r: dict[str, Any], seeds: int, label: str, prov: str) -> str:
    """One paragraph of block ``skating``: per primitive, the neutral model's and the range of the styled models'
    sliding share over their real clips', and the largest never-planted share of styled samples (means over seeds)."""
    parts = []
    for p in r["primitives"]:
        skating = r["summary"][p].get("foot_skating", {})
        styled = {m: k for m, k in skating.items() if m != "neutral" and ":" not in m}
        times = [k["times_real"]["mean"] for k in styled.values() if k["times_real"]["mean"] is not None]
        never = [k["samples_no_plant_share"]["mean"] for k in styled.values()]
        neutral = skating.get("neutral", {}).get("times_real", {}).get("mean")
        parts.append(f"{p}: neutral VAE {fmt(neutral, 1)}×, style CVAEs {fmt(min(times, default=None), 1)}–"
                     f"{fmt(max(times, default=None), 1)}× (stance foot never planted in up to "
                     f"{fmt(max(never, default=None), 2)} of a CVAE's samples)")
    return (f"{label}Raw foot skating of samples ÷ that of the real clips each model is judged against ({r['data']}, "
            f"{seeds} seeds, means over seeds; issue 27's aim ≤ 1.5×): " + "; ".join(parts) + f". {prov}")


def summarize(per_seed: dict[str, dict[str, Any]]) -> tuple[dict[str, Any], dict[str, Any]]:
    """Spreads over seeds of :func:`seed_figures`: per primitive (``summary``) and over all (``overall``)."""
    first = next(iter(per_seed.values()))
    primitives = list(first["primitives"])
    summary: dict[str, Any] = {}
    for p in primitives:
        figs = [s["primitives"][p] for s in per_seed.values()]
        models = list(figs[0]["variance_ratio"])
        summary[p] = {
            "models": figs[0]["models"],
            "diagonal_rows": spread(f["diagonal_rows"] for f in figs),
            "diagonal_columns": spread(f["diagonal_columns"] for f in figs),
            "classifier_heldout_accuracy": spread(f["classifier"]["heldout_accuracy"] for f in figs),
            # rows without a recognition or a style of their own (the shift baselines shift:<style>) are left out
            # of those tables, not shown as missing figures
            "recognition": {m: spread(f["recognition"].get(m) for f in figs) for m in models
                            if m in figs[0]["recognition"]},
            "variance_ratio": {m: {k: spread(f["variance_ratio"][m][k] for f in figs) for k in RATIOS}
                               for m in models},
            "variation_vs_style": {m: {k: spread(f["variation_vs_style"].get(m, {}).get(k) for f in figs)
                                       for k in VS_STYLE} for m in models if m in figs[0]["variation_vs_style"]},
            # results recorded before the suite read the skating figures have none
            "foot_skating": {m: skating_spread([f["foot_skating"][m] for f in figs if m in f.get("foot_skating", {})])
                             for m in figs[0].get("foot_skating", {})},
        }
    styled = [m for m in first["recognition_per_model"] if m != "neutral"]
    overall = {
        "recognition_mean_styled": spread(sum(s["recognition_per_model"][m] for m in styled) / len(styled)
                                          for s in per_seed.values()),
        "classifier_heldout_accuracy": spread(s["classifier_heldout_accuracy"] for s in per_seed.values()),
        "autoencoder": {k: spread(s["autoencoder"][k] for s in per_seed.values()) for k in AUTOENCODER[:2]},
    }
    return summary, overall


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch

    torch.set_num_threads(1)
    styles = sample_styles(args.data, args.sample_styles)
    alpha_choice = choose_alpha(args, seeds[0], args.primitives, styles) if getattr(args, "alphas", None) else None
    alpha = alpha_choice["chosen"] if alpha_choice else None
    per_seed = {}
    report_on = getattr(args, "report_on", "all")
    for seed in seeds:
        out = args.runs / args.data / setup_tag(args.primitives, styles) / f"seed{seed}"
        report = reproduce_seed(args.data, seed, out, args.workers, args.primitives, styles, alpha,
                                extra=REPORTS[report_on][1])
        from stylemotion.io.jsonfile import read_json_object

        stages = read_json_object(out / "reproduce.json", "the reproduction's summary", "rerun the suite")["stages"]
        per_seed[str(seed)] = seed_figures(report) | {
            "run": str(out.relative_to(ROOT) if out.is_relative_to(ROOT) else out),
            # training time of the stages (also when an earlier command trained them and this one reused them)
            "stage_minutes": round(stage_minutes(stages), 1),
            "stage_status": sorted({str(st.get("status")) for st in stages})}
    first = next(iter(per_seed.values()))
    primitives = list(first["primitives"])
    summary, overall = summarize(per_seed)
    split = first["split"] or {}
    clips = {p: first["primitives"][p]["classifier"] for p in primitives}
    subsample = {"primitives": args.primitives, "styles": styles,
                 "how": None if not (args.primitives or styles) else
                 "CVAE styles: a seeded choice (numpy default_rng(0)) of the data's styles, the same for every seed"
                 if styles else "primitives narrowed on the command line"}
    held = "test" if report_on == "test" else "val+test"
    truth = ("the test-split clips of the model's style" if report_on == "test"
             else "all real clips of the model's style")
    return {"data": args.data, "subsample": subsample, "report_on": report_on,
            "splits": {"data": {"kind": "by take", **split, "group_by": ["content", "style"]},
                       "seed_varies": "model initialization, batches and samples (not the data or its split)",
                       "classifier": "fitted on the train-split clips of every style; its accuracy and the samples' "
                                     f"recognition are read against it (held-out accuracy on the {held} clips)",
                       "table_5_1": "each model's samples against each style's example clip (the CVAE's training "
                                    "example; neutral: the mean of the neutral train clips) — not a held-out figure",
                       "variation": "model samples against the neutral train clips (variance_ratio) and "
                                    f"{truth} (variation_vs_style)",
                       "clips": clips,
                       "chosen_here": (f"α = {alpha:g}, chosen on validation clips (alpha_choice)" if alpha_choice
                                       else "nothing: α (chosen by suite style_alpha) and the style-term "
                                            "options are the configs' defaults")},
            "alpha_choice": alpha_choice,
            "primitives": primitives, "summary": summary, "overall": overall, "per_seed": per_seed}


def alpha_blocks(choice: dict[str, Any], prov: str) -> dict[str, str]:
    """The ``alpha`` block: every candidate's validation figures per style, its score and the choice."""
    names = sorted({n for per in choice["values"].values() for n in per})
    rows = [[f"**{a}**" if float(a) == choice["chosen"] else a,
             *(f"{fmt(v[n]['val/style'], 2)} / {fmt(v[n]['val/mpjpe'], 4)} / "
               f"{fmt(v[n].get('samples/pose_across_sd'), 2)}" if n in v else "failed" for n in names),
             fmt(choice["scores"][a], 3)]
            for a, v in choice["values"].items()]
    return {"alpha": (f"Style weight α chosen on **validation** clips before any figure was reported with it: CVAEs "
                      f"of {', '.join(names)} trained with seed {choice['seed']} (not a reported seed) on the "
                      f"autoencoder of seed {choice['autoencoder_of_seed']}'s run; each cell is val/style (Gram "
                      f"distance to the example) / val/mpjpe (m, reconstruction of held-out neutral clips) at the best "
                      f"val/loss epoch / pose_across_SD (cm) of 256 prior samples of that checkpoint. Rule: "
                      f"{choice['rule']}. Chosen: α = "
                      f"{choice['chosen']:g}.\n\n"
                      + md_table(["α", *names, "score (lower is better)"], rows) + f"\n\n{prov}")}


def autoencoder_block(r: dict[str, Any], seeds: int, prov: str) -> str:
    """The ``autoencoder`` block: the reproduction's autoencoder on test-split windows, per seed and over seeds."""
    o = r["overall"]["autoencoder"]
    first = next(iter(r["per_seed"].values()))["autoencoder"]
    rows = [[k, fmt(100 * v["autoencoder"]["test_mpjpe_m"], 2), fmt(100 * v["autoencoder"]["test_local_mpjpe_m"], 2)]
            for k, v in r["per_seed"].items()]

    def cm(sp: dict[str, Any]) -> str:
        return (f"{fmt(100 * sp['mean'], 2)} ± {fmt(100 * sp['sd'], 2)} "
                f"({fmt(100 * sp['min'], 2)}–{fmt(100 * sp['max'], 2)})") if sp.get("n") else "—"

    rows.append([f"**mean ± sd (min–max), {seeds} seeds**", cm(o["test_mpjpe_m"]), cm(o["test_local_mpjpe_m"])])
    windows = f"{first['test_windows']} windows of {first['window_frames']} frames"
    return (f"The reproduction's motion autoencoder (Du §5.3.1) on the **test** split's windows ({windows}, "
            f"{r['data']}): MPJPE in cm, integrated from the root over the window (root drift counts) and "
            "root-local (the pose alone). The seed varies initialization and batches; the data split is fixed. "
            "The autoencoder is trained as the reproduction's budget at the recorded commit says (schedule and "
            "epochs: configs/experiment/autoencoder.yaml and the budget; which data chose them: docs/style.md, "
            "\"Defaults\").\n\n"
            + md_table(["seed", "MPJPE integrated (cm)", "MPJPE root-local (cm)"], rows) + f"\n\n{prov}")


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    seeds = len(record.get("seeds", []))
    label = ("**Synthetic data: a smoke test of the pipeline, not evidence that the method works.** "
             if r["data"] == "synthetic" else "")
    split = r["splits"]["data"]
    sub = r.get("subsample") or {}
    if sub.get("primitives") and not sub.get("styles"):
        label += (f"**Primitives {', '.join(sub['primitives'])} only** (every style; the thesis' Table 5.1 "
                  "primitive; the other stance is not trained here). ")
    elif sub.get("styles") or sub.get("primitives"):
        label += ("**Subsampled to fit the machine** (not the thesis' full setup: a smaller Table 5.1 is easier): "
                  + (f"CVAE styles {', '.join(sub['styles'])} (a seeded choice, the same for every seed)"
                     if sub.get("styles") else "every style")
                  + (f", primitives {', '.join(sub['primitives'])}" if sub.get("primitives") else "") + ". ")
    test_only = r.get("report_on") == "test"
    split_line = (f"Data split by take (seed {split.get('seed')}, val {split.get('val_fraction')}, test "
                  f"{split.get('test_fraction')}); the seed varies training and sampling only. The classifier is "
                  f"fitted on train-split clips and scored on {'test' if test_only else 'val+test'} clips; "
                  + ("every figure against real clips reads the **test split only** (`report=report_test "
                     "evaluation.heldout_splits=[test] evaluation.style_truth=heldout`: no clip a validation choice "
                     "read); " if test_only else "")
                  + "Table 5.1 compares samples with the CVAE's own training example (not a held-out figure).")
    prov = provenance_line(record)

    rows = []
    for p in r["primitives"]:
        s = r["summary"][p]
        rows.append([p, f"{s['models']}", f"{fmt_spread(s['diagonal_rows'], 2)} ({fmt_range(s['diagonal_rows'], 0)})",
                     f"{fmt_spread(s['diagonal_columns'], 2)} ({fmt_range(s['diagonal_columns'], 0)})",
                     f"{fmt_spread(s['classifier_heldout_accuracy'], 3)}"])
    o = r["overall"]
    judged = ", judged on the **test split**" if test_only else ""
    headline = (f"{label}Style CVAEs ({r['data']}, {seeds} seeds{judged}): Table 5.1 diagonal and recognition.\n\n"
                + md_table(["primitive", "models", "Table 5.1 rows on diagonal, mean ± sd (min–max)",
                            "columns on diagonal", "classifier held-out accuracy"], rows)
                + f"\n\nRecognition of the styled models' samples (mean over styles): "
                  f"{fmt_spread(o['recognition_mean_styled'], 3)} "
                  f"(min–max {fmt_range(o['recognition_mean_styled'], 3)}). "
                + split_line + " "
                + (f"α = {r['alpha_choice']['chosen']:g}, chosen on validation clips by this command (block alpha). "
                   if r.get("alpha_choice") else "α: the config default, chosen on Bandai validation clips by suite "
                   "style_alpha; the style-term options: the configs' defaults. ")
                + prov)

    blocks = {"headline": headline}
    if r.get("alpha_choice"):
        blocks |= alpha_blocks(r["alpha_choice"], prov)
    recog_rows, ratio_rows, vs_rows = [], [], []
    for p in r["primitives"]:
        s = r["summary"][p]
        for m, sp in s["recognition"].items():
            recog_rows.append([p, m, fmt_spread(sp, 3), fmt_range(sp, 3)])
        for m, ks in s["variance_ratio"].items():
            ratio_rows.append([p, m, *(f"{fmt_spread(ks[k], 2)} ({fmt_range(ks[k], 2)})" for k in RATIOS)])
        for m, ks in s["variation_vs_style"].items():
            vs_rows.append([p, m, *(f"{fmt_spread(ks[k], 2)} ({fmt_range(ks[k], 2)})" for k in VS_STYLE)])
    blocks["recognition"] = (f"{label}Share of each model's samples the style classifier assigns to the model's "
                             f"style ({r['data']}, {seeds} seeds).\n\n"
                             + md_table(["primitive", "model", "mean ± sd", "min–max"], recog_rows)
                             + f"\n\n{split_line} {prov}")
    blocks["variation"] = (f"{label}Variation of the samples relative to the neutral training clips "
                           f"(pose_SD, V_SD, step_SD of the model / of the training data; mean ± sd (min–max) over "
                           f"{seeds} seeds, {r['data']}).\n\n"
                           + md_table(["primitive", "model", "pose_SD ratio", "V_SD ratio", "step_SD ratio"],
                                      ratio_rows)
                           + f"\n\n{split_line} {prov}")
    own = "the test-split clips of its own style" if test_only else "all real clips of its own style"
    blocks["variation_vs_style"] = (f"{label}Variation of each model relative to {own} "
                                    f"(pose_across_SD, V_SD, step_SD and diversity of the samples / of the real "
                                    f"clips; mean ± sd (min–max) over {seeds} seeds, {r['data']}).\n\n"
                                    + md_table(["primitive", "model", "pose_across_SD", "V_SD", "step_SD",
                                                "diversity"], vs_rows)
                                    + f"\n\n{split_line} {prov}")
    skating_rows = [[p, m, f"{fmt_spread(k['samples_ratio'], 3)} ({fmt_range(k['samples_ratio'], 3)})",
                     fmt_spread(k["real_ratio"], 3),
                     f"{fmt_spread(k['times_real'], 1)} ({fmt_range(k['times_real'], 1)})",
                     fmt_spread(k["samples_no_plant_share"], 2), fmt_spread(k["real_no_plant_share"], 2),
                     f"{fmt_spread(k['samples_planted_mid_mps'], 3)} / {fmt_spread(k['real_planted_mid_mps'], 3)}"]
                    for p in r["primitives"] for m, k in r["summary"][p].get("foot_skating", {}).items()]
    if skating_rows:
        blocks["skating"] = (f"{label}Raw foot skating of each model's samples beside the real clips it is judged "
                             f"against (the model's ground truth: docs/report.md), no clean-up pass ({r['data']}, "
                             f"{seeds} seeds; mean ± sd (min–max)). Sliding: the share of contact foot-frames whose "
                             f"planted point moves faster than the report's skate speed; never planted: the share of "
                             f"motions whose stance foot is never detected in contact (their slide is not in the "
                             f"first column); mid-stance speed: the stance foot over the middle half, m/s. Issue 27's "
                             f"aim: sliding ≤ 1.5× the real clips'.\n\n"
                             + md_table(["primitive", "model", "sliding, samples", "sliding, real",
                                         "samples ÷ real", "never planted, samples", "never planted, real",
                                         "mid-stance speed, samples / real"], skating_rows)
                             + f"\n\n{split_line} {prov}")
        blocks["skating_line"] = skating_line(r, seeds, label, prov)
    if "autoencoder" in o:  # results recorded before the suite read the autoencoder's figures have none
        blocks["autoencoder"] = autoencoder_block(r, seeds, prov)
    per_seed_rows = [[k, p, f"{v['primitives'][p]['diagonal_rows']}/{v['primitives'][p]['models']}",
                      f"{v['primitives'][p]['diagonal_columns']}/{v['primitives'][p]['models']}",
                      fmt(v['primitives'][p]['classifier']['heldout_accuracy'], 3), v["run"]]
                     for k, v in r["per_seed"].items() for p in r["primitives"]]
    minutes = [v.get("stage_minutes") for v in r["per_seed"].values()]
    blocks["per_seed"] = (md_table(["seed", "primitive", "rows on diagonal", "columns on diagonal",
                                    "classifier held-out accuracy", "run folder"], per_seed_rows)
                          + f"\n\nTraining stages took {', '.join(fmt(m, 1) for m in minutes)} min per seed, summed "
                          f"over stages (the reproduction trains several at once, so its wall time is shorter; not a "
                          f"timing figure: suite reproduce_speed times the reproduction alone). The command's own "
                          f"seconds below count only what it did not reuse. {prov}")
    return blocks
