"""Suite ``style_duration``: whether the style CVAE's draws take the duration of the style's steps (the styled
duration term, ``model.style_duration_weight`` = γ), chosen on **validation** clips of every Bandai style at the
reproduction's full budget (issue 27 items 1–2: samples whose legs keep the style without outrunning the root).

    python scripts/benchmarks.py run style_duration --seeds 100 101 --weights 50 500

Why: the style term reads features on the canonical timeline, and the reconstruction holds the draws' durations to
the neutral content clips', so every style's draws last about as long as neutral steps (suite contact_template's
stance block: CVAE draws 0.44–0.50 s in every style, while the style's real steps last 0.44 s (active) to 0.62 s
(masculine)). A draw with a style's spatial step but a neutral duration walks the step at the wrong pace.

Arms per training seed (not reported seeds), each the user's ``stylemotion-reproduce data=bandai`` (both walk
stances, every style) with ``evaluation.heldout_splits=[val]``: ``off`` (the CVAE stages with
``++model.style_duration_weight=0``) and ``duration<γ>`` (with ``++model.style_duration_weight=γ``), sharing ``off``'s
autoencoder and neutral VAE stages (copied). The run that chose γ = 50 (benchmarks/results/style_duration.json, commit
d6356a7, before γ was a config key) took suite contact_template's ``off`` runs as its ``off``: the configs' defaults
then, γ = 0, the same settings. Per (seed, stance,
style) case, ``--stance-samples`` draws of each CVAE against the style's real clips of the train and val splits
(suite contact_template's stance figures): the **duration error** ``|log(mean duration of the draws ÷ that of the real
clips)|``.

Rule (:func:`choose`, fixed before any run): an arm is eligible as in suite contact_template (Table 5.1 rows on the
diagonal no fewer than ``off``'s, mean recognition ≥ min(0.9, ``off``'s), mean capped log variation ≥ ``off``'s minus
:data:`suites.style_channels.TIE`); starting from ``off``, each eligible arm in order of γ replaces the holder when
its mean duration error is more than :data:`TIE` (relative) below the holder's.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

from suites import contact_draws, contact_full, contact_template, style, style_channels
from suites.common import fmt, md_table, number_above, provenance_line, spread

DESCRIPTION = ("whether the style CVAE's draws take the duration of the style's steps (model.style_duration_weight), "
               "chosen at full budget on Bandai validation clips of every style")
DEFAULT_SEEDS = (100, 101)
DEFAULT_WEIGHTS = (50.0, 500.0)
#: relative difference of the mean duration error under which two arms tie
TIE = 0.05


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style_channels.run_arguments(parser, "folder of the arms' reproduction runs (reused and resumed)")
    parser.set_defaults(runs=style.ROOT / "runs" / "benchmarks" / "style_duration")
    parser.add_argument("--weights", type=number_above(0, float, inclusive=False), nargs="+",
                        default=list(DEFAULT_WEIGHTS), metavar="GAMMA",
                        help="γ of the duration arms (model.style_duration_weight > 0)")
    parser.add_argument("--stance-samples", type=number_above(2), default=300, metavar="N",
                        help="draws per model for the durations (≥ 2)")


def arms(weights: list[float]) -> dict[str, list[str]]:
    """Arm name (``off``, ``duration<γ>`` in order of γ) → the CVAE stages' ``train`` overrides."""
    return {"off": ["++model.style_duration_weight=0"], **{f"duration{g:g}": [f"++model.style_duration_weight={g:g}"]
                          for g in sorted({float(w) for w in weights if w > 0})}}


def duration_cases(stance: dict[str, dict[str, Any]], real: dict[str, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Per styled ``<primitive>/<style>``: the draws' and the real clips' mean durations (s) and the log ratio."""
    out = {}
    for key, figures in stance.items():
        if key.endswith("/neutral") or key not in real:
            continue
        drawn, recorded = figures["duration_s"], real[key]["duration_s"]
        out[key] = {"samples_s": drawn, "real_s": recorded, "log_ratio": math.log(drawn / recorded)}
    return out


def arm_summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Over every (seed, stance, style) case of one arm: suite contact_template's figures and the duration error."""
    durations = [c for run in runs for c in run["durations"].values()]
    return {**contact_template.arm_summary(runs),
            "duration_log_ratio": spread(c["log_ratio"] for c in durations),
            "duration_error": spread(abs(c["log_ratio"]) for c in durations)}


def choose(summaries: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The module doc's rule; the first key is ``off``, the others in order of γ."""
    eligible, floor, variation_floor = contact_draws.eligibility(summaries)
    names = list(summaries)

    def error(n: str) -> float:
        return float(summaries[n]["duration_error"]["mean"])

    chosen = names[0]
    for n in names[1:]:
        if eligible[n] and error(n) < error(chosen) * (1 - TIE):
            chosen = n
    return {"eligible": eligible, "recognition_floor": floor, "variation_floor": variation_floor, "chosen": chosen}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch

    torch.set_num_threads(1)
    table = arms(list(args.weights))
    per_seed: dict[str, dict[str, Any]] = {}
    real: dict[str, dict[str, Any]] = {}
    for seed in seeds:
        first = args.runs / args.data / f"seed{seed}" / "off"
        for name, overrides in table.items():
            record = contact_template.arm_record(args, seed, first, name, overrides, real.setdefault(str(seed), {}))
            record["durations"] = duration_cases(record["stance_travel"], real[str(seed)])
            per_seed.setdefault(str(seed), {})[name] = record
    summaries = {name: arm_summary([s[name] for s in per_seed.values()]) for name in table}
    return {"data": args.data, "arms": table, "overrides": args.override, "stance_samples": args.stance_samples,
            "splits": {"choose": "evaluation.heldout_splits=[val]: no test clip is read by the figures the rule uses",
                       "seeds": "training seeds, not reported seeds"},
            "per_seed": per_seed, "real_stance": real, "summary": summaries, "choice": choose(summaries)}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice = r["choice"]
    label, sd = contact_full.run_label(r), contact_full.sd
    rows = contact_draws.arm_rows(r, lambda s: [
        sd(s["duration_log_ratio"], 3), sd(s["duration_error"], 3), *contact_draws.styled_cells(s["styled"]),
        sd(s["styled_skating_relative"]), sd(s["mid_excess"], 2)])
    verdict = "`off` **stays**" if choice["chosen"] == "off" else f"**{choice['chosen']}** is chosen"
    return {"headline": (
        f"{label}Whether the style CVAE's draws take the duration of the style's steps (`model.style_duration_weight`"
        f" = γ) at the reproduction's budget on **validation** clips ({r['data']}, both walk stances, every style, "
        f"training seeds {', '.join(r['per_seed'])}: not reported seeds), `evaluation.heldout_splits=[val]`; the arms "
        f"share `off`'s autoencoder and VAE stages. Duration log ratio: log(mean duration of {r['stance_samples']} "
        f"draws ÷ that of the style's train + val clips); error: its absolute value. Mean ± sd (min–max) over (seed, "
        f"stance, style). Rule: eligible when Table 5.1 rows on the diagonal are no fewer than `off`'s, mean "
        f"recognition ≥ {fmt(choice['recognition_floor'], 3)} and mean capped log variation ≥ "
        f"{fmt(choice['variation_floor'], 3)}; then the lowest mean duration error, beating the holder by more than "
        f"{TIE:.0%}. Verdict: {verdict}.\n\n"
        + md_table(["arm", "duration log ratio", "duration error", "rows on diagonal", "recognition", "V_SD / style",
                    "step_SD / style", "diversity / style", "mean capped log variation", "skating ÷ real",
                    "mid-stance speed − real (m/s)", "CVAE minutes per run", "eligible"], rows)
        + f"\n\n{provenance_line(record)}"),
        "styles": f"{render_styles(r)}\n\n{provenance_line(record)}"}


def render_styles(r: dict[str, Any]) -> str:
    """Per style: the real clips' mean duration and each arm's draws', mean (min–max) over seeds and stances."""
    names = list(r["summary"])
    by_style: dict[str, dict[str, list[dict[str, Any]]]] = {}
    for seed in r["per_seed"].values():
        for name in names:
            for key, case in seed[name]["durations"].items():
                by_style.setdefault(key.split("/", 1)[1], {}).setdefault(name, []).append(case)
    rows = []
    for style_name, cases in by_style.items():
        first = cases[names[0]]
        rows.append([style_name, sd_seconds([c["real_s"] for c in first]),
                     *(sd_seconds([c["samples_s"] for c in cases.get(n, [])]) for n in names)])
    return ("Mean duration per style (s), real clips (train + val) and each arm's draws; mean (min–max) over training "
            "seeds and stances (same runs as above).\n\n"
            + md_table(["style", "real", *(f"{n}: draws" for n in names)], rows))


def sd_seconds(values: list[float]) -> str:
    s = spread(values)
    return f"{fmt(s['mean'], 3)} ({fmt(s['min'], 3)}–{fmt(s['max'], 3)})" if s.get("n") else "—"
