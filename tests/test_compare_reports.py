"""scripts/compare_reports.py: a difference is found, NaN→null is accepted, ignored keys are skipped."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path
from types import ModuleType

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "compare_reports.py"


def _script() -> ModuleType:
    spec = importlib.util.spec_from_file_location("compare_reports", SCRIPT)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up
    spec.loader.exec_module(module)
    return module


def _write(path: Path, value: object) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(value))
    return path


def test_difference_found(tmp_path: Path, capsys) -> None:
    old = _write(tmp_path / "old.json", {"a": {"b": [1.0, 2.0]}, "c": "x"})
    new = _write(tmp_path / "new.json", {"a": {"b": [1.0, 2.5]}, "c": "x"})
    assert _script().main([str(old), str(new)]) == 1
    out = capsys.readouterr().out
    assert "$.a.b[1]" not in out and "old.json.a.b[1]: 2.0 -> 2.5" in out and "1 differ" in out


def test_within_tolerance_and_nan_to_null(tmp_path: Path, capsys) -> None:
    old = _write(tmp_path / "old" / "r" / "report.json", {"x": float("nan"), "y": 1.0, "z": float("inf")})
    new = _write(tmp_path / "new" / "r" / "report.json", {"x": None, "y": 1.0 + 1e-9, "z": None})
    (tmp_path / "old" / "log.txt").write_text("a")
    (tmp_path / "new" / "log.txt").write_text("b")
    assert _script().main([str(tmp_path / "old"), str(tmp_path / "new")]) == 0
    out = capsys.readouterr().out
    assert out.count("nan→null r/report.json") == 2 and "identical; 3 values compared, 0 differ, 2 nan→null" in out
    assert old.exists() and new.exists()


def test_ignored_keys_and_missing_file(tmp_path: Path, capsys) -> None:
    old = _write(tmp_path / "old" / "m.json", {"seconds": 1, "fit_s": 2, "provenance": {"git_commit": "a"},
                                               "path": "/tmp/old/x", "loss": 0.5})
    _write(tmp_path / "new" / "m.json", {"seconds": 9, "fit_s": 8, "provenance": {"git_commit": "b"},
                                         "path": "/tmp/new/x", "loss": 0.7})
    script = _script()
    assert script.main([str(old), str(tmp_path / "new" / "m.json"), "--ignore", "loss"]) == 0
    assert "identical" in capsys.readouterr().out
    _write(tmp_path / "old" / "extra.json", {})
    assert script.main([str(tmp_path / "old"), str(tmp_path / "new"), "--ignore", "loss"]) == 1
    assert "extra.json: <file> -> <missing>" in capsys.readouterr().out
