"""scripts/bench_reconstruct.py --tiny: JSON lines for each query, database and feature set, on synthetic data."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "bench_reconstruct.py"


def test_tiny_run_writes_a_line_per_query_and_summaries(capsys):
    spec = importlib.util.spec_from_file_location("bench_reconstruct", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--tiny", "--features", "E15,E30"]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert lines[0]["kind"] == "setup" and len(lines[0]["queries"]) == 2
    queries = [r for r in lines if r["kind"] == "query"]
    expected = {(d, f) for d in ("HDM", "CMU-") for f in ("E15", "E30")}
    assert {(r["database"], r["features"]) for r in queries} == expected
    assert all(r["frames"] == 20 and r["mean_cm"] > 0 and r["max_cm"] >= r["mean_cm"] for r in queries)
    cmu = [r for r in queries if r["database"] == "CMU-"]
    assert all(r["db_frames"] < lines[1]["db_frames"] for r in cmu)
    assert sum(r["kind"] == "summary" for r in lines) == 4
