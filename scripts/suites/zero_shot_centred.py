"""Suite ``zero_shot_centred``: the zero-shot network sampled with its variation centred on the example
(``model.sample_centred``), chosen on **validation** clips, and with it stylemotion-style's ``method`` (issue 27
item 3).

    python scripts/benchmarks.py run zero_shot_centred --seeds 100 101

Suite ``zero_shot_temperature`` found that a smaller τ makes the network's unseen styles worse, not better: the codes
nearest the prior's centre decode farthest from the style. The anchored network decodes the example plus a variation;
for a style it never saw, the variation's mean over the prior is not zero but a shift towards styles it knows. Centred
sampling takes that mean off (:meth:`stylemotion.models.zero_shot.ZeroShotStyleVAE.variation_centre`, over 1,024 prior
codes), so the samples spread around their example with the variation's spread kept. Everything else is suite
``zero_shot_temperature``'s (the same judges, autoencoders, CVAEs and 10-epoch networks; arms ``--temperatures``,
default τ = 1 only; the evaluation of an arm in ``seed<k>_e<epochs>_t<τ>_centred/``).

Rule (fixed before any run, suite ``zero_shot_temperature``'s): an arm qualifies when ``style_method``'s whole rule
gives ``zero_shot`` on it; the qualifying arm with the most variation wins (ties: the larger τ), and then
``method=zero_shot`` becomes the default, sampled centred at that τ. When none qualifies, ``method=cvae`` stays and
centring stays off.
"""

from __future__ import annotations

import argparse

from suites import zero_shot_temperature

DESCRIPTION = ("the zero-shot network sampled with its variation centred on the example (model.sample_centred) and "
               "with it stylemotion-style's method, chosen on validation clips")
DEFAULT_SEEDS = zero_shot_temperature.DEFAULT_SEEDS
run = zero_shot_temperature.run
render = zero_shot_temperature.render


def add_arguments(parser: argparse.ArgumentParser) -> None:
    zero_shot_temperature.add_arguments(parser)
    parser.set_defaults(centred=True, temperatures=[1.0])
