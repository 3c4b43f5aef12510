"""Suite ``style_method``: which ``method`` of ``stylemotion-style`` serves a style the run never saw, chosen on
**validation** clips (issue 27 item 3: the zero-shot network as the default if the validation split supports it).

    python scripts/benchmarks.py run style_method --seeds 100 101 --primitives walk_leftStance

A user's new style is one the run's autoencoder never saw. Per training seed ``k`` (not a reported seed) the judge is
a reproduction evaluated on validation clips (``--judge``, default suite ``contact_template``'s ``off`` run of that
seed; run here through the library when missing, with ``evaluation.heldout_splits=[val]``), and for each left-out
style ``s`` :func:`stylemotion.evaluation.zero_shot.leave_one_style_out` (``cvae_unseen=True``) trains an
autoencoder without any take of ``s`` and on it, for each primitive, the two methods of ``stylemotion-style``:

* ``zero_shot``: the zero-shot network trained without ``s`` (``--epochs``; default the ``zero_shot`` experiment's,
  as ``stylemotion-style method=zero_shot`` trains it), conditioned on the example clip(s) of the judge's CVAE of s
  (in ``seed<k>_e<epochs>/`` when ``--epochs`` is given; the autoencoders and CVAEs stay in ``seed<k>/``, shared);
* ``cvae_unseen``: the judge's CVAE stage of ``(p, s)`` (the same settings and example clips) on that autoencoder,
  as ``stylemotion-style method=cvae`` trains it.

Both are measured in the judge's space (its autoencoder, its style classifier fitted on train clips) against s's
real clips of the train and val splits but the example (the judge's val protocol: no test clip): recognition, whether
the Table 5.1 row's minimum is s's own column, and V_SD, step_SD and diversity of the samples as shares of the real
clips'. The judge's own CVAE of s (its autoencoder saw s) stands beside as ``cvae``, not ruled on.

Rule (:func:`choose`, fixed before any Bandai run), over every (seed, primitive, style) case: ``zero_shot`` becomes
the default when its own-column rows are no fewer than ``cvae_unseen``'s, its mean recognition is at least min(0.9,
``cvae_unseen``'s) and its mean capped log variation (the log of each share capped at 1, averaged) exceeds
``cvae_unseen``'s by more than :data:`TIE`; else ``cvae`` stays the default.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from suites import contact_full
from suites.common import fmt, md_table, mean_capped_log, provenance_line, spread
from suites.style import DATA, reproduce_seed

DESCRIPTION = ("stylemotion-style's method for a style the run never saw (zero-shot network or CVAE, both on an "
               "autoencoder without the style), chosen on validation clips")
DEFAULT_SEEDS = (100, 101)
ROOT = Path(__file__).resolve().parents[2]
#: The methods compared (rows of leave_one_style_out) and the reference row beside them.
METHODS = ("zero_shot", "cvae_unseen")
REFERENCE = "cvae"
LABELS = {"zero_shot": "zero-shot network (method=zero_shot)",
          "cvae_unseen": "CVAE on the autoencoder without the style (method=cvae)",
          "cvae": "the judge's CVAE (its autoencoder saw the style; not ruled on)"}
#: Variation shares of the samples over the style's real clips.
VARIATION = ("v_sd", "step_sd", "diversity")
#: Which report of the judge a leave-one-style-out reads (``report_on``): its folder, and the evaluation settings
#: (``heldout_splits``, ``style_truth``) it must have been made with. ``val``: choices, reading no test clip; ``test``:
#: figures reported after the choices, against each style's test clips only.
JUDGE_REPORTS = {"val": ("report", ["val"], "all"), "test": ("report_test", ["test"], "heldout")}
#: Mean capped log variations this close count as tied (as suite style_channels).
TIE = 0.05
AIM_RECOGNITION = 0.9


def experiment_epochs() -> int:
    """``trainer.max_epochs`` of ``experiment=zero_shot`` (what ``stylemotion-style method=zero_shot`` trains)."""
    from omegaconf import OmegaConf

    return int(OmegaConf.load(ROOT / "stylemotion" / "configs" / "experiment" / "zero_shot.yaml").trainer.max_epochs)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    leave_one_out_arguments(parser)
    parser.add_argument("--epochs", type=int, default=None,
                        help="epochs of each zero-shot network (default: the zero_shot experiment's, as "
                             "stylemotion-style trains it)")


#: The default judge of each training seed: suite ``contact_template``'s ``off`` run of that seed.
VAL_JUDGE = str(ROOT / "runs" / "benchmarks" / "contact_template" / "{data}" / "seed{seed}" / "off")


def leave_one_out_arguments(parser: argparse.ArgumentParser, judge: str = VAL_JUDGE,
                            judge_help: str = "the judge reproduction per seed ({data} and {seed} are filled in); "
                                              "made here with evaluation.heldout_splits=[val] when missing") -> None:
    """The options of the leave-one-style-out runs but the networks' epochs (suite zero_shot_epochs shares them);
    ``judge``/``judge_help``: ``--judge``'s default and help."""
    parser.add_argument("--data", choices=sorted(DATA), default="bandai",
                        help="bandai: dataset-2 walks; synthetic: a smoke run of the suite only")
    parser.add_argument("--judge", default=judge, help=judge_help)
    parser.add_argument("--runs", type=Path, default=ROOT / "runs" / "benchmarks" / "style_method",
                        help="folder of the leave-one-style-out trainings (reused and resumed)")
    parser.add_argument("--styles", nargs="+", default=None, help="left-out styles (default: the judge's CVAE styles)")
    parser.add_argument("--primitives", nargs="+", default=None, help="primitives (default: the judge's)")
    parser.add_argument("--samples", type=int, default=1000, help="samples per model and seed")
    parser.add_argument("--workers", type=int, default=2,
                        help="processes at once: training stages of a judge made here, then seeds (one thread each)")
    parser.add_argument("--override", nargs="*", default=[], metavar="KEY=VALUE",
                        help="more reproduce overrides of a judge made here (e.g. budget.* for a smoke run)")


def judge_for(args: argparse.Namespace, seed: int) -> Path:
    """The judge of ``seed``: the ``--judge`` folder, made (val protocol) when it holds no finished reproduction."""
    folder = Path(str(args.judge).format(data=args.data, seed=seed)).expanduser()
    if not (folder / "report" / "report.json").is_file():
        reproduce_seed(args.data, seed, folder, args.workers, args.primitives, args.styles,
                       extra=["evaluation.heldout_splits=[val]", *args.override])
    return folder.resolve()


def case_figures(row: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Per method row of one left-out (primitive, style): recognition, own column, variation shares of real, and
    (rows that measured it) the samples' raw foot skating and its multiple of the style's real clips'."""
    real = row["real"]["variation"]
    real_skating = (row["real"].get("foot_skating") or {}).get("ratio")
    out = {}
    for kind in (*METHODS, REFERENCE):
        if kind not in row:  # a run without the CVAE on the autoencoder without the style
            continue
        r = row[kind]
        shares = {k: (r["variation"][k] / real[k] if real[k] else None) for k in VARIATION}
        out[kind] = {"recognition": r["recognition"], "own_column": bool(r["own_column_is_minimum"]), **shares}
        if "foot_skating" in r:
            skating = r["foot_skating"]["ratio"]
            out[kind].update(skating=skating, skating_vs_real=skating / real_skating if real_skating else None)
    if real_skating is not None:
        out["real_skating"] = real_skating
    for key, name in (("foot_skating", "reconstructed_skating_vs_real"),
                      ("foot_skating_timeline", "timeline_skating_vs_real"),
                      ("foot_skating_judge", "judge_reconstructed_skating_vs_real")):
        rebuilt = (row.get("reconstructed") or {}).get(key)
        if rebuilt is not None and real_skating:
            out[name] = rebuilt["ratio"] / real_skating
    return out


def reconstruction_skating(cases: list[dict[str, Any]]) -> str:
    """A sentence on the raw skating of the style's real clips encoded and decoded by the autoencoder without the
    style (what any model decoding through it starts from), × the real clips'; empty when no case measured it."""
    rebuilt = spread(c.get("reconstructed_skating_vs_real") for c in cases)
    if not rebuilt.get("n"):
        return ""
    timeline = spread(c.get("timeline_skating_vs_real") for c in cases)
    judge = spread(c.get("judge_reconstructed_skating_vs_real") for c in cases)
    alone = (f"; only resampled to the canonical timeline and back (no autoencoder), {contact_full.sd(timeline, 1)}×"
             if timeline.get("n") else "")
    seen = (f"; through the judge's autoencoder, which saw the style, {contact_full.sd(judge, 1)}×"
            if judge.get("n") else "")
    return (f" The style's real clips encoded and decoded by the autoencoder without the style (no model; their own "
            f"durations) skate {contact_full.sd(rebuilt, 1)}× the real clips'{alone}{seen} (over {rebuilt['n']} "
            "cases).")


def summary(cases: list[dict[str, Any]]) -> dict[str, Any]:
    """Over every case of one method (the skating figures when every case has them)."""
    out = {"cases": len(cases), "own_column": sum(c["own_column"] for c in cases),
           "recognition": spread(c["recognition"] for c in cases),
           **{k: spread(c[k] for c in cases) for k in VARIATION},
           "capped_log_variation": mean_capped_log(cases, VARIATION)}
    if cases and all("skating" in c for c in cases):
        out.update(skating=spread(c["skating"] for c in cases),
                   skating_vs_real=spread(c["skating_vs_real"] for c in cases))
    return out


def method_summaries(per_seed: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Per method row (and the reference), :func:`summary` over every case of every seed."""
    cases = [c for s in per_seed.values() for c in s["cases"].values()]
    return {kind: summary([c[kind] for c in cases]) for kind in (*METHODS, REFERENCE)
            if all(kind in c for c in cases)}


def choose(summaries: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The module doc's rule."""
    zs, cv = summaries["zero_shot"], summaries["cvae_unseen"]
    floor = min(AIM_RECOGNITION, cv["recognition"]["mean"])
    tests = {"own_column": zs["own_column"] >= cv["own_column"],
             "recognition": zs["recognition"]["mean"] >= floor,
             "variation": zs["capped_log_variation"] > cv["capped_log_variation"] + TIE}
    return {"tests": tests, "recognition_floor": floor,
            "default": "zero_shot" if all(tests.values()) else "cvae"}


def contact_networks(weight: float) -> tuple[list[str], str]:
    """The networks' training override for foot-contact loss weight ``weight`` and their folder's tag (``""`` for 0:
    the networks every earlier suite trained, in ``seed<k>_e<epochs>/``; ``_contact<w>`` else), so one folder always
    holds networks of one weight, whatever the configs' default."""
    # a float as the yaml writes it (0.0): the trainings' hash reads the composed value, and 0 is not 0.0 there
    return [f"model.contact_weight={float(weight)!r}"], (f"_contact{weight:g}" if weight else "")


def seed_record(args: argparse.Namespace, seed: int, judge: Path) -> dict[str, Any]:
    """One training seed's leave-one-style-out on ``judge`` (one torch thread): its cases, minutes and splits."""
    import torch

    from stylemotion.evaluation.zero_shot import ZeroShotRunError, leave_one_style_out, read_run

    torch.set_num_threads(1)
    report_on = getattr(args, "report_on", "val")
    report, splits, truth = JUDGE_REPORTS[report_on]
    source = read_run(judge, report)
    if list(source.settings.heldout_splits) != splits or source.settings.style_truth != truth:
        raise ZeroShotRunError(f"judge {judge}'s {report} was evaluated on {list(source.settings.heldout_splits)} "
                               f"with style_truth={source.settings.style_truth}, not {splits} with {truth}: "
                               + ("the choice must not read test clips" if report_on == "val" else
                                  "test figures must read test clips only"))
    # Autoencoders and CVAEs in seed<k>/, shared by every epoch count and training override of the networks
    # (seed<k>_e<epochs>[<networks_tag>]/), and those networks by every way of sampling them (the evaluation of one in
    # seed<k>[_e<epochs>][<networks_tag>]_t<τ>[_centred]/, with ``_test`` appended when it is judged on test clips).
    network_overrides, tag = list(getattr(args, "network_overrides", None) or []), getattr(args, "networks_tag", "")
    stages = args.runs / args.data / f"seed{seed}"
    networks = stages if args.epochs is None and not tag else stages.with_name(
        f"seed{seed}{f'_e{args.epochs}' if args.epochs is not None else ''}{tag}")
    temperature, centred = getattr(args, "temperature", None), getattr(args, "centred", None) or None
    out = networks if temperature is None and not centred else networks.with_name(
        f"{networks.name}_t{1.0 if temperature is None else temperature:g}{'_centred' if centred else ''}")
    if report_on != "val":
        out = out.with_name(f"{out.name}_{report_on}")
    out = out.with_name(out.name + getattr(args, "out_tag", ""))  # e.g. another leave-out protocol's evaluation
    result = leave_one_style_out(judge, out, args.styles, args.primitives, args.epochs, args.samples, seed,
                                 overrides=network_overrides, threads=1, resume=True,
                                 cvae_unseen=getattr(args, "cvae_unseen", True), stages=stages, networks=networks,
                                 temperature=temperature, centred=centred, report=report,
                                 groups=getattr(args, "groups", None))
    cases = {f"{p}/{s}": case_figures(row) for p, res in result["primitives"].items()
             for s, row in res["styles"].items()}
    minutes = {f"{p}/{s}": {
        "autoencoder": round((row["generator_autoencoder"].get("train_seconds") or 0) / 60, 1),
        "zero_shot": round((row["zero_shot"].get("train_seconds") or 0) / 60, 1),
        "cvae_unseen": round(((row.get("cvae_unseen") or {}).get("train_seconds") or 0) / 60, 1)}
        for p, res in result["primitives"].items() for s, row in res["styles"].items()}
    return {"judge": str(judge.relative_to(ROOT)) if judge.is_relative_to(ROOT) else str(judge),
            "out": str(out), "networks": str(networks), "cases": cases, "train_minutes": minutes,
            "seconds": round(result["meta"]["seconds"], 1), "splits": result["splits"]}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    judges = {seed: judge_for(args, seed) for seed in seeds}  # made one after another, each with --workers stages
    # Seeds in parallel, one torch thread each (--workers processes); a seed's figures do not depend on it.
    processes = max(1, min(args.workers, len(seeds)))
    with ProcessPoolExecutor(max_workers=processes, mp_context=get_context("spawn")) as pool:
        futures = {seed: pool.submit(seed_record, args, seed, judge) for seed, judge in judges.items()}
        per_seed: dict[str, Any] = {str(seed): future.result() for seed, future in futures.items()}
    summaries = method_summaries(per_seed)
    return {"data": args.data, "epochs": args.epochs, "experiment_epochs": experiment_epochs(), "samples": args.samples,
            "narrowed": {"primitives": args.primitives, "styles": args.styles},
            "splits": {"choose": "the judge's evaluation.heldout_splits=[val]: real clips of the train and val "
                                 "splits; no test clip", "seeds": "training seeds, not reported seeds"},
            "per_seed": per_seed, "summary": summaries, "choice": choose(summaries)}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice = r["choice"]
    sd = contact_full.sd
    label = "**Synthetic data: a smoke run of the suite, not evidence.** " if r["data"] == "synthetic" else ""
    narrowed = {k: v for k, v in r["narrowed"].items() if v}
    if narrowed:
        label += "**Narrowed:** " + "; ".join(f"{k} {', '.join(v)}" for k, v in narrowed.items()) + ". "
    rows = [[LABELS[kind], f"{s['own_column']}/{s['cases']}", sd(s["recognition"], 3),
             *(sd(s[k]) for k in VARIATION), fmt(s["capped_log_variation"], 3)]
            for kind, s in r["summary"].items()]
    full = not narrowed and not r["epochs"] and len(r["per_seed"]) >= 2
    verdict = ("**method=zero_shot becomes the default**" if choice["default"] == "zero_shot"
               else "method=cvae **stays** the default")
    if not full:
        verdict = (f"{'zero-shot' if choice['default'] == 'zero_shot' else 'CVAE'} by the rule, **not applied**: a "
                   "narrowed run (fewer than 2 seeds, a subset, or shortened networks) changes no default")
    tests = ", ".join(f"{k}: {'yes' if v else 'no'}" for k, v in choice["tests"].items())
    return {"headline": (
        f"{label}A style the run never saw, on **validation** clips ({r['data']}, training seeds "
        f"{', '.join(r['per_seed'])}: not reported seeds; network epochs: "
        f"{network_epochs(r, record)}): per left-out style an autoencoder without "
        f"it, and on it the zero-shot network and the CVAE as stylemotion-style trains them, judged by a "
        f"reproduction evaluated with `evaluation.heldout_splits=[val]`. Recognition: share of samples the judge's "
        f"classifier gives the style; own column: Table 5.1 rows whose minimum is the style's example; V_SD, step_SD, "
        f"diversity: samples ÷ the style's train + val clips; mean ± sd (min–max) over (seed, primitive, style). Rule: "
        f"zero-shot when its own-column rows are no fewer, its mean recognition ≥ "
        f"{fmt(choice['recognition_floor'], 3)} and its mean capped log variation exceeds the CVAE's by more than "
        f"{TIE:g}. Tests: {tests}. Verdict: {verdict}.\n\n"
        + md_table(["method", "own column", "recognition", "V_SD / style", "step_SD / style", "diversity / style",
                    "mean capped log variation"], rows)
        + f"\n\n{provenance_line(record)}"),
        "styles": f"{render_styles(r)}\n\n{provenance_line(record)}"}


def network_epochs(r: dict[str, Any], record: dict[str, Any]) -> str:
    """The networks' epochs as the block states them: ``--epochs``, else the experiment's when the run recorded it,
    else the experiment's at the run's commit (results from before the record)."""
    if r["epochs"]:
        return str(r["epochs"])
    if r.get("experiment_epochs"):
        return f"{r['experiment_epochs']}, the zero_shot experiment's"
    return f"the zero_shot experiment's at commit {record['commit'][:12]}"


def render_styles(r: dict[str, Any]) -> str:
    """Per left-out style, over seeds and primitives: each method's recognition, own-column rows and diversity."""
    cases: dict[str, list[dict[str, Any]]] = {}
    for seed in r["per_seed"].values():
        for key, case in seed["cases"].items():
            cases.setdefault(key.split("/", 1)[1], []).append(case)
    sd = contact_full.sd
    rows = [[style, *(cell for kind in (*METHODS, REFERENCE) for cell in (
        sd(spread(c[kind]["recognition"] for c in group), 3),
        f"{sum(c[kind]['own_column'] for c in group)}/{len(group)}",
        sd(spread(c[kind]["diversity"] for c in group))))] for style, group in cases.items()]
    header = [h for kind in ("zero-shot", "CVAE, AE without the style", "judge's CVAE")
              for h in (f"{kind}: recognition", "own column", "diversity / style")]
    return ("Per left-out style, mean ± sd (min–max) over training seeds and primitives (same runs as above).\n\n"
            + md_table(["style", *header], rows))
