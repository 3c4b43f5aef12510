"""Suite ``zero_shot``: the zero-shot style network left one style out at a time, without leakage, over seeds.

For each seed ``k`` and each left-out style ``s`` (:func:`stylemotion.evaluation.zero_shot.leave_one_style_out`):
an autoencoder trained with seed ``k`` on the judge run's data and split minus every take of ``s`` (the run's
autoencoder stage settings), a zero-shot network trained with seed ``k`` on its features without any clip of
``s``, conditioned on the example clip(s) of the run's CVAE of ``s``; its samples (seed ``k``) decoded by its own
autoencoder and measured in the judge's space: the finished reproduction's autoencoder (Table 5.1 features) and
style classifier (fitted on train-split clips of every style), a fixed instrument as an FID network is. Beside it
the run's CVAE of ``s`` (trained on s's example: a supervised baseline, samples seeded ``k``) and s's real clips.

The judge: ``--run`` (any finished ``stylemotion-reproduce`` run), else ``stylemotion-reproduce seed=<judge seed>
out=runs/benchmarks/zero_shot/<data>/<setup>/judge<seed>`` run (or reused, resumed) through its library entry as
suite ``style`` does. Trainings land under ``runs/benchmarks/zero_shot/<data>/loso_<judge>[_e<epochs>]/seed<k>/``
and are reused when the suite runs again, also with other ``--styles`` (an interrupted one resumes).

``--data synthetic`` (default) is the embedded synthetic set: a smoke test of the pipeline, never evidence.
``--data bandai`` (or suite ``zero_shot_bandai``) Bandai dataset-2's walks: about 10 min per autoencoder and 1–2 min
per network at ``--epochs 10`` on 2 loaded cores, so ~1.2 h per seed for the six styles of one primitive.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from suites.common import fmt, fmt_range, fmt_spread, md_table, progress_printed, provenance_line, spread
from suites.style import DATA, reproduce_seed, sample_styles, setup_tag

DESCRIPTION = ("zero-shot style network, leave one style out without leakage (an autoencoder and a network per "
               "left-out style that never saw it, judged by a reproduction's autoencoder and classifier), over seeds")
DEFAULT_SEEDS = (0, 1, 2)
ROOT = Path(__file__).resolve().parents[2]
#: The rows of each left-out style, and their names in the tables.
ROWS = {"zero_shot": "zero-shot network (never saw the style)", "cvae": "CVAE of the style (trained on its example)",
        "real": "real clips of the style",
        "reconstructed": "real clips through the generator's autoencoder (what its features keep of the style)"}
#: Column names of the rows.
SHORT = {"zero_shot": "zero-shot", "cvae": "CVAE", "real": "real clips", "reconstructed": "real through generator AE",
         "zero_shot_leaky": "LEAKY zero-shot"}
#: The row ``--leaky`` adds: the earlier protocol's network, on the judge's autoencoder.
LEAKY_ROW = {"zero_shot_leaky": "LEAKY: zero-shot network on the judge's autoencoder (which saw the style)"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--data", choices=sorted(DATA), default="synthetic",
                        help="synthetic: the embedded set (smoke evidence only); bandai: dataset-2 walks (slow)")
    parser.add_argument("--run", type=Path, default=None,
                        help="a finished stylemotion-reproduce run to judge with (its autoencoder, classifier and "
                             "CVAEs; default: run or reuse one under --runs with --judge-seed)")
    parser.add_argument("--judge-seed", type=int, default=0, help="seed of the judge reproduction the suite runs")
    parser.add_argument("--runs", type=Path, default=ROOT / "runs" / "benchmarks" / "zero_shot",
                        help="folder of the judge run and the per-seed trainings (reused and resumed)")
    parser.add_argument("--styles", nargs="+", default=None,
                        help="left-out styles (default: every CVAE style of the judge run; the judge the suite runs "
                             "trains CVAEs of these only)")
    parser.add_argument("--sample-styles", type=int, default=None, metavar="K",
                        help="leave out K styles only, a seeded choice (numpy default_rng(0), as suite style's "
                             "--sample-styles) instead of naming them with --styles")
    parser.add_argument("--primitives", nargs="+", default=None, help="stance primitives (default: the judge run's)")
    parser.add_argument("--epochs", type=int, default=None,
                        help="epochs of each zero-shot network (default: the zero_shot experiment's 100, early "
                             "stopped); the autoencoders train as the judge run's autoencoder stage")
    parser.add_argument("--samples", type=int, default=1000, help="samples per model and seed")
    parser.add_argument("--workers", type=int, default=2, help="training stages at once of the judge reproduction")
    parser.add_argument("--leaky", action="store_true",
                        help="also the earlier, leaky protocol per seed (networks on the judge's autoencoder, which "
                             "saw the style), as a labelled row: what the leakage changes")


def judge_run(args: argparse.Namespace) -> Path:
    """The judge: ``--run``, else the reproduction the suite runs (or reuses) under ``--runs``."""
    if args.run is not None:
        return args.run.expanduser().resolve()
    out = args.runs / args.data / setup_tag(args.primitives, args.styles) / f"judge{args.judge_seed}"
    reproduce_seed(args.data, args.judge_seed, out, args.workers, args.primitives, args.styles)
    return out


def loso_folder(args: argparse.Namespace, judge: Path) -> Path:
    """Where the seeds' trainings go: ``<runs>/<data>/loso_<judge>[_e<epochs>]``. A training depends on the judge
    run's data, split and autoencoder stage, its seed and the network epochs, not on which other styles or
    primitives are left out, so narrowed and full runs on one judge share (reuse) their trainings."""
    from stylemotion.io.outputs import safe_name

    name = safe_name(f"{judge.parent.name}_{judge.name}", "judge run folder")
    return args.runs / args.data / (f"loso_{name}" + (f"_e{args.epochs}" if args.epochs else ""))


def relative(path: Path | str) -> str:
    path = Path(path)
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def check_data(run: Path, data: str, meta_data: dict[str, Any]) -> None:
    """``--data`` must name the judge run's data (the results say which data they are)."""
    from stylemotion.evaluation.zero_shot import ZeroShotRunError

    synthetic = meta_data.get("name") == "synthetic"
    if synthetic != (data == "synthetic"):
        raise ZeroShotRunError(f"--run {run} holds {meta_data.get('name')!r} data, not --data {data}; pass "
                               f"--data {'synthetic' if synthetic else 'bandai'}")


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch

    from stylemotion.evaluation.zero_shot import leave_one_style_out, read_run

    torch.set_num_threads(1)
    how = "narrowed on the command line"
    if getattr(args, "sample_styles", None) is not None and args.styles is None:
        args.styles = sample_styles(args.data, args.sample_styles)
        how = f"{args.sample_styles} left-out styles, a seeded choice (numpy default_rng(0))"
    judge = judge_run(args)
    source = read_run(judge)
    check_data(judge, args.data, source.data_cfg)
    base = loso_folder(args, judge)
    per_seed: dict[str, Any] = {}
    for seed in seeds:
        out = base / f"seed{seed}"
        with progress_printed(f"[seed {seed}]"):
            result = leave_one_style_out(judge, out, args.styles, args.primitives, args.epochs, args.samples, seed,
                                         threads=1, resume=True)
        if getattr(args, "leaky", False):
            with progress_printed(f"[seed {seed}, leaky]"):
                leaky = leave_one_style_out(judge, base / f"seed{seed}_leaky", args.styles, args.primitives,
                                            args.epochs, args.samples, seed, threads=1, resume=True,
                                            shared_autoencoder=True)
            for p, res in leaky["primitives"].items():
                for s, row in res["styles"].items():
                    result["primitives"][p]["styles"][s]["zero_shot_leaky"] = row["zero_shot"]
            result["summary"]["zero_shot_leaky"] = leaky["summary"]["zero_shot"]
        per_seed[str(seed)] = {"out": relative(out), "primitives": result["primitives"], "summary": result["summary"],
                               "seconds": result["meta"]["seconds"]}
    first = next(iter(per_seed.values()))
    kinds = [k for k in {**ROWS, **LEAKY_ROW} if k in first["summary"]]
    left_out = [(p, s) for p, res in first["primitives"].items() for s in res["styles"]]
    per_style: dict[str, dict[str, Any]] = {}
    for p, s in left_out:
        rows = [v["primitives"][p]["styles"][s] for v in per_seed.values()]
        per_style.setdefault(p, {})[s] = {
            kind: {"recognition": spread(r[kind]["recognition"] for r in rows),
                   "own_column_is_minimum": sum(bool(r[kind]["own_column_is_minimum"]) for r in rows),
                   "nearest_columns": [r[kind]["nearest_column"] for r in rows],
                   "spread_vs_real": spread(r[kind]["pose_across_sd"] / r["real"]["pose_across_sd"] for r in rows)}
            for kind in kinds}
        per_style[p][s]["seeds"] = len(rows)
        per_style[p][s]["train_minutes"] = [
            round(((r["zero_shot"].get("train_seconds") or 0) + (r["generator_autoencoder"].get("train_seconds") or 0))
                  / 60, 1) for r in rows]
    headline = {kind: {"mean_recognition": spread(v["summary"][kind]["mean_recognition"] for v in per_seed.values()),
                       "own_column_is_minimum": spread(v["summary"][kind]["own_column_is_minimum"]
                                                       for v in per_seed.values()),
                       "rows": first["summary"][kind]["rows"]} for kind in kinds}
    classifier = {p: res["classifier"] for p, res in first["primitives"].items()}
    splits = read_splits(per_seed, base, seeds)
    return {"data": args.data, "judge": {"run": relative(judge), "seed": source.seed,
                                         "autoencoder": relative(source.autoencoder_ckpt),
                                         "cvae_styles": {p: source.styles(p) for p in source.primitives}},
            "subsample": {"primitives": args.primitives, "styles": args.styles,
                          "how": None if not (args.primitives or args.styles) else how},
            "kinds": kinds,
            "epochs": args.epochs, "samples": args.samples, "left_out": [f"{p}/{s}" for p, s in left_out],
            "splits": {**splits, "seed_varies": "the autoencoders and networks without each style (initialization, "
                                                "batches) and every model's samples; the judge run, its CVAEs and its "
                                                "classifier are fixed"},
            "classifier": classifier, "headline": headline, "per_style": per_style,
            "per_seed": {k: {"out": v["out"], "summary": v["summary"], "seconds": round(v["seconds"], 1)}
                         for k, v in per_seed.items()}}


def read_splits(per_seed: dict[str, Any], base: Path, seeds: list[int]) -> dict[str, Any]:
    """The ``splits`` record of the first seed's ``zero_shot.json`` (the same for every seed)."""
    from stylemotion.io.jsonfile import read_json_object

    record = read_json_object(base / f"seed{seeds[0]}" / "zero_shot.json", "the evaluation's results",
                              "rerun the suite")
    return dict(record["splits"])


def data_label(r: dict[str, Any], which: str = "left-out styles") -> str:
    """The label a block starts with: synthetic data (a smoke test) and narrowed styles (``which``: what
    ``r["left_out"]`` lists)."""
    label = ("**Synthetic data: a smoke test of the pipeline, not evidence that the method works.** "
             if r["data"] == "synthetic" else "")
    sub = r.get("subsample") or {}
    if sub.get("styles") or sub.get("primitives"):
        label += (f"**Narrowed to fit the machine** (not every style and primitive of the data): {which} "
                  + ", ".join(r["left_out"]) + ". ")
    return label


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    seeds = len(record.get("seeds", []))
    prov = provenance_line(record)
    label = data_label(r)
    split = r["splits"]["data"]
    protocol = (f"Each seed trains, per left-out style, an autoencoder on the judge run's data split by take (seed "
                f"{split.get('seed')}, val {split.get('val_fraction')}, test {split.get('test_fraction')}) minus every "
                f"take of the style, and a zero-shot network on its features without any clip of the style; the "
                f"network is conditioned on the example clip(s) of the run's CVAE of the style and its samples are "
                f"decoded by its own autoencoder. Every row is measured by the judge, run `{r['judge']['run']}` "
                f"(seed {r['judge']['seed']}): its style classifier (fitted on the train-split clips of every style, "
                f"the left-out one included) and its autoencoder's Gram distances (Table 5.1). The CVAE row is the "
                f"run's CVAE of the style (trained on its example: supervised); real: the style's clips but its "
                f"example. {r['samples']:,} samples per model and seed"
                + (f"; networks trained {r['epochs']} epochs" if r.get("epochs") else "") + ".")
    names = {**ROWS, **LEAKY_ROW}
    kinds = r.get("kinds") or list(ROWS)
    rows = []
    for kind in kinds:
        name = names[kind]
        h = r["headline"][kind]
        rows.append([name, f"{fmt_spread(h['mean_recognition'], 3)} ({fmt_range(h['mean_recognition'], 3)})",
                     f"{fmt_spread(h['own_column_is_minimum'], 2)} ({fmt_range(h['own_column_is_minimum'], 0)}) "
                     f"of {h['rows']}"])
    chance = {p: c.get("chance") for p, c in r["classifier"].items()}
    accuracy = ", ".join(f"{p} {fmt(c.get('heldout_accuracy'), 3)}" for p, c in r["classifier"].items())
    headline = (f"{label}Zero-shot style network, leave one style out without leakage ({r['data']}, {seeds} seeds; "
                f"left out: {', '.join(r['left_out'])}).\n\n"
                + md_table(["row", "recognition of the left-out style, mean over styles: mean ± sd (min–max)",
                            "Table 5.1 rows whose minimum is the style's own example: mean ± sd (min–max)"], rows)
                + f"\n\nThe judge's classifier: held-out accuracy {accuracy} (chance "
                  f"{', '.join(fmt(v, 3) for v in chance.values())}). {protocol} {prov}")
    style_rows = []
    for p, styles in r["per_style"].items():
        for s, v in styles.items():
            style_rows.append([p, s, *(f"{fmt_spread(v[k]['recognition'], 3)} ({fmt_range(v[k]['recognition'], 3)})"
                                       for k in kinds),
                               *(f"{v[k]['own_column_is_minimum']}/{v['seeds']}" for k in kinds),
                               *(f"{fmt_spread(v[k]['spread_vs_real'], 2)}" for k in ("zero_shot", "cvae"))])
    per_style = (f"{label}Per left-out style ({r['data']}, {seeds} seeds): recognition of the style, mean ± sd "
                 f"(min–max) over seeds; seeds whose Table 5.1 row has the style's own example as its minimum; the "
                 f"samples' spread across samples (pose_across_SD) relative to the style's real clips.\n\n"
                 + md_table(["primitive", "left-out style", *(f"{SHORT[k]} recognition" for k in kinds),
                             *(f"{SHORT[k]} own column" for k in kinds), "zero-shot spread / real",
                             "CVAE spread / real"], style_rows)
                 + f"\n\n{protocol} {prov}")
    seed_rows = [[k, *(fmt(v["summary"][kind]["mean_recognition"], 3) for kind in kinds),
                  *(f"{v['summary'][kind]['own_column_is_minimum']}/{v['summary'][kind]['rows']}" for kind in kinds),
                  v["out"]] for k, v in r["per_seed"].items()]
    minutes = [m for styles in r["per_style"].values() for v in styles.values() for m in v["train_minutes"] if m]
    per_seed = (md_table(["seed", *(f"{SHORT[k]} recognition" for k in kinds),
                          *(f"{SHORT[k]} own column" for k in kinds), "trainings"], seed_rows)
                + "\n\n" + (f"Trainings (autoencoder + network per left-out style) took {fmt(min(minutes), 1)}–"
                              f"{fmt(max(minutes), 1)} min each where this command trained them" if minutes else
                              "This command trained none of the leakage-free models: it reused those an earlier run "
                              "of it had trained")
                + f" (reused trainings are not timed; a loaded machine: no timing figure). {prov}")
    return {"headline": headline, "per_style": per_style, "per_seed": per_seed}
