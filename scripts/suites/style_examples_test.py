"""Suite ``style_examples_test``: stylemotion-style's default path for a new style (the zero-shot network, sampled as
``configs/model/zero_shot.yaml`` says) conditioned on k = 1, 2, 4, 8 clips of a style it never saw, judged against
the style's **test** clips only (issue 27 item 2: a user who recorded several takes of a style).

    python scripts/benchmarks.py run style_examples_test --seeds 100 101 102

No network is trained here: the suite reads suite ``zero_shot_test``'s leave-one-style-out evaluations (per training
seed, ``runs/benchmarks/style_method/<data>/seed<k>_e<epochs>…_test/zero_shot.json``: an autoencoder and a network
per primitive that never saw the style, each seed judged by one of suite style_bandai's reproductions through its test
report) and runs suite ``style_examples``' curve on them (:func:`suites.style_examples.style_curve`): k clips of the
style drawn from its **train** split (nested draws), pooled by their mean (``stylemotion-style example=[…]``'s) and,
in rows named per_sample, one clip per sample; every network sampled as that evaluation sampled it (centred, τ = 1);
figures against the style's test-split clips (the judge's ``report_test``: its classifier fitted on train clips).
Nothing is chosen here; issue 27's aims at k = 4 are counted per style.
"""

from __future__ import annotations

import argparse
from typing import Any

from suites import style_examples, style_method, zero_shot_test

DESCRIPTION = ("stylemotion-style's default (the zero-shot network) from k = 1, 2, 4, 8 train-split clips of a style "
               "it never saw, judged on the style's test clips (suite zero_shot_test's trainings, no training)")
DEFAULT_SEEDS = zero_shot_test.DEFAULT_SEEDS


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style_examples.add_arguments(parser, style_method.ROOT / "runs" / "benchmarks" / "style_method" / "bandai")
    parser.set_defaults(data="bandai", pooling=["mean", "per_sample"])
    parser.add_argument("--folder", default=None,
                        help="each seed's evaluation folder under --loso, {seed} filled in (default: suite "
                             "zero_shot_test's for today's network settings)")


def evaluation_folder() -> str:
    """Suite zero_shot_test's evaluation folder of a seed for today's network settings (``{seed}`` left in)."""
    sample, epochs = zero_shot_test.sampling(), style_method.experiment_epochs()
    _, tag = style_method.contact_networks(zero_shot_test.contact_weight())
    return (f"seed{{seed}}_e{epochs}{tag}_t{sample['sample_temperature']:g}"
            f"{'_centred' if sample['sample_centred'] else ''}_test")


def protocol(args: argparse.Namespace) -> dict[str, Any]:
    """Where this suite's models come from and what each split serves (recorded with its results)."""
    return {"loso": style_examples.relative(args.loso.expanduser()), "folder": args.folder,
            "splits": {"examples": "k clips of the left-out style drawn from its train-split clips (nested: one seeded "
                                   "permutation per seed, primitive and style)",
                       "reference": "the left-out style's test-split clips (the judge's report_test)",
                       "judge": "suite zero_shot_test's judge of the seed: a style_bandai reproduction, its "
                                "autoencoder (Table 5.1) and style classifier (fitted on train-split clips)",
                       "networks": "suite zero_shot_test's leave-one-style-out trainings (autoencoder and network "
                                   "without the style), sampled as it sampled them; nothing trained here",
                       "seed_varies": "the trainings and their judge, the example draws and the samples"}}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    args.folder = args.folder or evaluation_folder()
    return style_examples.run(args, seeds, protocol(args))


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    text = (f"stylemotion-style's default networks (suite zero_shot_test's, `{r['loso']}/{r['folder']}`: per seed an "
            f"autoencoder and a network that never saw the left-out style, sampled centred as stylemotion-style "
            f"samples them), each conditioned on k clips of the style drawn from its train split (nested draws), "
            f"pooled by their mean (as `stylemotion-style example=[…]` pools them) or, in rows named per_sample, one "
            f"clip drawn per sample; {r['samples']:,} samples per network, k and seed, judged by run(s) "
            f"{', '.join(r['judge'])} through their test reports. Variation as a share of the style's **test** "
            f"clips.")
    return style_examples.render_curve(record, "The default for a new style from k examples of a style it never saw, "
                                               "on test clips", "left-out style", text)
