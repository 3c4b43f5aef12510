"""Suite ``style_bandai``: suite ``style`` on Bandai dataset-2's walks, its results kept apart from the synthetic
smoke run (``benchmarks/results/style_bandai.json``). The same options; ``--data`` defaults to ``bandai``.

    python scripts/benchmarks.py run style_bandai --primitives walk_leftStance --workers 2

α is the default chosen on validation clips by suite ``style_alpha`` (``--alphas`` would choose again here).
"""

from __future__ import annotations

from suites import style
from suites.common import bandai_arguments

DESCRIPTION = "style VAEs/CVAEs (Du ch. 5) on Bandai walks over seeds, α as chosen by suite style_alpha"
DEFAULT_SEEDS = style.DEFAULT_SEEDS
add_arguments = bandai_arguments(style)
run = style.run
render = style.render
