"""Suite ``startup`` (scripts/suites/startup.py): it runs a console script's ``--help`` and bad argument, checks
their exit status and lines, records the heavy modules, and its render marks what misses the aims. Fast: only
``stylemotion-convert`` (the lightest command) runs here; the timings are never asserted."""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def suite():
    sys.path.insert(0, str(ROOT / "scripts"))  # the suite imports suites.common, as the runner arranges
    spec = importlib.util.spec_from_file_location("suites.startup", ROOT / "scripts" / "suites" / "startup.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def _run(rc, stderr_lines=1, last="stylemotion-search: Could not override 'nosuchkey'", chars=0):
    return {"wall_s": 0.5, "cpu_s": 0.4, "exit": rc, "stdout_chars": chars, "stderr_lines": stderr_lines,
            "stderr_last": last}


def test_every_console_script_of_pyproject_is_measured(suite):
    scripts = suite.console_scripts()
    assert len(scripts) >= 14 and set(suite.BAD_ARGUMENTS) <= set(scripts)
    assert suite.case_arguments("stylemotion-search", "bad") == ["nosuchkey=1"]
    assert suite.case_arguments("stylemotion-view", "help") == ["--help"]


@pytest.mark.parametrize("command, case, runs, wrong", [
    ("stylemotion-search", "help", [_run(0, 0, "", 500)], False),
    ("stylemotion-search", "help", [_run(1, 3, "Traceback", 0)], True),
    ("stylemotion-search", "bad", [_run(2)], False),
    ("stylemotion-search", "bad", [_run(2, 2)], True),  # one line, not two
    ("stylemotion-search", "bad", [_run(1)], True),  # exit 2
    ("stylemotion-convert", "bad", [_run(2, 5, "stylemotion-convert: error: unrecognized arguments")], False),
])
def test_the_answers_are_checked(suite, command, case, runs, wrong):
    assert bool(suite.checked(command, case, runs)) is wrong


def test_a_real_run_of_the_lightest_command_and_its_render(suite, tmp_path):
    args = argparse.Namespace(repeat=1, warmup=0, commands=["stylemotion-convert"], compare=None, timeout=120.0)
    results = suite.run(args, [0])
    (row,) = results["commands"]
    assert row["help"]["problems"] == [] and row["bad"]["problems"] == [], row
    assert row["help"]["exit"] == [0] and row["bad"]["exit"] == [2]
    assert row["help"]["imports"]["heavy"] == [] and row["help"]["imports"]["modules"] > 0
    record = {"command": "python scripts/benchmarks.py run startup", "commit": "abc", "started": "2026-12-03T00:00",
              "seeds": [0], "results": results}
    blocks = suite.render(record)
    assert set(blocks) == {"commands", "headline"}
    assert "`stylemotion-convert`" in blocks["commands"]
    # a miss is marked: the median over the aim, or only the slowest run over it
    slow = {**row["help"], "median_s": 2.0, "max_s": 2.5}
    assert suite._cell(slow, 1.5).endswith("✗")
    assert suite._cell({**slow, "median_s": 1.0}, 1.5).endswith("(max over)")
