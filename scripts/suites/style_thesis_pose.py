"""Suite ``style_thesis_pose``: suite ``style_thesis``'s pose-only Gram arm beside ours at the reproduction's CVAE
budget (60 epochs), where ours is styled (the 15-epoch run of ``style_thesis`` is too short to tell).

    python scripts/benchmarks.py run style_thesis_pose --seeds 0 1 2

The same data, autoencoder, neutral VAE, evaluation and figures as ``style_thesis`` (its module doc), arms ``ours``
and ``pose_gram`` only. An ablation: nothing is chosen from it.
"""

from __future__ import annotations

import argparse
from typing import Any

from suites import style_thesis

DESCRIPTION = ("the style CVAE's Gram over pose-only features (root velocity and yaw rate left out) beside ours at the "
               "reproduction's 60 epochs: Tables 5.1-5.3 figures on Bandai walks")
DEFAULT_SEEDS = (0, 1, 2)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style_thesis.add_arguments(parser)
    parser.set_defaults(arms=["ours", "pose_gram"], epochs=60)


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    return style_thesis.run(args, seeds)


def render(record: dict[str, Any]) -> dict[str, str]:
    return style_thesis.render(record)
