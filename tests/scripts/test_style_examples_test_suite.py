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
