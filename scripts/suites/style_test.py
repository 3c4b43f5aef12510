"""Suite ``style_test``: suite ``style_bandai``'s runs judged on the **test split only** (issue 27's aims are test
figures), its results in ``benchmarks/results/style_test.json``.

    python scripts/benchmarks.py run style_test --workers 2

The same runs as suite ``style_bandai`` (``runs/benchmarks/style/bandai/full/seed<k>``, every stage reused or trained
the same way) and a second report of each, ``report_test`` (``stylemotion-reproduce ... report=report_test
evaluation.heldout_splits=[test] evaluation.style_truth=heldout``): the classifier scored on test clips and every
model judged against its style's test-split clips only — no clip the validation suites (``evaluation.heldout_splits
=[val]``: the train and val clips of each style) chose a default on. Nothing is chosen here.
"""

from __future__ import annotations

import argparse

from suites import style

DESCRIPTION = "style VAEs/CVAEs (Du ch. 5) on Bandai walks over seeds, judged on test-split clips only"
DEFAULT_SEEDS = style.DEFAULT_SEEDS
run = style.run
render = style.render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style.add_arguments(parser)
    parser.set_defaults(data="bandai", report_on="test")
