"""Suite ``zero_shot_bandai``: suite ``zero_shot`` on Bandai dataset-2's walks, its results kept apart from the
synthetic smoke run (``benchmarks/results/zero_shot_bandai.json``). The same options; ``--data`` defaults to
``bandai``.

    python scripts/benchmarks.py run zero_shot_bandai --run runs/benchmarks/style/bandai/walk_leftStance/seed0 \
        --epochs 10
"""

from __future__ import annotations

import argparse
from typing import Any

from suites import zero_shot

DESCRIPTION = "zero-shot style network on Bandai walks: leave one style out without leakage, over seeds"
DEFAULT_SEEDS = zero_shot.DEFAULT_SEEDS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    zero_shot.add_arguments(parser)
    parser.set_defaults(data="bandai")


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    return zero_shot.run(args, seeds)


def render(record: dict[str, Any]) -> dict[str, str]:
    return zero_shot.render(record)
