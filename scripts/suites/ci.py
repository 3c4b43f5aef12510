"""Suite ``ci``: the landing check timed end to end — `.ci/run` with `CI=true` on a fresh clone of the committed
HEAD with `../shared` beside it, as the landing CI runs it. Run it ALONE (it takes about 20 minutes).

One repetition (the pipeline is deterministic; its time is what varies, so compare runs as ratios on one
machine). Records the total time, the time until the tests start (install + the synthetic
`stylemotion-reproduce` + the browser check), pytest's summary and its slowest tests.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import tempfile
import time
from pathlib import Path
from typing import Any

from suites.common import DATA_ROOT, md_table, provenance_line

DESCRIPTION = "fresh-clone `CI=true .ci/run` timed end to end (run alone; about 20 min)"
DEFAULT_SEEDS = (0,)
ROOT = Path(__file__).resolve().parents[2]


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    with tempfile.TemporaryDirectory(prefix="stylemotion-ci-") as tmp:
        clone = Path(tmp) / "main"
        subprocess.run(["git", "clone", "-q", str(ROOT), str(clone)], check=True)
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=clone, capture_output=True, text=True,
                              check=True).stdout.strip()
        (Path(tmp) / "shared").symlink_to(DATA_ROOT.parent)
        env = {k: v for k, v in os.environ.items() if not k.startswith(("STYLEMOTION", "VIRTUAL_ENV"))}
        env.update(CI="true", PATH=":".join(p for p in env.get("PATH", "").split(":") if ".venv" not in p))
        started, tests_start, lines = time.perf_counter(), None, []
        with subprocess.Popen([str(clone / ".ci" / "run")], cwd=clone, env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True) as proc:
            for line in proc.stdout:
                if tests_start is None and "test session starts" in line:
                    tests_start = time.perf_counter() - started
                lines.append(line.rstrip("\n"))
            status = proc.wait()
        total = time.perf_counter() - started
    summary = next((ln for ln in reversed(lines) if re.search(r"=+ .*(passed|failed|error).* in ", ln)), "")
    durations = [ln for ln in lines if re.match(r"\s*\d+\.\d+s (call|setup|teardown)\s", ln)]
    return {"splits": {"kind": "none: the synthetic default and the test suite"}, "commit_tested": head,
            "exit_status": status, "total_s": round(total, 1),
            "until_tests_s": round(tests_start, 1) if tests_start is not None else None,
            "pytest_summary": summary.strip("= "), "slowest": durations[:10],
            "tail": lines[-5:] if status else []}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    minutes = lambda s: "—" if s is None else f"{s / 60:.1f} min"  # noqa: E731
    tests = None if r["until_tests_s"] is None else r["total_s"] - r["until_tests_s"]
    table = md_table(["figure", "result", "aim"], [
        ["fresh-clone `CI=true .ci/run`, exit status", f"{minutes(r['total_s'])}, {r['exit_status']}", "≤ 25 min, 0"],
        ["install + synthetic `stylemotion-reproduce` + browser check", minutes(r["until_tests_s"]), ""],
        ["`ruff check . && python -m pytest`", f"{minutes(tests)}: {r['pytest_summary']}", ""]])
    slow = "\n".join(f"    {ln.strip()}" for ln in r["slowest"])
    line = provenance_line(record)
    return {"headline": f"{table}\n\nCommit tested: {r['commit_tested'][:12]}. {line}",
            "slowest": f"Slowest tests of that run:\n\n{slow}\n\n{line}"}
