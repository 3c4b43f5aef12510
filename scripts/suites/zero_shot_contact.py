"""Suite ``zero_shot_contact``: the zero-shot network's foot-contact velocity loss (``model.contact_weight``) at the
network's full budget, chosen on **validation** clips (issue 27 item 1: raw samples whose feet stay planted).

    python scripts/benchmarks.py run zero_shot_contact --seeds 100 101 --weights 0 100

Suite ``contact_loss`` chose weight 100 for the zero-shot network on a narrowed run (one stance, one style, 30-epoch
networks with the style in their data); ``configs/model/zero_shot.yaml`` keeps 0 until a full-budget run confirms it.
This is that run, on the path ``stylemotion-style method=zero_shot`` takes today. Each arm is ``style_method``'s
leave-one-style-out (:func:`suites.style_method.seed_record`) on the same judges (suite ``contact_template``'s ``off``
runs, evaluated with ``evaluation.heldout_splits=[val]``), the same autoencoders without each style and the same
CVAEs on them (``seed<k>/``), and networks of the experiment's epoch count trained with ``model.contact_weight=w``
(``seed<k>_e<epochs>_contact<w>/``; ``w = 0`` is the configs' networks, ``seed<k>_e<epochs>/``), every one sampled as
``stylemotion-style`` samples today (``configs/model/zero_shot.yaml``: centred, τ = 1). Arms differ only in ``w``.

Rule (:func:`choose_weight`, fixed before any run): an arm ``w > 0`` **qualifies** when, over every (seed,
primitive, style) case, its samples' mean raw skating ÷ the style's real clips' is at least :data:`GAIN` (relative)
below the ``w = 0`` arm's, ``style_method``'s own-column and recognition tests pass (own-column rows no fewer than the
CVAE's, mean recognition ≥ min(0.9, the CVAE's)) and its mean capped log variation is no more than
``style_method.TIE`` below the ``w = 0`` arm's. Among qualifying arms the lowest skating wins (arms within
:data:`GAIN` of it relative: the smallest ``w``); then the network's ``contact_weight`` default becomes that ``w``.
When none qualifies it stays 0.
"""

from __future__ import annotations

import argparse
import copy
from typing import Any

from suites import contact_full, style_method, zero_shot_epochs, zero_shot_test
from suites.common import fmt, md_table, number_above, provenance_line, spread

DESCRIPTION = ("the zero-shot network's foot-contact velocity loss weight at full budget, chosen on validation "
               "clips by raw skating of its samples against the style's real clips")
DEFAULT_SEEDS = style_method.DEFAULT_SEEDS
DEFAULT_WEIGHTS = (0.0, 100.0)
#: Relative skating reduction an arm must reach over ``w = 0``; arms this close to the lowest count as tied.
GAIN = 0.1


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style_method.leave_one_out_arguments(parser)
    parser.add_argument("--weights", type=number_above(0, kind=float), nargs="+", default=list(DEFAULT_WEIGHTS),
                        help="the networks' model.contact_weight, one arm each (0, the configs' networks, is always "
                             "an arm: the rule compares with it)")
    parser.add_argument("--epochs", type=number_above(1), default=None,
                        help="epochs of the networks (default: the zero_shot experiment's)")


def arm_key(weight: float) -> str:
    return f"{weight:g}"


def arm_args(args: argparse.Namespace, weight: float, epochs: int) -> argparse.Namespace:
    """``style_method.seed_record``'s options for the arm of ``weight``: its networks' override and folder tag, the
    experiment's epochs and today's sampling."""
    sample = zero_shot_test.sampling()
    out = copy.copy(args)
    out.epochs, out.temperature, out.centred = epochs, sample["sample_temperature"], sample["sample_centred"]
    out.network_overrides, out.networks_tag = style_method.contact_networks(weight)
    return out


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    epochs = args.epochs or style_method.experiment_epochs()
    judges = {seed: style_method.judge_for(args, seed) for seed in seeds}
    per_arm, arms = zero_shot_epochs.run_arms(args, judges, {arm_key(w): arm_args(args, w, epochs)
                                                             for w in sorted({0.0, *args.weights})})
    return {"epochs": epochs, "sampling": zero_shot_test.sampling(),
            **zero_shot_epochs.arms_record(args, per_arm, arms), "choice": choose_weight(arms)}


def choose_weight(arms: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The module doc's rule over ``{w: arm_summary}`` (``w`` as :func:`arm_key` writes it; ``"0"`` required)."""
    off = arms["0"]["summary"]["zero_shot"]
    why: dict[str, str] = {}
    for w, arm in arms.items():
        if w == "0":
            continue
        s, tests = arm["summary"]["zero_shot"], arm["choice"]["tests"]
        failed = [name for name, ok in (
            ("skating", s["skating_vs_real"]["mean"] <= (1 - GAIN) * off["skating_vs_real"]["mean"]),
            ("own_column", tests["own_column"]), ("recognition", tests["recognition"]),
            ("variation", s["capped_log_variation"] >= off["capped_log_variation"] - style_method.TIE)) if not ok]
        why[w] = "qualifies" if not failed else "fails " + ", ".join(failed)
    qualifying = [w for w, text in why.items() if text == "qualifies"]
    if not qualifying:
        return {"weight": 0.0, "qualifying": [], "why": why, "how": "no arm qualifies: the weight stays 0"}
    skating = {w: arms[w]["summary"]["zero_shot"]["skating_vs_real"]["mean"] for w in qualifying}
    best = min(skating.values())
    near = [w for w in qualifying if skating[w] <= best * (1 + GAIN)]
    return {"weight": min(float(w) for w in near), "qualifying": qualifying, "why": why,
            "how": "the qualifying arm with the lowest skating (ties: the smallest weight)"}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice, sd = r["choice"], contact_full.sd
    label, seeds, full, same = zero_shot_epochs.arms_frame(r)
    order = sorted(r["arms"], key=float)
    rows = []
    for w in order:
        s = r["arms"][w]["summary"]["zero_shot"]
        rows.append([f"zero-shot, contact weight {w}", f"{s['own_column']}/{s['cases']}", sd(s["recognition"], 3),
                     *(sd(s[k]) for k in style_method.VARIATION), fmt(s["capped_log_variation"], 3),
                     sd(s["skating"], 3), sd(s["skating_vs_real"], 1), choice["why"].get(w, "the reference")])
    cv = r["arms"][order[0]]["summary"]["cvae_unseen"]
    rows.append([style_method.LABELS["cvae_unseen"], f"{cv['own_column']}/{cv['cases']}", sd(cv["recognition"], 3),
                 *(sd(cv[k]) for k in style_method.VARIATION), fmt(cv["capped_log_variation"], 3),
                 sd(cv.get("skating", {}), 3), sd(cv.get("skating_vs_real", {}), 1), ""])
    verdict = (f"**the network's contact_weight default becomes {choice['weight']:g}** ({choice['how']})"
               if choice["weight"] else f"the network's contact_weight **stays 0** ({choice['how']})")
    if not full:
        verdict = f"weight {choice['weight']:g} by the rule, **not applied**: a narrowed run"
    sample = r["sampling"]
    real = spread(c["real_skating"] for seed in r["per_arm"][order[0]].values() for c in seed["cases"].values()
                  if c.get("real_skating") is not None)
    rebuilt = style_method.reconstruction_skating(
        [c for seed in r["per_arm"][order[0]].values() for c in seed["cases"].values()])
    headline = (
        f"{label}The zero-shot network's foot-contact velocity loss on **validation** clips ({r['data']}, training "
        f"seeds {', '.join(seeds)}: not reported seeds; networks of {r['epochs']} epochs, sampled at τ = "
        f"{sample['sample_temperature']:g}{', centred' if sample['sample_centred'] else ''}): suite style_method's "
        f"leave-one-style-out per arm, the autoencoders without each style and the CVAEs on them shared; {same}. "
        f"Skating: share of contact foot-frames sliding > 0.2 m/s in raw samples, and its multiple of the style's "
        f"real clips' (train + val clips but the example; they skate {sd(real, 3)}).{rebuilt} Other figures as in "
        f"style_method's block. Rule: skating ÷ real ≥ {GAIN:g} below weight 0's, style_method's own-column and "
        f"recognition tests, variation within {style_method.TIE:g} of weight 0's. Verdict: {verdict}.\n\n"
        + md_table(["model", "own column", "recognition", "V_SD / style", "step_SD / style", "diversity / style",
                    "mean capped log variation", "raw skating", "skating × real clips", "rule"], rows)
        + f"\n\n{provenance_line(record)}")
    return {"headline": headline, "styles": f"{render_styles(r, order)}\n\n{provenance_line(record)}"}


def render_styles(r: dict[str, Any], order: list[str]) -> str:
    """Per left-out style: the zero-shot network's recognition and skating × real at each weight."""
    styles = zero_shot_epochs.zero_shot_by_style(r)
    sd = contact_full.sd
    rows = [[style, *(cell for w in order for cell in (
        sd(spread(c["recognition"] for c in by_arm.get(w, [])), 3),
        sd(spread(c.get("skating_vs_real") for c in by_arm.get(w, [])), 1)))] for style, by_arm in styles.items()]
    header = [h for w in order for h in (f"weight {w}: recognition", "skating × real")]
    return ("The zero-shot network per left-out style, mean ± sd (min–max) over training seeds and primitives "
            "(same runs as above).\n\n" + md_table(["style", *header], rows))
