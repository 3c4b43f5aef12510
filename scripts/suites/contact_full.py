"""Suite ``contact_full``: the foot-contact loss weights that suite ``contact_loss`` chose on a narrowed run
(autoencoder 0.1, neutral VAE 100, CVAE 0; one stance, one style, 20/30-epoch models), confirmed or refused at the
reproduction's full budget on **validation** clips of every Bandai style (issue 27 item 1).

    python scripts/benchmarks.py run contact_full --seeds 100 101

Two arms per training seed (not reported seeds), both on the CVAE settings of suite ``style_channels``' choice
(``--cvae``, read from ``benchmarks/results/style_channels.json`` by default), each the user's ``stylemotion-reproduce
data=bandai`` (both walk stances, every style) evaluated with ``evaluation.heldout_splits=[val]`` (no test clip in the
figures the rule reads, as in suite ``style_channels``):

* ``off``: the configs' ``contact_weight`` 0. Its runs are suite ``style_channels``' runs of the chosen candidate
  (same folder, same settings), so they are reused, not trained again;
* ``contact``: ``model.contact_weight`` 0.1 for the autoencoder and 100 for the neutral VAE (the CVAE keeps 0, as
  suite ``contact_loss`` chose; it inherits the VAE's config but is trained with ``model.contact_weight=0``).

Rule (:func:`choose`, fixed before the run): ``contact`` is adopted when, over every (seed, stance), the neutral VAE's
samples skate less relative to the neutral val clips (mean of samples ÷ real) than ``off``'s; its styled cases are
eligible by suite ``style_channels``' rule (rows on the diagonal no fewer than ``off``'s, mean recognition ≥ min(0.9,
``off``'s)); and the styled samples' mean skating relative to their real clips is no higher than ``off``'s. Else
``off`` stays. The autoencoder's best val MPJPE is shown beside, not ruled on.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from suites import style, style_channels
from suites.common import fmt, md_table, provenance_line, spread

DESCRIPTION = ("the foot-contact loss weights of a narrowed run (autoencoder 0.1, VAE 100) confirmed or refused at "
               "full budget on Bandai validation clips of every style (raw skating against real clips)")
DEFAULT_SEEDS = (100, 101)
#: arm → stage kind → ``train`` overrides beyond the CVAE base (the first arm is the configs' default)
ARMS: dict[str, dict[str, list[str]]] = {
    "off": {},
    "contact": {"autoencoder": ["model.contact_weight=0.1"], "vae": ["model.contact_weight=100"],
                "cvae": ["model.contact_weight=0"]},
}
CHANNELS_RESULTS = style.ROOT / "benchmarks" / "results" / "style_channels.json"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style_channels.run_arguments(parser, "suite style_channels' run folder (its chosen candidate's runs are the off "
                                         "arm)")
    parser.add_argument("--base", default=None, metavar="CANDIDATE",
                        help="suite style_channels' candidate both arms build on (default: its recorded choice)")


def chosen_channels(path: Path = CHANNELS_RESULTS) -> str:
    """The candidate suite ``style_channels`` chose (its results file), refused in one line when there is none."""
    try:
        return str(json.loads(path.read_text())["results"]["choice"]["chosen"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise SystemExit(f"{path}: no style_channels choice to build on ({exc}); run suite style_channels first "
                         "or give --base") from None


def neutral_skating(report: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Per stance: the neutral VAE samples' and the neutral held-out clips' skating ratios."""
    out = {}
    for primitive, rows in report.get("foot_skating_detail", {}).items():
        row = rows.get("neutral") or {}
        out[primitive] = {"samples": (row.get("samples") or {}).get("ratio"),
                          "real": (row.get("real") or {}).get("ratio"),
                          "recognition": report["style_recognition"]["per_model_detail"][primitive]["neutral"]
                          ["share"]}
    return out


def relative(samples: float | None, real: float | None) -> float | None:
    """samples ÷ real skating, None when either is missing or the real clips never skate."""
    return samples / real if samples is not None and real else None


def arm_summary(per_seed: dict[str, dict[str, Any]], arm: str) -> dict[str, Any]:
    """Over every (seed, stance): the neutral VAE's and the styled cases' skating (÷ real) and the styled cases'
    rule figures (:func:`suites.style_channels.candidate_summary`)."""
    neutral = [v for seed in per_seed.values() for v in seed[arm]["neutral"].values()]
    cases = [c for seed in per_seed.values() for c in seed[arm]["cases"].values()]
    return {"styled": style_channels.candidate_summary(cases),
            "neutral_skating_relative": spread(relative(v["samples"], v["real"]) for v in neutral),
            "neutral_skating": spread(v["samples"] for v in neutral),
            "neutral_real_skating": spread(v["real"] for v in neutral),
            "neutral_recognition": spread(v["recognition"] for v in neutral),
            "styled_skating_relative": spread(relative(c["skating_samples"], c["skating_real"]) for c in cases),
            "autoencoder_val_mpjpe_m": spread(seed[arm]["autoencoder_val_mpjpe_m"] for seed in per_seed.values())}


def choose(summaries: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The module doc's rule: ``contact`` against ``off``; returns each test and the choice."""
    off, on = summaries["off"], summaries["contact"]
    eligible = style_channels.choose({"off": off["styled"], "contact": on["styled"]})["eligible"]["contact"]
    def means(key: str) -> tuple[float, float] | None:  # None: an arm without the figure (its feet never plant)
        pair = (on[key].get("mean"), off[key].get("mean"))
        return None if None in pair else pair

    neutral, styled = means("neutral_skating_relative"), means("styled_skating_relative")
    tests = {"neutral_skates_less": neutral is not None and neutral[0] < neutral[1],
             "styled_eligible": eligible,
             "styled_skate_no_more": styled is not None and styled[0] <= styled[1]}
    return {"tests": tests, "chosen": "contact" if all(tests.values()) else "off"}


def autoencoder_val_mpjpe(out: Path) -> float | None:
    """The autoencoder stage's best-epoch ``val/mpjpe`` (m) from its ``metrics.json``, None when absent."""
    try:
        return float(json.loads((out / "autoencoder" / "metrics.json").read_text())["val"]["val/mpjpe"])
    except (OSError, ValueError, KeyError, TypeError):
        return None


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch

    from stylemotion.io.jsonfile import read_json_object

    torch.set_num_threads(1)
    base = args.base or chosen_channels()
    base_cvae = style_channels.CANDIDATES[base]
    folders = {"off": base, "contact": f"{base}+contact"}
    per_seed: dict[str, dict[str, Any]] = {}
    for seed in seeds:
        for arm, stages in ARMS.items():
            out = args.runs / args.data / f"seed{seed}" / folders[arm]
            merged = {**stages, "cvae": [*base_cvae, *stages.get("cvae", [])]}
            report = style.reproduce_seed(args.data, seed, out, args.workers,
                                          extra=["evaluation.heldout_splits=[val]", *args.override],
                                          stages={k: v for k, v in merged.items() if v})
            styles = read_json_object(out / "data.json", "the reproduction's data summary",
                                      "rerun the suite")["cvae_styles"]
            per_seed.setdefault(str(seed), {})[arm] = {
                "run": str(out.relative_to(style.ROOT) if out.is_relative_to(style.ROOT) else out),
                "stages": merged, "heldout_splits": report["meta"]["settings"]["heldout_splits"],
                "autoencoder_val_mpjpe_m": autoencoder_val_mpjpe(out),
                "neutral": neutral_skating(report), "cases": style_channels.case_figures(report, styles)}
    summaries = {arm: arm_summary(per_seed, arm) for arm in ARMS}
    return {"data": args.data, "base": base, "arms": ARMS, "overrides": args.override,
            "splits": {"choose": "evaluation.heldout_splits=[val], as suite style_channels: no test clip is read by "
                                 "the figures the rule uses",
                       "seeds": "training seeds, not reported seeds"},
            "per_seed": per_seed, "summary": summaries, "choice": choose(summaries)}


def run_label(results: dict[str, Any]) -> str:
    """The bold warning a block of a synthetic or narrowed run opens with (empty for a full Bandai run)."""
    label = "**Synthetic data: a smoke run of the suite, not evidence.** " if results["data"] == "synthetic" else ""
    if results.get("overrides"):
        label += f"**Not the full budget: overrides {', '.join(results['overrides'])}.** "
    return label


def sd(s: dict[str, Any], digits: int = 2, scale: float = 1.0) -> str:
    """A spread as ``mean ± sd (min–max)``, each × ``scale``; ``—`` when empty."""
    return (f"{fmt(scale * s['mean'], digits)} ± {fmt(scale * s['sd'], digits)} ({fmt(scale * s['min'], digits)}–"
            f"{fmt(scale * s['max'], digits)})") if s.get("n") else "—"


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    label = run_label(r)
    rows = []
    for arm, s in r["summary"].items():
        st = s["styled"]
        overrides = "; ".join(f"{k}: {', '.join(v)}" for k, v in r["arms"][arm].items()) or "(the configs' 0)"
        rows.append([f"**{arm}**" if arm == r["choice"]["chosen"] else arm, overrides,
                     sd(s["neutral_skating"], 1, 100), sd(s["neutral_real_skating"], 1, 100),
                     sd(s["neutral_skating_relative"]), sd(s["neutral_recognition"], 3),
                     sd(st["skating_samples"], 1, 100), sd(st["skating_real"], 1, 100),
                     sd(s["styled_skating_relative"]), f"{st['rows_on_diagonal']}/{st['cases']}",
                     sd(st["recognition"], 3), sd(st["v_sd"]), sd(st["diversity"]),
                     sd(s["autoencoder_val_mpjpe_m"], 2, 100)])
    tests = ", ".join(f"{k.replace('_', ' ')}: {'yes' if v else 'no'}" for k, v in r["choice"]["tests"].items())
    verdict = ("the weights of the narrowed run are **adopted**" if r["choice"]["chosen"] == "contact"
               else "the configs' 0 **stays**")
    seeds = ", ".join(r["per_seed"])
    return {"headline": (
        f"{label}Foot-contact loss at the reproduction's budget on **validation** clips ({r['data']}, both walk "
        f"stances, every style, training seeds {seeds}: not reported seeds), on the CVAE settings of suite "
        f"style_channels' candidate `{r['base']}`; `evaluation.heldout_splits=[val]`. Skating: share of contact "
        f"foot-frames whose planted point moves > 0.2 m/s (%), of the samples and of the real val clips (neutral) or "
        f"the style's real clips besides its example (styled); mean ± sd (min–max) over (seed, stance) and, for the "
        f"styled models, styles. Rule: adopt the contact weights when the neutral VAE's samples skate less relative "
        f"to real clips, the styled models stay eligible by suite style_channels' rule, and the styled samples skate "
        f"no more relative to real clips. Tests: {tests}. Verdict: {verdict}. The autoencoder's best val MPJPE "
        f"(cm) is shown, not ruled on.\n\n"
        + md_table(["arm", "overrides", "neutral skating, samples (%)", "neutral skating, real (%)",
                    "neutral ÷ real", "neutral recognition", "styled skating, samples (%)",
                    "styled skating, real (%)", "styled ÷ real", "styled rows on diagonal", "styled recognition",
                    "styled V_SD / style", "styled diversity / style", "autoencoder val MPJPE (cm)"], rows)
        + f"\n\n{provenance_line(record)}")}
