"""Suite ``style_bandai``: suite ``style`` on Bandai dataset-2's walks, its results kept apart from the synthetic
smoke run (``benchmarks/results/style_bandai.json``). The same options; ``--data`` defaults to ``bandai``.

    python scripts/benchmarks.py run style_bandai --primitives walk_leftStance --alphas 1 5 15 50 200
"""

from __future__ import annotations

import argparse
from typing import Any

from suites import style

DESCRIPTION = "style VAEs/CVAEs (Du ch. 5) on Bandai walks: α chosen on validation clips, then seeds"
DEFAULT_SEEDS = style.DEFAULT_SEEDS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style.add_arguments(parser)
    parser.set_defaults(data="bandai")


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    return style.run(args, seeds)


def render(record: dict[str, Any]) -> dict[str, str]:
    return style.render(record)
