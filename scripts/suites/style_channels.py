"""Suite ``style_channels``: which channels the style CVAE's Gram term sees (``model.style_channels``: ``all``, the
thesis', or ``pose``, root velocity and yaw rate left out), chosen on **validation** clips of every Bandai style at
the reproduction's full budget, against issue 27's aims.

    python scripts/benchmarks.py run style_channels --seeds 100 101

Per training seed (not a reported seed: suite ``style_bandai`` reports seeds 0, 1, 2) and candidate, the user's
``stylemotion-reproduce data=bandai`` (both walk stances, every style) runs with ``evaluation.heldout_splits=[val]``:
the evaluation's held-out clips are the val split only, so a style's ground truth is its train + val clips besides
its example and no test clip is read by the figures the rule uses. The candidates of one seed share the
autoencoder and neutral VAE stages (copied from the first candidate's run; the reproduction checks their settings
hash), so they differ in their CVAEs only.

Per (seed, stance, style) the rule reads the report: the style's Table 5.1 row on the diagonal, the share of
samples the classifier (fitted on train clips) gives the style, and V_SD, step_SD and diversity of the samples over
the style's real clips. It meets issue 27's aims when the row is on the diagonal, recognition ≥ 0.9, V_SD and
step_SD ≥ 0.8 and diversity ≥ 0.7 (:data:`AIMS`). Rule (:func:`choose`): a candidate is eligible when its rows on
the diagonal are no fewer than the default's and its mean recognition is at least min(0.9, the default's); among
the eligible ones, most cases meeting every aim, then the highest mean over cases of the log of V_SD, step_SD and
diversity each capped at 1 (variation up to the real clips' own); candidates within :data:`TIE` of the highest count
as tied, and the tie goes to the least CVAE training time (summed over the run's CVAE stages; the pose-only Gram
decodes and encodes every style decode, ``pose-subset`` only 64 of them per step). Raw foot skating is recorded
beside, not ruled on.
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path
from typing import Any

from suites import style
from suites.common import fmt, md_table, mean_capped_log, provenance_line, spread

DESCRIPTION = ("the style CVAE's Gram over all channels or pose channels only, chosen on Bandai validation clips at "
               "full budget against issue 27's aims")
DEFAULT_SEEDS = (100, 101)
#: candidate → the ``train`` overrides appended to the CVAE stages (the first is the config's default)
CANDIDATES: dict[str, list[str]] = {"all": [], "pose": ["model.style_channels=pose"],
                                    "pose-subset": ["model.style_channels=pose", "model.style_subset=64"]}
#: mean capped log variations this close count as tied; the tie goes to the least CVAE training time
TIE = 0.05
#: issue 27's aims per style: recognition, V_SD, step_SD, diversity (samples over the style's real clips)
AIMS = {"recognition": 0.9, "v_sd": 0.8, "step_sd": 0.8, "diversity": 0.7}
VARIATION = ("v_sd", "step_sd", "diversity")
#: the stages every candidate of one seed shares (copied from the first candidate's run)
SHARED_STAGES = ("autoencoder", "vae")


def run_arguments(parser: argparse.ArgumentParser, runs_help: str) -> None:
    """``--data``, ``--runs``, ``--workers`` and ``--override``: the options of a suite that runs whole reproductions
    on validation clips (this one, suite ``contact_full``)."""
    parser.add_argument("--data", choices=sorted(style.DATA), default="bandai",
                        help="bandai: dataset-2 walks; synthetic: a smoke run of the suite only")
    parser.add_argument("--runs", type=Path, default=style.ROOT / "runs" / "benchmarks" / "style_channels",
                        help=runs_help)
    parser.add_argument("--workers", type=int, default=2, help="training stages at once (the reproduction's workers)")
    parser.add_argument("--override", nargs="*", default=[], metavar="KEY=VALUE",
                        help="more reproduce overrides for every run (e.g. budget.* for a smoke run)")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    run_arguments(parser, "folder of the candidates' reproduction runs (reused and resumed)")
    parser.add_argument("--candidates", nargs="+", choices=sorted(CANDIDATES), default=list(CANDIDATES),
                        help="candidates; the first is the reference of the rule (default: all three)")


def case_figures(report: dict[str, Any], styles: list[str]) -> dict[str, dict[str, Any]]:
    """Per ``<primitive>/<style>`` of the report's CVAE styles: Table 5.1 row on the diagonal, recognition, the
    variation over the style's real clips, the samples' raw skating, and whether every aim is met."""
    out: dict[str, dict[str, Any]] = {}
    for primitive, table in report["table_5_1"].items():
        rows = set(table["diagonal"]["rows"])
        recognized = report["style_recognition"]["per_model_detail"][primitive]
        variation = report["variation_vs_style"][primitive]
        skating = report.get("foot_skating_detail", {}).get(primitive, {})
        for s in styles:
            figures = {"row_on_diagonal": s in rows, "recognition": recognized[s]["share"],
                       **{k: variation[s].get(k) for k in VARIATION},
                       "skating_samples": (skating.get(s) or {}).get("samples", {}).get("ratio"),
                       "skating_real": (skating.get(s) or {}).get("real", {}).get("ratio")}
            figures["meets_aims"] = bool(figures["row_on_diagonal"] and all(
                figures[k] is not None and figures[k] >= aim for k, aim in AIMS.items()))
            out[f"{primitive}/{s}"] = figures
    return out


def candidate_summary(cases: list[dict[str, Any]]) -> dict[str, Any]:
    """Over every (seed, stance, style) case of a candidate: the rule's figures and spreads."""
    return {"cases": len(cases), "rows_on_diagonal": sum(c["row_on_diagonal"] for c in cases),
            "meets_aims": sum(c["meets_aims"] for c in cases),
            "recognition": spread(c["recognition"] for c in cases),
            **{k: spread(c[k] for c in cases) for k in VARIATION},
            "skating_samples": spread(c["skating_samples"] for c in cases),
            "skating_real": spread(c["skating_real"] for c in cases),
            "capped_log_variation": mean_capped_log(cases, VARIATION)}


def choose(summaries: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The module doc's rule over candidate summaries (the first is the default); returns eligibility and choice."""
    default = summaries[next(iter(summaries))]
    floor = min(AIMS["recognition"], default["recognition"]["mean"])
    eligible = {name: s["rows_on_diagonal"] >= default["rows_on_diagonal"] and s["recognition"]["mean"] >= floor
                for name, s in summaries.items()}
    pool = [name for name in summaries if eligible[name]]
    most = max(summaries[n]["meets_aims"] for n in pool)
    pool = [n for n in pool if summaries[n]["meets_aims"] == most]
    best = max(summaries[n]["capped_log_variation"] for n in pool)
    tied = [n for n in pool if summaries[n]["capped_log_variation"] >= best - TIE]
    chosen = min(tied, key=lambda n: summaries[n].get("cvae_minutes") or 0.0)  # stable: the first on equal time
    return {"eligible": eligible, "recognition_floor": floor, "tie": TIE, "tied": tied, "chosen": chosen}


def share_stages(first: Path, out: Path) -> list[str]:
    """Copy the finished shared stages of ``first`` into ``out`` (those ``out`` lacks); returns their names."""
    copied = []
    for name in SHARED_STAGES:
        source, target = first / name, out / name
        if source.is_dir() and not target.exists():
            shutil.copytree(source, target, symlinks=False)
            copied.append(name)
    return copied


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch

    from stylemotion.io.jsonfile import read_json_object

    torch.set_num_threads(1)
    names = list(dict.fromkeys(args.candidates))
    per_seed: dict[str, dict[str, Any]] = {}
    for seed in seeds:
        first = None
        for name in names:
            out = args.runs / args.data / f"seed{seed}" / name
            out.mkdir(parents=True, exist_ok=True)
            copied = share_stages(first, out) if first is not None else []
            report = style.reproduce_seed(args.data, seed, out, args.workers,
                                          extra=["evaluation.heldout_splits=[val]", *args.override],
                                          stages={"cvae": CANDIDATES[name]})
            styles = read_json_object(out / "data.json", "the reproduction's data summary",
                                      "rerun the suite")["cvae_styles"]
            stages = read_json_object(out / "reproduce.json", "the reproduction's summary", "rerun the suite")["stages"]
            per_seed.setdefault(str(seed), {})[name] = {
                "run": str(out.relative_to(style.ROOT) if out.is_relative_to(style.ROOT) else out),
                "cvae_minutes": round(style.stage_minutes(stages, "cvae"), 2),
                "shared_from_first": copied, "heldout_splits": report["meta"]["settings"]["heldout_splits"],
                "cases": case_figures(report, styles)}
            first = first or out
    summaries = {name: candidate_summary([c for s in per_seed.values() for c in s[name]["cases"].values()])
                 | {"cvae_minutes": sum(s[name]["cvae_minutes"] for s in per_seed.values()) / len(per_seed)}
                 for name in names}
    return {"data": args.data, "candidates": {n: CANDIDATES[n] for n in names}, "aims": AIMS,
            "overrides": args.override,
            "splits": {"choose": "evaluation.heldout_splits=[val]: a style's ground truth is its train + val clips "
                                 "besides its example, the classifier is fitted on train clips; no test clip is read "
                                 "by the figures the rule uses",
                       "seeds": "training seeds of the candidates, not reported seeds"},
            "per_seed": per_seed, "summary": summaries, "choice": choose(summaries)}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice, summary = r["choice"], r["summary"]
    default = next(iter(r["candidates"]))
    label = "**Synthetic data: a smoke run of the suite, not evidence.** " if r["data"] == "synthetic" else ""
    if r.get("overrides"):
        label += f"**Not the full budget: overrides {', '.join(r['overrides'])}.** "

    def sd(s: dict[str, Any], digits: int = 2) -> str:
        return f"{fmt(s.get('mean'), digits)} ± {fmt(s.get('sd'), digits)} ({fmt(s.get('min'), digits)}–" \
               f"{fmt(s.get('max'), digits)})" if s.get("n") else "—"

    rows = [[f"**{n}**" if n == choice["chosen"] else n, ", ".join(r["candidates"][n]) or "(the config's default)",
             f"{s['rows_on_diagonal']}/{s['cases']}", f"{s['meets_aims']}/{s['cases']}", sd(s["recognition"], 3),
             *(sd(s[k]) for k in VARIATION), sd(s["skating_samples"]), sd(s["skating_real"]),
             fmt(s["capped_log_variation"], 3), fmt(s.get("cvae_minutes"), 1),
             "yes" if choice["eligible"][n] else "no"]
            for n, s in summary.items()]
    cases = sorted({c for seed in r["per_seed"].values() for cand in seed.values() for c in cand["cases"]})
    case_rows = []
    for case in cases:
        cells = []
        for n in summary:
            got = [seed[n]["cases"].get(case) for seed in r["per_seed"].values()]
            cells.append(" / ".join(f"{'✓' if g['row_on_diagonal'] else '✗'} {fmt(g['recognition'], 2)} "
                                    f"{fmt(g['v_sd'], 2)} {fmt(g['step_sd'], 2)} {fmt(g['diversity'], 2)}"
                                    if g else "—" for g in got))
        case_rows.append([case, *cells])
    verdict = (f"the config's default ({default}) stays" if choice["chosen"] == default
               else f"{choice['chosen']} is chosen over the config's {default}")
    aims = ", ".join(f"{k} ≥ {v:g}" for k, v in r["aims"].items())
    seeds = ", ".join(r["per_seed"])
    line = "; ".join(f"{n} V_SD {fmt(s['v_sd'].get('mean'), 2)} / step_SD {fmt(s['step_sd'].get('mean'), 2)} / "
                     f"diversity {fmt(s['diversity'].get('mean'), 2)} of the style's clips, recognized "
                     f"{fmt(100 * (s['recognition'].get('mean') or 0), 0)} %, rows on the diagonal "
                     f"{s['rows_on_diagonal']}/{s['cases']}, CVAE {fmt(s.get('cvae_minutes'), 1)} min a run"
                     for n, s in summary.items())
    return {"line": (
        f"{label}The style CVAE's Gram channels chosen on **validation** clips ({r['data']}, both walk stances, every "
        f"style, training seeds {seeds}; means over (seed, stance, style)): {line}. Chosen: **{choice['chosen']}**. "
        f"Rule and per-case figures: benchmarks/evaluation.md. {provenance_line(record)}"),
        "headline": (
        f"{label}The style CVAE's Gram channels chosen on **validation** clips ({r['data']}, both walk stances, every "
        f"style, the reproduction's budget, training seeds {seeds}: not reported seeds). Each candidate's "
        f"reproduction evaluated with `evaluation.heldout_splits=[val]`: a style's ground truth is its train + val "
        f"clips besides its example, the classifier is fitted on train clips; no test clip enters the rule. Per "
        f"(seed, stance, style) case: Table 5.1 row on the diagonal, recognition, and V_SD, step_SD, diversity of "
        f"the samples over the style's real clips (mean ± sd (min–max) over cases); issue 27's aims: row on the "
        f"diagonal, {aims}. Rule: eligible when its rows on the diagonal are no fewer than the default's and its mean "
        f"recognition is at least {fmt(choice['recognition_floor'], 3)} (min of 0.9 and the default's); then most "
        f"cases meeting every aim, then the highest mean log of the three variation ratios capped at 1, a difference "
        f"under {choice.get('tie', TIE):g} a tie that goes to the least CVAE training time (summed over a run's "
        f"CVAE stages, 2 at once on 2 cores; tied: {', '.join(choice.get('tied', [choice['chosen']]))}). Raw foot "
        f"skating (share of contact foot-frames moving > 0.2 m/s; samples and the style's real clips) is shown, not "
        f"ruled on. Chosen: **{choice['chosen']}**: {verdict}.\n\n"
        + md_table(["candidate", "CVAE overrides", "rows on diagonal", "cases meeting every aim", "recognition",
                    "V_SD / style", "step_SD / style", "diversity / style", "skating, samples", "skating, real",
                    "mean capped log variation", "CVAE minutes per run", "eligible"], rows)
        + f"\n\n{provenance_line(record)}"),
        "cases": (
        f"{label}Per case, per seed ({seeds}, separated by /): Table 5.1 row on the diagonal (✓/✗), recognition, "
        f"V_SD, step_SD and diversity over the style's real clips (validation protocol as in the headline).\n\n"
        + md_table(["stance/style", *summary], case_rows) + f"\n\n{provenance_line(record)}")}
