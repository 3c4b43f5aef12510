"""The reconstruction benchmark scripts (keyframes, texture, style transfer) on synthetic data: their JSON lines."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_keyframes_tiny_run_writes_queries_a_summary_and_the_rotation_sweep(capsys):
    assert _load("bench_keyframes").main(["--tiny"]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert lines[0]["kind"] == "setup" and lines[0]["settings"]["k"] == 16
    (query,) = [r for r in lines if r["kind"] == "query"]
    assert query["pairs"] == 3 and 0 <= query["joined"] <= 3 and query["seconds_per_pair"] > 0
    (summary,) = [r for r in lines if r["kind"] == "summary"]
    assert summary["success"] == query["joined"] / query["pairs"]
    rotations = [r for r in lines if r["kind"] == "rotate"]
    assert [r["angle_deg"] for r in rotations] == [0.0, 180.0]
    assert rotations[0]["joined"] and rotations[0]["frames"] > 30


def test_texture_tiny_run_writes_completion_and_texturing_lines(capsys):
    assert _load("bench_texture").main(["--tiny", "--every", "3,10"]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert lines[0]["kind"] == "setup" and len(lines[0]["queries"]) == 2
    summaries = {r["mode"]: r for r in lines if r["kind"] == "summary"}
    assert set(summaries) == {"complete", "texture@3", "texture@10"}
    assert summaries["complete"]["upper_cm"] > 0 and summaries["complete"]["nn_upper_cm"] > 0
    assert summaries["texture@10"]["spline_cm"] > summaries["texture@3"]["spline_cm"]


def test_style_transfer_script_completes_from_both_databases(capsys):
    assert _load("bench_style_transfer").main(["--data", "synthetic"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert [r["kind"] for r in rows] == ["real", "real", "completed", "completed"]
    assert [r["database"] for r in rows[2:]] == ["walk normal", "walk elderly"]
    assert all(r["db_takes"] >= 1 and r["upper_cm_to_take"] > 0 for r in rows[2:])
