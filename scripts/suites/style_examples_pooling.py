"""Suite ``style_examples_pooling``: how the zero-shot network should pool several example clips of a new style
(``mean`` or ``per_sample``), chosen on **validation** clips (issue 27 item 2).

    python scripts/benchmarks.py run style_examples_pooling --seeds 100 101

Suite ``style_examples_test``'s curve on the validation evaluations instead of the test ones: the networks of suite
``style_method``'s leave-one-style-out (training seeds 100 and 101, not reported seeds; the same networks suite
``zero_shot_test`` reports on test clips), their evaluation sampled as ``stylemotion-style`` samples today
(``runs/benchmarks/style_method/<data>/seed<k>_e<epochs>…_t<τ>[_centred]/``, judged by suite ``contact_template``'s
``off`` runs, ``evaluation.heldout_splits=[val]``), k clips drawn from the style's train split, figures against the
style's **validation** clips.

Rule (:func:`choose_pooling`), written after suite ``style_examples_test``'s test curve had been seen (so this
validation run can only confirm or refuse what it showed, and its rule is the issue's own aims): ``per_sample``
becomes the pooling of several examples when, at k = 4 over every (seed, primitive, style) case, it meets issue 27's
k = 4 aims (V_SD and step_SD ≥ 0.8, diversity ≥ 0.7 of the style's clips, recognition ≥ 0.9) in more cases than
``mean``, its own-column rows are no fewer than ``mean``'s and its mean recognition is ≥ 0.9. Else ``mean`` stays.
"""

from __future__ import annotations

import argparse
from typing import Any

from suites import style_examples, style_examples_test
from suites.common import fmt, md_table, provenance_line

DESCRIPTION = ("the zero-shot network's pooling of several examples of a new style (mean or per_sample), chosen on "
               "validation clips at k = 4")
DEFAULT_SEEDS = (100, 101)
K = 4


def add_arguments(parser: argparse.ArgumentParser) -> None:
    style_examples_test.add_arguments(parser)


def validation_folder() -> str:
    """The validation evaluation of a seed for today's network settings (suite zero_shot_test's folder without
    ``_test``; ``{seed}`` left in)."""
    return style_examples_test.evaluation_folder().removesuffix("_test")


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    args.folder = args.folder or validation_folder()
    protocol = style_examples_test.protocol(args)
    protocol["splits"] = {**protocol["splits"], "reference": "the left-out style's validation-split clips (judges "
                                                             "evaluated with evaluation.heldout_splits=[val])",
                          "judge": "suite contact_template's off run of the seed (its classifier fitted on train "
                                   "clips)"}
    result = style_examples.run(args, seeds, protocol)
    return {**result, "choice": choose_pooling(result)}


def case_counts(results: dict[str, Any], label: str) -> dict[str, Any]:
    """At one row (``"4"``, ``"4 per_sample"``), over every (seed, primitive, style): cases meeting the k = 4 aims,
    own-column rows, mean recognition."""
    headline = results["headline"][label]
    seeds = max(1, headline["recognition"]["n"])
    return {"aims_met": round(headline["aims_met"]["mean"] * seeds), "own_column": round(
        headline["own_column_is_minimum"]["mean"] * seeds), "recognition": headline["recognition"]["mean"],
        "cases": headline["rows_per_seed"] * seeds}


def choose_pooling(results: dict[str, Any]) -> dict[str, Any]:
    """The module doc's rule at k = :data:`K`."""
    mean, per = case_counts(results, str(K)), case_counts(results, f"{K} per_sample")
    tests = {"aims_met": per["aims_met"] > mean["aims_met"], "own_column": per["own_column"] >= mean["own_column"],
             "recognition": per["recognition"] >= style_examples.AIM_RECOGNITION}
    return {"mean": mean, "per_sample": per, "tests": tests,
            "pooling": "per_sample" if all(tests.values()) else "mean"}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice = r["choice"]
    text = (f"Networks of suite style_method (`{r['loso']}/{r['folder']}`), judged on **validation** clips; "
            f"otherwise as suite style_examples_test.")
    blocks = style_examples.render_curve(record, "The zero-shot network from k examples of a style it never saw, on "
                                                 "validation clips", "left-out style", text)
    rows = [[pooling, f"{c['aims_met']}/{c['cases']}", f"{c['own_column']}/{c['cases']}", fmt(c["recognition"], 3)]
            for pooling, c in (("mean", choice["mean"]), ("per_sample", choice["per_sample"]))]
    failed = ", ".join(k for k, ok in choice["tests"].items() if not ok) or "none"
    verdict = (f"**per_sample** (tests failed: {failed})" if choice["pooling"] == "per_sample"
               else f"**mean** stays (tests failed: {failed})")
    blocks["choice"] = (f"Pooling of several examples at k = {K}, over every (seed, primitive, style) case on "
                        f"validation clips: {verdict}.\n\n"
                        + md_table(["pooling", "cases meeting the k = 4 aims", "own-column rows",
                                    "mean recognition"], rows) + f"\n\n{provenance_line(record)}")
    return blocks
