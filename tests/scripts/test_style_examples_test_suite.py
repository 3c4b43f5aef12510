"""Suite ``style_examples_test`` (scripts/suites/style_examples_test.py): it reads the very folders suite
``zero_shot_test`` writes for today's network settings, and its options (no training, no data)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_examples_test, style_method, zero_shot_test  # noqa: E402


class Written(Exception):
    """Raised by the stand-in evaluation with the folder it was asked to write."""


def test_the_curve_reads_the_evaluation_folder_zero_shot_test_writes(monkeypatch, tmp_path) -> None:
    from stylemotion.evaluation import zero_shot as library

    def evaluation(judge, out, *args, **kwargs):
        raise Written(out)

    source = SimpleNamespace(settings=SimpleNamespace(heldout_splits=["test"], style_truth="heldout"))
    monkeypatch.setattr(library, "read_run", lambda folder, report: source)
    monkeypatch.setattr(library, "leave_one_style_out", evaluation)
    parser = argparse.ArgumentParser(prog="zero_shot_test")
    zero_shot_test.add_arguments(parser)
    args = parser.parse_args(["--runs", str(tmp_path)])
    with pytest.raises(Written) as written:
        style_method.seed_record(zero_shot_test.seed_options(args), 101, Path("judge"))
    out = Path(str(written.value))
    assert out.parent == tmp_path / "bandai"
    assert out.name == style_examples_test.evaluation_folder().format(seed=101)


def test_the_options_default_to_the_bandai_evaluations_and_both_poolings() -> None:
    parser = argparse.ArgumentParser(prog="style_examples_test")
    style_examples_test.add_arguments(parser)
    args = parser.parse_args([])
    assert args.data == "bandai" and args.pooling == ["mean", "per_sample"] and args.folder is None
    assert args.loso == ROOT / "runs" / "benchmarks" / "style_method" / "bandai" and args.ks == [1, 2, 4, 8]


def headline(aims: float, own: float, recognition: float, seeds: int = 2) -> dict:
    """One curve row's headline over ``seeds`` seeds of 12 cases each (per-seed means as given)."""
    def one(value: float) -> dict:
        return {"mean": value, "n": seeds}

    return {"aims_met": one(aims), "own_column_is_minimum": one(own), "recognition": one(recognition),
            "rows_per_seed": 12}


def test_per_sample_pooling_wins_only_with_more_aims_met_no_fewer_own_columns_and_recognition() -> None:
    from suites import style_examples_pooling

    results = {"headline": {"4": headline(1.0, 8.0, 0.998), "4 per_sample": headline(6.5, 9.0, 0.99)}}
    chosen = style_examples_pooling.choose_pooling(results)
    assert chosen["pooling"] == "per_sample" and chosen["per_sample"] == {
        "aims_met": 13, "own_column": 18, "recognition": 0.99, "cases": 24}
    fewer_rows = {"headline": {"4": headline(1.0, 8.0, 0.998), "4 per_sample": headline(6.5, 7.5, 0.99)}}
    assert style_examples_pooling.choose_pooling(fewer_rows)["tests"] == {
        "aims_met": True, "own_column": False, "recognition": True}
    unrecognized = {"headline": {"4": headline(1.0, 8.0, 0.998), "4 per_sample": headline(6.5, 9.0, 0.85)}}
    assert style_examples_pooling.choose_pooling(unrecognized)["pooling"] == "mean"
    assert style_examples_pooling.validation_folder() == \
        style_examples_test.evaluation_folder().removesuffix("_test")
