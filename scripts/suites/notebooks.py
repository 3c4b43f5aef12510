"""Suite ``notebooks``: how long each task notebook (``notebooks/02_…`` to ``06_…``) takes to run top to bottom on
this CPU (issue 30's aim: ≤ 60 s each) — measured ALONE, so that the test suite holds no timing.

Each repetition (a "seed") is one ``python -m pytest tests/test_task_notebooks.py`` in a subprocess, exactly as the
tests run the notebooks (the same tiny reproduce run and zero-shot networks, trained by the tests' fixtures, not
timed); the tests append each notebook's seconds, clocked around its execution alone, to the file named by
``STYLEMOTION_NOTEBOOK_SECONDS``. A notebook whose test fails counts as failed in the table, not as a time.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

from suites.common import fmt_range, md_table, provenance_line, spread

DESCRIPTION = "seconds per task notebook run top to bottom, as the tests run them (run alone; repetitions as seeds)"
DEFAULT_SEEDS = (0, 1, 2)
ROOT = Path(__file__).resolve().parents[2]
TEST_FILE = "tests/test_task_notebooks.py"
#: Issue 30's aim for each notebook, seconds of wall time on CPU.
AIM_S = 60.0
#: The environment variable naming the file the notebook tests append ``{"notebook", "seconds"}`` lines to.
SECONDS_FILE_ENV = "STYLEMOTION_NOTEBOOK_SECONDS"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--timeout", type=float, default=1800.0, help="seconds one repetition may take")


def repetition(timeout: float) -> dict[str, Any]:
    """One pytest run of the notebook tests: each notebook's seconds, and the tests that failed."""
    with tempfile.TemporaryDirectory() as scratch:
        record = Path(scratch) / "seconds.jsonl"
        env = {**os.environ, SECONDS_FILE_ENV: str(record)}
        done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--basetemp",
                               str(Path(scratch) / "pytest"), TEST_FILE], cwd=ROOT, env=env, capture_output=True,
                              text=True, timeout=timeout)
        lines = record.read_text().splitlines() if record.is_file() else []
    seconds = {}
    for line in lines:
        entry = json.loads(line)
        seconds[str(entry["notebook"])] = float(entry["seconds"])
    failed = sorted({ln.split("::")[-1].split(" ")[0] for ln in done.stdout.splitlines() if ln.startswith("FAILED")})
    return {"seconds": seconds, "failed": failed, "exit": done.returncode,
            "summary": (done.stdout.strip().splitlines() or [""])[-1][:300]}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    reps = {str(seed): repetition(args.timeout) for seed in seeds}
    notebooks = sorted(Path(ROOT, "notebooks").glob("0[2-9]_*.ipynb"))
    per_notebook = {}
    for path in notebooks:
        test = f"test_{path.stem}"
        values = [None if test in r["failed"] else r["seconds"].get(path.name) for r in reps.values()]
        per_notebook[path.name] = spread(values) | {"values": values, "test": test,
                                                    "failed": sum(test in r["failed"] for r in reps.values())}
    return {"splits": {"kind": "none: timing of the notebooks on the tests' tiny data"}, "aim_s": AIM_S,
            "repetitions": reps, "notebooks": per_notebook}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    aim = r["aim_s"]
    rows = []
    for name, s in r["notebooks"].items():
        done, total = s.get("n", 0), s.get("n", 0) + s["missing"]
        verdict = ("no run finished" if not done else f"**missed** (max {s['max']:.1f} s)" if s["max"] > aim
                   else f"met in {done} of {total}" + (" (the rest failed or did not run)" if done < total else ""))
        rows.append([f"`{name}`", fmt_range(s, 1), f"{s['failed']} of {total}", verdict])
    failed = sorted({f for rep in r["repetitions"].values() for f in rep["failed"]})
    text = (f"Seconds per task notebook, run top to bottom by its test (`{TEST_FILE}`) and clocked around the "
            f"notebook alone (the fixtures' tiny trainings are not counted), min–max over {len(r['repetitions'])} "
            f"repetitions; a repetition whose test failed is counted as failed, not as a time. Aim: ≤ {aim:g} s each "
            f"(issue 30).\n\n"
            + md_table(["notebook", "seconds (min–max)", "failed", f"≤ {aim:g} s"], rows)
            + (f"\n\nFailed tests: {', '.join(failed)}." if failed else "")
            + f"\n\n{provenance_line(record)}")
    return {"headline": text}
