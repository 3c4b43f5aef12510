"""scripts/bench_style_transfer.py on synthetic data: the upper body of a walk completed from two databases."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "bench_style_transfer.py"


def test_style_transfer_script_completes_from_both_databases(capsys):
    spec = importlib.util.spec_from_file_location("bench_style_transfer", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--data", "synthetic"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [r["kind"] for r in rows] == ["real", "real", "completed", "completed"]
    assert [r["database"] for r in rows[2:]] == ["walk normal", "walk elderly"]
    assert all(r["db_takes"] >= 1 and r["upper_cm_to_take"] > 0 for r in rows[2:])
