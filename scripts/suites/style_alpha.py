"""Suite ``style_alpha``: the style CVAE's style weight α chosen on **validation** clips of Bandai walks, before any
figure is reported with it (stylemotion/training/style_weight.py has the rule).

    python scripts/benchmarks.py run style_alpha --seeds 0 --primitives walk_leftStance --alphas 1 5 15 50 200

For each candidate α, CVAEs of ``--alpha-styles`` seeded styles are trained with seed ``--alpha-seed`` (not a
reported seed) on the autoencoder of the reproduction of ``--seeds``' first seed (trained here when missing, the same
stage suite ``style_bandai`` then reuses); their ``val/style`` and ``val/mpjpe`` at the best ``val/loss`` epoch
decide. The chosen α becomes the default (``configs/budget/default.yaml``, ``configs/model/style_cvae.yaml``) that
suite ``style_bandai`` reports with. Finished candidates are reused (``candidate.json`` in their folders).
"""

from __future__ import annotations

import argparse
from typing import Any

from suites import style
from suites.common import provenance_line

DESCRIPTION = "style weight α of the style CVAEs chosen on Bandai validation clips (the rule, candidates, scores)"
DEFAULT_SEEDS = (0,)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style.add_arguments(parser)
    parser.set_defaults(data="bandai", alphas=[1.0, 5.0, 15.0, 50.0, 200.0])


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    styles = style.sample_styles(args.data, args.sample_styles)
    choice = style.choose_alpha(args, seeds[0], args.primitives, styles)
    return {"data": args.data, "primitives": args.primitives,
            "splits": {"choose": "validation clips of the data's take split (val/style, val/mpjpe at the best "
                                 "val/loss epoch); no test clip is read",
                       "seed": f"candidates trained with seed {args.alpha_seed}, not a reported seed; the autoencoder "
                               f"is seed {seeds[0]}'s reproduction stage"},
            "alpha_choice": choice}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    blocks = style.alpha_blocks(r["alpha_choice"], provenance_line(record))
    return {"headline": blocks["alpha"]}
