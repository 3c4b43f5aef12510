"""scripts/bench_imports.py: one JSON line per module, with what the import loaded."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "bench_imports.py"


def test_one_json_line_per_module_with_what_it_loaded(capsys) -> None:
    spec = importlib.util.spec_from_file_location("bench_imports", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--repeat", "2", "--module", "stylemotion.config"]) == 0
    (line,) = capsys.readouterr().out.strip().splitlines()
    record = json.loads(line)
    assert record["module"] == "stylemotion.config" and record["repeat"] == 2
    assert 0 < record["min_s"] <= record["median_s"] <= record["max_s"]
    assert record["lightning"] is False and record["stylemotion_modules"] >= 1
