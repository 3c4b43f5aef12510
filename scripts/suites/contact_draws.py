"""Suite ``contact_draws``: the style CVAE's draws' own-contact loss weight β (``model.sample_contact_weight``,
stylemotion/models/cvae.py), chosen on **validation** clips of every Bandai style at the reproduction's full budget
(issue 27 item 1: the styled samples' feet).

    python scripts/benchmarks.py run contact_draws --seeds 100 101

It builds on suite ``contact_full``'s choice (``--base``, read from ``benchmarks/results/contact_full.json`` by
default): per training seed (not reported seeds), β = 0 **is** that suite's run of the chosen arm (reused, not
trained again), and each β > 0 is the same reproduction (``evaluation.heldout_splits=[val]``, both walk stances,
every style) whose autoencoder and neutral VAE stages are copied from it (the reproduction checks their settings
hash), so the candidates differ in their CVAEs' β only.

Rule (:func:`choose`, fixed before the run), over every (seed, stance, style) case: a β > 0 is eligible when its
Table 5.1 rows on the diagonal are no fewer than β = 0's, its mean recognition is at least min(0.9, β = 0's) (suite
``style_channels``' test) and its mean capped log variation (V_SD, step_SD, diversity over the style's real clips,
each capped at 1) is no lower than β = 0's minus :data:`suites.style_channels.TIE`; among β = 0 and the eligible ones,
the lowest mean styled skating relative to the style's real clips (samples ÷ real) wins, a tie going to the smaller β.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

from suites import contact_full, style, style_channels
from suites.common import fmt, md_table, provenance_line, spread

DESCRIPTION = ("the style CVAE's draws' own-contact loss weight chosen at full budget on Bandai validation clips of "
               "every style (raw skating of styled samples against the style's real clips)")
DEFAULT_SEEDS = (100, 101)
DEFAULT_WEIGHTS = (100.0, 1000.0)
CONTACT_RESULTS = style.ROOT / "benchmarks" / "results" / "contact_full.json"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style_channels.run_arguments(parser, "suite style_channels' run folder (suite contact_full's chosen arm is β = 0)")
    parser.add_argument("--weights", nargs="+", type=float, default=list(DEFAULT_WEIGHTS), metavar="BETA",
                        help="β > 0 candidates (β = 0 is suite contact_full's chosen arm)")
    parser.add_argument("--base", default=None, metavar="RESULTS",
                        help="suite contact_full's results file (default: benchmarks/results/contact_full.json)")


def contact_base(path: Path) -> dict[str, Any]:
    """Suite ``contact_full``'s chosen arm: its style_channels candidate, run folder name and stage overrides."""
    try:
        r = json.loads(path.read_text())["results"]
        arm = str(r["choice"]["chosen"])
        stages = next(iter(r["per_seed"].values()))[arm]["stages"]
        folder = str(r["base"]) if arm == "off" else f"{r['base']}+{arm}"
        return {"arm": arm, "channels": str(r["base"]), "folder": folder,
                "stages": {str(k): [str(o) for o in v] for k, v in stages.items()}}
    except (OSError, ValueError, KeyError, TypeError, StopIteration) as exc:
        raise SystemExit(f"{path}: no contact_full choice to build on ({exc}); run suite contact_full first") from None


def weight_label(beta: float) -> str:
    return f"{beta:g}"


def candidate_summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Over every (seed, stance, style) case of one β: suite style_channels' figures and the styled skating ÷ real."""
    cases = [c for run in runs for c in run["cases"].values()]
    return {"styled": style_channels.candidate_summary(cases),
            "styled_skating_relative": spread(contact_full.relative(c["skating_samples"], c["skating_real"])
                                              for c in cases),
            "cvae_minutes": sum(run["cvae_minutes"] for run in runs) / len(runs) if runs else None}


def eligibility(summaries: dict[str, dict[str, Any]], variation: dict[str, float] | None = None
                ) -> tuple[dict[str, bool], float, float]:
    """Which candidates keep the first one's styled rows, recognition (floor min(0.9, its mean)) and capped log
    variation (its own minus :data:`suites.style_channels.TIE`; ``variation``: another figure per candidate in its
    place, default each summary's ``capped_log_variation``); returns (eligible, recognition floor, variation floor).
    The first candidate is always eligible."""
    names = list(summaries)
    first = summaries[names[0]]["styled"]
    if variation is None:
        variation = {n: s["styled"]["capped_log_variation"] for n, s in summaries.items()}
    floor = min(style_channels.AIMS["recognition"], first["recognition"]["mean"])
    variation_floor = variation[names[0]] - style_channels.TIE
    eligible = {n: n == names[0] or (s["styled"]["rows_on_diagonal"] >= first["rows_on_diagonal"]
                                     and s["styled"]["recognition"]["mean"] >= floor
                                     and variation[n] >= variation_floor)
                for n, s in summaries.items()}
    return eligible, floor, variation_floor


def choose(summaries: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The module doc's rule; the first key is β = 0."""
    names = list(summaries)
    eligible, floor, variation_floor = eligibility(summaries)

    def skating(n: str) -> float:
        mean = summaries[n]["styled_skating_relative"].get("mean")
        return float("inf") if mean is None else mean  # samples that never plant are not chosen

    chosen = min((n for n in names if eligible[n]), key=lambda n: (skating(n), float(n)))
    return {"eligible": eligible, "recognition_floor": floor, "variation_floor": variation_floor,
            "chosen": chosen}


def val_arm(args: argparse.Namespace, seed: int, out: Path, stages: dict[str, list[str]]
            ) -> tuple[dict[str, Any], list[str], dict[str, Any]]:
    """One arm's reproduction of ``seed`` into ``out`` evaluated on validation clips (``stages``: stage kind → extra
    ``train`` overrides); returns its report, its CVAE styles and the arm's record (run folder, held-out splits, CVAE
    minutes, suite style_channels' case figures)."""
    from stylemotion.io.jsonfile import read_json_object

    report = style.reproduce_seed(args.data, seed, out, args.workers,
                                  extra=["evaluation.heldout_splits=[val]", *args.override],
                                  stages={k: v for k, v in stages.items() if v} or None)
    styles = read_json_object(out / "data.json", "the reproduction's data summary", "rerun the suite")["cvae_styles"]
    recorded = read_json_object(out / "reproduce.json", "the reproduction's summary", "rerun the suite")["stages"]
    return report, styles, {"run": str(out.relative_to(style.ROOT) if out.is_relative_to(style.ROOT) else out),
                            "heldout_splits": report["meta"]["settings"]["heldout_splits"],
                            "cvae_minutes": round(style.stage_minutes(recorded, "cvae"), 2),
                            "cases": style_channels.case_figures(report, styles)}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch


    torch.set_num_threads(1)
    base = contact_base(Path(args.base) if args.base else CONTACT_RESULTS)
    weights = [0.0, *sorted({float(w) for w in args.weights if w > 0})]
    per_seed: dict[str, dict[str, Any]] = {}
    for seed in seeds:
        first = args.runs / args.data / f"seed{seed}" / base["folder"]
        for beta in weights:
            name = weight_label(beta)
            out = first if beta == 0 else first.with_name(f"{base['folder']}+draws{name}")
            out.mkdir(parents=True, exist_ok=True)
            copied = style_channels.share_stages(first, out) if beta > 0 else []
            cvae = [*base["stages"].get("cvae", []), *([f"model.sample_contact_weight={beta:g}"] if beta else [])]
            stages = {**base["stages"], "cvae": cvae}
            _, _, record = val_arm(args, seed, out, stages)
            per_seed.setdefault(str(seed), {})[name] = {**record, "stages": stages, "shared_from_base": copied}
    summaries = {weight_label(b): candidate_summary([s[weight_label(b)] for s in per_seed.values()])
                 for b in weights}
    return {"data": args.data, "base": base, "weights": weights, "overrides": args.override,
            "splits": {"choose": "evaluation.heldout_splits=[val], as suites style_channels and contact_full: no "
                                 "test clip is read by the figures the rule uses",
                       "seeds": "training seeds, not reported seeds"},
            "per_seed": per_seed, "summary": summaries, "choice": choose(summaries)}


def styled_cells(styled: dict[str, Any]) -> list[str]:
    """A block's cells of an arm's styled figures: rows on the diagonal, recognition, V_SD, step_SD and diversity
    over the style's real clips, mean capped log variation."""
    sd = contact_full.sd
    return [f"{styled['rows_on_diagonal']}/{styled['cases']}", sd(styled["recognition"], 3), sd(styled["v_sd"]),
            sd(styled["step_sd"]), sd(styled["diversity"]), fmt(styled["capped_log_variation"], 3)]


def arm_rows(r: dict[str, Any], cells: Callable[[dict[str, Any]], list[str]]) -> list[list[str]]:
    """A block row per arm of ``r["summary"]``: its name (bold when chosen), ``cells(summary)``, its CVAE minutes per
    run and whether it was eligible."""
    choice = r["choice"]
    return [[f"**{name}**" if name == choice["chosen"] else name, *cells(s), fmt(s.get("cvae_minutes"), 1),
             "yes" if choice["eligible"][name] else "no"] for name, s in r["summary"].items()]


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice = r["choice"]
    label, sd = contact_full.run_label(r), contact_full.sd
    rows = arm_rows(r, lambda s: [sd(s["styled"]["skating_samples"], 1, 100), sd(s["styled"]["skating_real"], 1, 100),
                                  sd(s["styled_skating_relative"]), *styled_cells(s["styled"])])
    base = r["base"]
    seeds = ", ".join(r["per_seed"])
    stages = "; ".join(f"{k}: {', '.join(v)}" for k, v in base["stages"].items() if v) or "none"
    verdict = ("β = 0 (off) **stays**" if choice["chosen"] == "0"
               else f"β = **{choice['chosen']}** is chosen")
    return {"headline": (
        f"{label}The style CVAE's draws' own-contact loss (`model.sample_contact_weight` β) at the reproduction's "
        f"budget on **validation** clips ({r['data']}, both walk stances, every style, training seeds {seeds}: not "
        f"reported seeds), on suite contact_full's chosen arm `{base['arm']}` (stage overrides: {stages}); "
        f"`evaluation.heldout_splits=[val]`. β = 0 is that arm's run; the others share its autoencoder and VAE "
        f"stages. Skating: share of contact foot-frames whose planted point moves > 0.2 m/s (%), of the styled "
        f"samples and of the style's real clips besides its example; mean ± sd (min–max) over (seed, stance, style). "
        f"Rule: eligible when Table 5.1 rows on the diagonal are no fewer than β = 0's, mean recognition ≥ "
        f"{fmt(choice['recognition_floor'], 3)} and mean capped log variation ≥ {fmt(choice['variation_floor'], 3)} "
        f"(β = 0's minus {style_channels.TIE:g}); then the lowest styled skating ÷ real, a tie to the smaller β. "
        f"Verdict: {verdict}.\n\n"
        + md_table(["β", "styled skating, samples (%)", "styled skating, real (%)", "styled ÷ real",
                    "rows on diagonal", "recognition", "V_SD / style", "step_SD / style", "diversity / style",
                    "mean capped log variation", "CVAE minutes per run", "eligible"], rows)
        + f"\n\n{provenance_line(record)}")}
