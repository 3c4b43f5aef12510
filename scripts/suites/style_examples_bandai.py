"""Suite ``style_examples_bandai``: suite ``style_examples`` on the Bandai leave-one-style-out trainings of suite
``zero_shot_bandai``, its results kept apart from the synthetic smoke run
(``benchmarks/results/style_examples_bandai.json``). The same options; ``--data`` defaults to ``bandai``.

    python scripts/benchmarks.py run style_examples_bandai \
        --loso runs/benchmarks/zero_shot/bandai/loso_<judge>_e10
"""

from __future__ import annotations

from suites import style_examples
from suites.common import bandai_arguments

DESCRIPTION = ("zero-shot style network on Bandai walks conditioned on k = 1, 2, 4, 8 examples of a style it never "
               "saw, over seeds")
DEFAULT_SEEDS = style_examples.DEFAULT_SEEDS
add_arguments = bandai_arguments(style_examples)
run = style_examples.run
render = style_examples.render
