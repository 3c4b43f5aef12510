"""Suite ``style_examples_cvae``: the per-style CVAE trained on k = 1, 2, 4, 8 examples of its style.

Issue 27, item 2, for the model ``stylemotion-style`` trains by default (``method=cvae``): does a style keep more of
its variation when its CVAE sees several clips of it? Suite ``style_examples`` asks the same of the zero-shot
network; this suite trains, because a CVAE is fitted to its examples' mean Gram matrix.

For each seed ``k`` the suite reads suite ``style``'s (or ``style_bandai``'s) finished reproduction
``<--runs>/seed<k>`` (read only) and, for each primitive ``p`` and style ``s`` of its CVAEs:

1. draws k example clips from the **train-split** clips of ``s`` of ``p`` exactly as suite ``style_examples`` draws
   them (:func:`suites.style_examples.draw_examples`: one seeded permutation per seed, primitive and style, its
   first k; the draws are nested, and the same seed gives both suites the same clips);
2. trains a CVAE of ``s`` exactly as the run's CVAE stage (its overrides, data, autoencoder and seed:
   :func:`stylemotion.style_example.base_run.train_config`, as ``stylemotion-style`` does) with those k clips as its
   examples (``datamodule.examples``, each named by take, start frame, content and split; the style term's target
   is their mean Gram matrix), one thread per training, ``--workers`` at once, into
   ``<--train-dir>/seed<k>/<p>_<s>_k<k>`` (a finished training is reused, an interrupted one resumes);
3. draws ``--samples`` samples (seed ``k``) of its best checkpoint and measures them as suite ``style_examples``
   does (:func:`suites.style_examples.judged_samples`), judged by the same reproduction: recognition, the Table 5.1
   row (its columns are the run's examples), and V_SD, step_SD, pose spread and diversity as shares of the style's
   **held-out** (val + test split) real clips.

Nothing is chosen here: the curve is a measurement. ``k = 1`` is a CVAE of one drawn train clip, not the run's own
CVAE (whose example is the median straight-walk clip). The synthetic data is a smoke test only.

    python scripts/benchmarks.py run style_examples_cvae --workers 2
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from suites.common import progress_printed, provenance_line, run_jobs
from suites.style_examples import KS, relative

DESCRIPTION = ("per-style CVAE trained on k = 1, 2, 4, 8 train-split examples of its style (the reproduction's CVAE "
               "stage, mean Gram target): recognition, Table 5.1 row, V_SD, step_SD, pose spread and diversity "
               "against the style's held-out real clips, over seeds")
DEFAULT_SEEDS = (0, 1, 2)
ROOT = Path(__file__).resolve().parents[2]
#: The primitive of the curve unless ``--primitives`` names others (one stance keeps the run on two cores).
DEFAULT_PRIMITIVES = ("walk_leftStance",)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--runs", type=Path, default=None,
                        help="suite style's reproductions: a folder with seed<k>/ per seed (default "
                             "runs/benchmarks/style/<data>/full, suite style_bandai's); read only")
    parser.add_argument("--train-dir", type=Path, default=None,
                        help="where the CVAEs are trained (default runs/benchmarks/style_examples_cvae/<data>)")
    parser.add_argument("--data", choices=("synthetic", "bandai"), default="bandai",
                        help="the data the reproductions are of (checked)")
    parser.add_argument("--ks", type=int, nargs="+", default=list(KS), help="example counts of the curve")
    parser.add_argument("--samples", type=int, default=1000, help="samples per CVAE")
    parser.add_argument("--styles", nargs="+", default=None, help="styles (default: every style the run has a CVAE of)")
    parser.add_argument("--primitives", nargs="+", default=list(DEFAULT_PRIMITIVES),
                        help="primitives (of the run's CVAEs)")
    parser.add_argument("--workers", type=int, default=2, help="CVAE trainings at once (one thread each)")


def example_spec(clip: Any) -> dict[str, Any]:
    """``datamodule.examples`` entry naming exactly ``clip`` of the train split (take, start frame, content)."""
    return {"pick": "take", "take": clip.take, "start": int(clip.start), "content": clip.content,
            "primitive": clip.primitive, "split": "train"}


def training_job(source: Any, primitive: str, style: str, clips: list, folder: Path) -> tuple[dict[str, Any], str]:
    """``(resolved train config, folder)`` of the run's CVAE stage of ``primitive``/``style`` with ``clips`` as its
    examples, resuming in ``folder``, one thread, no sample GIFs."""
    from omegaconf import OmegaConf, open_dict

    from stylemotion.style_example.base_run import train_config

    cfg = train_config(source, primitive, style, folder, threads=1)
    with open_dict(cfg):
        cfg.datamodule.examples = [example_spec(c) for c in clips]
        cfg.ckpt_path = "auto"
        if "samples" in (cfg.get("callbacks") or {}):
            cfg.callbacks.samples = None
    return OmegaConf.to_container(cfg, resolve=True), str(folder)


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch
    from hydra.core.global_hydra import GlobalHydra
    from suites.style_examples import Judge, curve_start, draw_examples, judged_samples, summarize

    from stylemotion.datamodules.features import describe_clip
    from stylemotion.evaluation.zero_shot import ZeroShotRunError
    from stylemotion.models.loading import load_model
    from stylemotion.style_example.base_run import load_run
    from stylemotion.style_example.command import hydra_configs

    torch.set_num_threads(1)
    ks = sorted({int(k) for k in args.ks})
    if not ks or ks[0] < 1:
        raise ZeroShotRunError(f"--ks must be whole numbers ≥ 1, got {args.ks}")
    runs = (args.runs or ROOT / "runs" / "benchmarks" / "style" / args.data / "full").expanduser()
    out = (args.train_dir or ROOT / "runs" / "benchmarks" / "style_examples_cvae" / args.data).expanduser()
    judges: dict[int, Judge] = {}
    starts: dict[tuple[int, str, str], Any] = {}
    draws: dict[tuple[int, str, str], dict[int, list]] = {}
    jobs: dict[tuple[int, str, str, int], tuple[dict[str, Any], str]] = {}
    try:
        with hydra_configs():
            for seed in seeds:
                folder = runs / f"seed{seed}"
                judge = judges[seed] = Judge(folder)
                name = judge.source.data_cfg.get("name")
                if (name == "synthetic") != (args.data == "synthetic"):
                    raise ZeroShotRunError(f"{folder} holds {name!r} data, not --data {args.data}")
                source = load_run(folder)
                for p, s in sorted(judge.source.cvaes):
                    if p not in args.primitives or (args.styles and s not in args.styles):
                        continue
                    starts[(seed, p, s)] = curve_start(judge, p, s)
                    draws[(seed, p, s)] = draw_examples(starts[(seed, p, s)][2], ks, seed, p, s)
                    for k, clips in draws[(seed, p, s)].items():
                        jobs[(seed, p, s, k)] = training_job(source, p, s, clips, out / f"seed{seed}" / f"{p}_{s}_k{k}")
    finally:
        GlobalHydra.instance().clear()
    if not jobs:
        raise ZeroShotRunError(f"no CVAE of primitives {args.primitives} and styles {args.styles} in {runs}")
    trained = run_jobs(jobs, args.workers, ("val/loss", "val/style"))
    per_seed: dict[str, Any] = {}
    for (seed, p, s), (truth, reference, _, header) in starts.items():
        judge = judges[seed]
        # the seed's run is its own judge
        curve = per_seed.setdefault(str(seed), {"judge": relative(runs / f"seed{seed}"), "curves": {}})
        curve["curves"].setdefault(p, {})[s] = header
        for k, clips in draws[(seed, p, s)].items():
            folder = Path(jobs[(seed, p, s, k)][1])
            model = load_model(folder / "checkpoints" / "best.ckpt", judge.source.settings.neutral_style,
                               judge.autoencoder)
            with progress_printed(f"[seed {seed} {p}/{s} k={k}]"):
                point = judged_samples(judge, model, model.source.sample(args.samples, seed=seed), truth, reference,
                                       [describe_clip(c) for c in clips])
            header["ks"][str(k)] = {**point, "training": {**trained[(seed, p, s, k)], "folder": relative(folder)}}
    protocol = {"runs": relative(runs), "out": relative(out),
                "splits": {"examples": "k clips of the style drawn from its train split (nested: one seeded "
                                       "permutation per seed, primitive and style; suite style_examples' draws)",
                           "reference": "the style's held-out (val + test split) real clips",
                           "judge": "the seed's reproduction: its autoencoder (Table 5.1 columns: its CVAEs' "
                                    "examples) and style classifier (fitted on the train-split clips of every style)",
                           "models": "a CVAE per seed, style and k, trained as the reproduction's CVAE stage with "
                                     "the k clips as its examples",
                           "seed_varies": "the reproduction (training seeds of every stage), the example draws, "
                                          "the CVAE trainings and the samples; the data split is fixed"}}
    return summarize(per_seed, ks, args, ["mean"], protocol)


def render(record: dict[str, Any]) -> dict[str, str]:
    from suites.style_examples import render_curve

    r = record["results"]
    protocol = (f"Per seed a CVAE of each style and k, trained as the reproduction's CVAE stage (`{r['runs']}/"
                f"seed<k>`, suite style_bandai's) with k clips of the style drawn from its train split (nested "
                f"draws, the same clips suite style_examples conditions the zero-shot network on) as its examples "
                f"(the style term's target: their mean Gram matrix); {r['samples']:,} samples per CVAE, judged by "
                f"the same reproduction (its autoencoder's Table 5.1 columns and its style classifier). Variation "
                f"as a share of the style's held-out (val + test) real clips. Nothing is chosen from this table.")
    return {**render_curve(record, "Style CVAE trained on k examples of its style", "style", protocol),
            "reading": reading(r, provenance_line(record))}


def reading(r: dict[str, Any], prov: str) -> str:
    """The curve in one paragraph: how the means over styles move from the smallest to the largest k, the
    recognition range, the styles meeting the k = 4 aims, diversity by style at the largest k and the own-column
    count."""
    from suites.common import fmt

    rows = r.get("rows") or [str(k) for k in r["ks"]]
    first, last = r["headline"][str(rows[0])], r["headline"][str(rows[-1])]
    moves = ", ".join(f"{name} {fmt(first[m]['mean'], 2)} → {fmt(last[m]['mean'], 2)}"
                      for m, name in (("v_sd", "V_SD"), ("step_sd", "step_SD"), ("diversity", "diversity")))
    recognition = [r["headline"][str(k)]["recognition"]["mean"] for k in rows]
    aims = r["headline"].get("4", {}).get("aims_met", {})
    diversity = [v["ks"][str(rows[-1])]["vs_real"]["diversity"]["mean"]
                 for styles in r["per_style"].values() for v in styles.values()]
    own = [int(round(r["headline"][str(k)]["own_column_is_minimum"]["mean"])) for k in rows]
    return (f"From k = {rows[0]} to k = {rows[-1]} the means over styles move {moves} of the held-out clips; "
            f"recognition stays {fmt(min(recognition), 3)}–{fmt(max(recognition), 3)}. Styles meeting every k = 4 aim: "
            f"{fmt(aims.get('min'), 0)}–{fmt(aims.get('max'), 0)} of {r['headline'][str(rows[0])]['rows_per_seed']} "
            f"over seeds. Diversity at k = {rows[-1]} by style: {fmt(min(diversity, default=None), 2)}–"
            f"{fmt(max(diversity, default=None), 2)} (aim ≥ 0.7). Rows whose minimum is the style's own column, mean "
            f"over seeds per k: {', '.join(str(o) for o in own)}. {prov}")
