"""Suite ``zero_shot_bandai``: suite ``zero_shot`` on Bandai dataset-2's walks, its results kept apart from the
synthetic smoke run (``benchmarks/results/zero_shot_bandai.json``). The same options; ``--data`` defaults to
``bandai``.

    python scripts/benchmarks.py run zero_shot_bandai --run runs/benchmarks/style/bandai/walk_leftStance/seed0 \
        --epochs 10
"""

from __future__ import annotations

from suites import zero_shot
from suites.common import bandai_arguments

DESCRIPTION = "zero-shot style network on Bandai walks: leave one style out without leakage, over seeds"
DEFAULT_SEEDS = zero_shot.DEFAULT_SEEDS
add_arguments = bandai_arguments(zero_shot)
run = zero_shot.run
render = zero_shot.render
