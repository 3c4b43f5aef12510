"""scripts/benchmarks.py: results files carry their provenance, render rewrites only marked blocks, and the
committed documents are exactly what their results files render."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def runner():
    spec = importlib.util.spec_from_file_location("benchmarks_runner", ROOT / "scripts" / "benchmarks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_committed_documents_are_what_their_results_render(runner, capsys) -> None:
    """The aim of issue 24: `render` on a clean checkout changes nothing."""
    status = runner.main(["render", "--check"])
    assert status == 0, capsys.readouterr().out


def test_render_replaces_only_the_marked_block_and_refuses_unknown_ones(runner, tmp_path) -> None:
    record = json.loads((ROOT / "benchmarks" / "results" / "actors.json").read_text())
    block = runner.load_suite("actors").render(record)["headline"]
    text = "before 1.5\n<!-- begin: actors/headline -->\nstale 9.9\n<!-- end: actors/headline -->\nafter 2.5\n"
    new = runner.rendered(text, tmp_path / "doc.md", {})
    assert new.startswith("before 1.5\n<!-- begin: actors/headline -->\n") and new.endswith(
        "<!-- end: actors/headline -->\nafter 2.5\n")
    assert "stale 9.9" not in new and block.strip() in new
    with pytest.raises(runner.BenchmarkError, match="renders no block 'nope'"):
        runner.rendered("<!-- begin: actors/nope -->\n<!-- end: actors/nope -->", tmp_path / "doc.md", {})
    with pytest.raises(runner.BenchmarkError, match="no results file"):
        runner.rendered("<!-- begin: zzz_none/headline -->\n<!-- end: zzz_none/headline -->", tmp_path / "d.md", {})


def test_unknown_suite_is_one_line_naming_the_suites(runner, capsys) -> None:
    assert runner.main(["run", "no_such_suite"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "no suite 'no_such_suite'" in err and "actors" in err


TINY_SUITE = """
DESCRIPTION = "a tiny suite for the runner's test"
def run(args, seeds):
    return {"splits": {"kind": "none"}, "squares": [s * s for s in seeds]}
def render(record):
    return {"headline": str(record["results"]["squares"])}
"""


def test_run_writes_results_with_command_commit_machine_load_and_seeds(runner, tmp_path, monkeypatch,
                                                                      capsys) -> None:
    (tmp_path / "tiny.py").write_text(TINY_SUITE)
    (tmp_path / "silent.py").write_text(TINY_SUITE.replace('"splits": {"kind": "none"}, ', ""))
    monkeypatch.setattr(runner, "SUITES", tmp_path)
    out = tmp_path / "tiny.json"
    assert runner.main(["run", "tiny", "--seeds", "2", "3", "--out", str(out)]) == 0
    record = json.loads(out.read_text())
    assert record["command"] == f"python scripts/benchmarks.py run tiny --seeds 2 3 --out {out}"
    assert len(record["commit"]) >= 40 and record["seeds"] == [2, 3]
    assert record["machine"]["cores"] >= 1 and record["load_average_start"] is not None
    assert record["results"]["squares"] == [4, 9]
    capsys.readouterr()
    assert runner.main(["run", "silent", "--out", str(tmp_path / "silent.json")]) == 2
    assert "no 'splits' entry" in capsys.readouterr().err and not (tmp_path / "silent.json").exists()


def test_a_tree_with_uncommitted_changes_writes_no_results_file_only_a_trial(runner, tmp_path, monkeypatch,
                                                                           capsys) -> None:
    """A results file under benchmarks/results cites a commit: with a tracked file changed the run refuses in one
    line before running the suite; ``--out`` (a trial no document renders) runs and records the changed files."""
    (tmp_path / "tiny.py").write_text(TINY_SUITE)
    monkeypatch.setattr(runner, "SUITES", tmp_path)
    monkeypatch.setattr(runner, "RESULTS", tmp_path / "results")
    monkeypatch.setattr(runner, "uncommitted", lambda: ["benchmarks/results/other.json", "scripts/suites/a.py",
                                                        "b.py", "c.py"])
    assert runner.main(["run", "tiny"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "4 tracked file(s) differ from the commit" in err
    assert "benchmarks/results/other.json, scripts/suites/a.py, b.py, …" in err and "--out" in err
    assert not (tmp_path / "results").exists()
    assert runner.main(["run", "tiny", "--out", str(tmp_path / "trial.json")]) == 0
    assert json.loads((tmp_path / "trial.json").read_text())["uncommitted"][1] == "scripts/suites/a.py"


def test_a_suites_bad_input_is_one_line_and_writes_nothing(runner, tmp_path, capsys) -> None:
    out = tmp_path / "cvae.json"
    assert runner.main(["run", "style_examples_cvae", "--runs", str(tmp_path / "none"), "--seeds", "0",
                        "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and f"run={tmp_path / 'none' / 'seed0'} is not a finished" in err
    assert not out.exists()
