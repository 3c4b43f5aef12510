"""Suite ``style_term``: what the style CVAE's style term sees and how it pulls (``model.style_term``,
``model.style_latents``, ``model.style_margin``), chosen on **validation** clips of Bandai walks at the config's α.

    python scripts/benchmarks.py run style_term --seeds 0 --primitives walk_leftStance

The same machinery as suite ``style_alpha`` (:func:`suites.style.choose_cvae_setting`): per candidate, CVAEs of
``--alpha-styles`` seeded styles trained with seed ``--alpha-seed`` (not a reported seed) on the autoencoder of the
first seed's reproduction. The rule is α's (stylemotion/training/style_weight.py) over
:data:`~stylemotion.training.style_weight.SAMPLE_METRICS`: the logged ``val/style`` measures what each candidate's
term sees (posterior decodes, prior decodes or both), so the style figure is ``samples/style`` instead, the Gram
distance of the same 256 prior samples to the example; ``val/mpjpe`` and the samples' spread as for α.

``style_centred`` is not a candidate: its term compares Gram matrices of centred features, so its samples' style
distance measures another quantity than the others'. α is held at the config's value (chosen by suite
style_alpha with the default term): a coordinate choice, not a joint grid.
"""

from __future__ import annotations

import argparse
from typing import Any

from suites import style
from suites.common import fmt, md_table, provenance_line

DESCRIPTION = "the style CVAE's style-term options chosen on Bandai validation clips (candidates, scores, choice)"
DEFAULT_SEEDS = (0,)

#: candidate name → the ``model.*`` overrides it trains with (the first is the config's default, the thesis' term)
CANDIDATES: dict[str, list[str]] = {
    "distance-both": ["model.style_term=distance", "model.style_latents=both", "model.style_margin=1.0"],
    "distance-posterior": ["model.style_term=distance", "model.style_latents=posterior", "model.style_margin=1.0"],
    "distance-prior": ["model.style_term=distance", "model.style_latents=prior", "model.style_margin=1.0"],
    "margin1-both": ["model.style_term=margin", "model.style_latents=both", "model.style_margin=1.0"],
    "margin2-both": ["model.style_term=margin", "model.style_latents=both", "model.style_margin=2.0"],
}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style.add_arguments(parser)
    parser.add_argument("--terms", nargs="+", choices=sorted(CANDIDATES), default=list(CANDIDATES),
                        help="candidates (default: all)")
    parser.set_defaults(data="bandai")


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.training.style_weight import SAMPLE_METRICS

    styles = style.sample_styles(args.data, args.sample_styles)
    candidates = {name: CANDIDATES[name] for name in args.terms}
    choice = style.choose_cvae_setting(args, seeds[0], args.primitives, styles, candidates, "term", SAMPLE_METRICS)
    return {"data": args.data, "primitives": args.primitives, "candidates": candidates,
            "splits": {"choose": "validation clips of the data's take split (val/mpjpe at the best val/loss epoch) "
                                 "and prior samples (no data read); no test clip is read",
                       "seed": f"candidates trained with seed {args.alpha_seed}, not a reported seed; the autoencoder "
                               f"is seed {seeds[0]}'s reproduction stage"},
            "choice": {**choice, "rule": "min over candidates of the mean over styles of log(samples/style ÷ min) + "
                                         "log(val/mpjpe ÷ min) + log(max ÷ samples/pose_across_sd) "
                                         "(stylemotion/training/style_weight.py, SAMPLE_METRICS)"}}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice = r["choice"]
    names = sorted({n for per in choice["values"].values() for n in per})
    rows = []
    for candidate, per in choice["values"].items():
        label = f"**{candidate}**" if candidate == choice["chosen"] else candidate
        overrides = ", ".join(o.removeprefix("model.") for o in r["candidates"][candidate])
        cells = [f"{fmt(per[n].get('samples/style'), 2)} / {fmt(per[n].get('val/mpjpe'), 4)} / "
                 f"{fmt(per[n].get('samples/pose_across_sd'), 2)}" if n in per else "failed" for n in names]
        rows.append([label, overrides, *cells, fmt(choice["scores"][candidate], 3)])
    default = next(iter(r["candidates"]))
    verdict = ("the config's default (the thesis' distance term on posterior and prior decodes) stays"
               if choice["chosen"] == default else f"{choice['chosen']} is chosen over the config's {default}")
    return {"headline": (
        f"The style term chosen on **validation** clips at the config's α: CVAEs of {', '.join(names)} trained with "
        f"seed {choice['seed']} (not a reported seed) on the autoencoder of seed {choice['autoencoder_of_seed']}'s "
        f"run; each cell is samples/style (Gram distance of 256 prior samples to the example) / val/mpjpe (m, "
        f"reconstruction of held-out neutral clips at the best val/loss epoch) / pose_across_SD (cm) of the same "
        f"samples. Rule: {choice['rule']}. Chosen: {choice['chosen']}: {verdict}. `style_centred` is not a "
        f"candidate (its term measures centred Gram matrices, another distance).\n\n"
        + md_table(["candidate", "overrides", *names, "score (lower is better)"], rows)
        + f"\n\n{provenance_line(record)}")}
