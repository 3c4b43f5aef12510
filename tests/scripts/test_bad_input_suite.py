"""Suite ``bad_input`` (scripts/suites/bad_input.py): its classifier turns what a command did into the outcome the
issue counts, its snapshots see writes outside an output folder, and its output check sees NaN. Fast: no command
runs here (the suite itself runs them: ``python scripts/benchmarks.py run bad_input``)."""

from __future__ import annotations

import importlib.util
import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
CMD = "stylemotion-search"


@pytest.fixture(scope="module")
def suite():
    sys.path.insert(0, str(ROOT / "scripts"))  # the suite imports suites.common, as the runner arranges
    spec = importlib.util.spec_from_file_location("suites.bad_input", ROOT / "scripts" / "suites" / "bad_input.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def _case(expect: str, names=("walk.bvh",), warn=()):
    return {"command": CMD, "expect": expect, "names": names, "warn": warn}


def _result(rc: int = 2, stderr: str = "", **extra):
    return {"returncode": rc, "stderr": stderr, "timed_out": False, "peak_rss_kb": 200_000, "earlier": [],
            "outside": [], "leftover": [], "problem": None, "signalled": False, **extra}


@pytest.mark.parametrize("expect, result, outcome", [
    # a refusal: one line with the command's prefix naming the file
    ("refused", _result(2, f"INFO: loading\n{CMD}: walk.bvh:3: bad number\n"), "clear"),
    ("refused", _result(2, f"{CMD}: something is wrong\n"), "unclear"),  # names nothing
    ("refused", _result(1, "walk.bvh: bad\n"), "unclear"),  # no prefix: not the skeleton's line
    ("refused", _result(2, f"{CMD}: walk.bvh: a\n{CMD}: walk.bvh: b\n"), "unclear"),  # more than one
    ("refused", _result(1, "Traceback (most recent call last):\n  File x\nValueError: walk.bvh\n"), "traceback"),
    ("refused", _result(0, ""), "silent-wrong"),  # accepted what must be refused
    # the worst finding wins over a clear line
    ("refused", _result(2, f"{CMD}: walk.bvh: bad\n", timed_out=True), "hang"),
    ("refused", _result(2, f"{CMD}: walk.bvh: bad\n", peak_rss_kb=9_000_000), "unbounded"),
    ("refused", _result(1, "numpy.core._exceptions._ArrayMemoryError: Unable to allocate 224 GiB\n"), "unbounded"),
    ("refused", _result(2, f"{CMD}: walk.bvh: bad\n", earlier=["cases/x/run/run.json"]), "touched-earlier"),
    ("refused", _result(2, f"{CMD}: walk.bvh: bad\n", outside=["decoy/keep.txt"]), "wrote-outside"),
    # an answer
    ("answered", _result(0, ""), "correct"),
    ("answered", _result(0, "", problem="out/summary.json holds NaN or Infinity"), "silent-wrong"),
    ("answered", _result(2, f"{CMD}: walk.bvh: refused\n"), "refused-valid"),
    ("answered", _result(0, "", leftover=["cases/x/.out.abc123"]), "silent-wrong"),
    # Ctrl-C
    ("interrupt", _result(130, f"{CMD}: interrupted; nothing half-written was kept\n", signalled=True), "clear"),
    ("interrupt", _result(1, "Traceback (most recent call last):\nKeyboardInterrupt\n", signalled=True),
     "traceback"),
    ("interrupt", _result(130, f"{CMD}: interrupted\n", signalled=True, problem="left out after Ctrl-C"),
     "silent-wrong"),
    ("interrupt", _result(0, ""), "correct"),  # finished before the signal was sent
    ("interrupt", _result(1, "", signalled=True, finished_before_signal=True), "correct"),  # outputs older than it
])
def test_outcomes(suite, expect, result, outcome):
    assert suite.classify(_case(expect), result)[0] == outcome


def test_an_answer_that_must_warn_and_does_not_is_silent_wrong(suite):
    case = _case("either", names=("zup.bvh",), warn=("zup.bvh",))
    assert suite.classify(case, _result(0, "MotionDataWarning: zup.bvh: looks Z-up\n"))[0] == "correct"
    assert suite.classify(case, _result(0, "all fine\n"))[0] == "silent-wrong"
    assert suite.classify(case, _result(2, f"{CMD}: zup.bvh: refused\n"))[0] == "clear"


def test_changes_are_sorted_into_earlier_outside_and_leftovers(suite, tmp_path):
    (tmp_path / "case" / "run").mkdir(parents=True)
    (tmp_path / "decoy").mkdir()
    (tmp_path / "case" / "run" / "metrics.json").write_text("{}")
    (tmp_path / "decoy" / "keep.txt").write_text("x")
    before = suite.snapshot(tmp_path)
    (tmp_path / "case" / "out").mkdir()
    (tmp_path / "case" / "out" / "a.json").write_text("{}")  # allowed
    (tmp_path / "case" / ".out.x1y2z3").mkdir()  # an atomic folder's temporary name, left behind
    os.replace(tmp_path / "decoy" / "keep.txt", tmp_path / "decoy" / "moved.txt")  # outside
    (tmp_path / "case" / "run" / "metrics.json").write_text('{"best": null}')  # a finished result
    changed = suite.changes(before, suite.snapshot(tmp_path))
    got = suite.sort_changes(changed, ["case/out", "case/hydra"], ["case/run"])
    assert got == {"earlier": ["case/run/metrics.json"], "outside": ["decoy/keep.txt", "decoy/moved.txt"],
                   "leftover": ["case/.out.x1y2z3"]}


def test_output_check_finds_non_finite_numbers(suite, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    assert suite.check_outputs(tmp_path, ["out"]) == "no output in out"
    (out / "summary.json").write_text(json.dumps({"deviation": 0.1, "skating": None}))
    np.savez(out / "motion.npz", positions=np.zeros((3, 21, 3), np.float32), fps=np.float64(30))
    assert suite.check_outputs(tmp_path, ["out"]) is None
    (out / "summary.json").write_text('{"deviation": NaN}')
    assert "summary.json holds NaN" in suite.check_outputs(tmp_path, ["out"])
    (out / "summary.json").write_text("{}")
    np.savez(out / "motion.npz", positions=np.full((3, 21, 3), np.inf, np.float32))
    assert "motion.npz[positions]" in suite.check_outputs(tmp_path, ["out"])


def test_every_command_has_cases_and_ids_are_unique(suite, tmp_path):
    cases = suite.build_cases(suite.Inputs(tmp_path))
    assert len(cases) >= 200 and len({c.id for c in cases}) == len(cases)
    assert {c.command for c in cases} == set(suite.COMMANDS)
    assert {"refused", "answered", "either", "interrupt"} <= {c.expect for c in cases}
