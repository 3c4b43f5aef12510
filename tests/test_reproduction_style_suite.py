"""Suite ``style`` (scripts/suites/style.py) reads a reproduction's report as the report's own numbers say: Table 5.1's
diagonal counts recomputed here from the distance matrix (row and column minima), recognition and variation taken
over, and spreads over seeds computed from per-seed values (on conftest's shared tiny run)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style  # noqa: E402


def test_diagonal_counts_match_the_distance_matrix(tiny_run) -> None:
    report = json.loads((tiny_run.folder / "report" / "report.json").read_text())
    figures = style.seed_figures(report)
    for primitive, table in report["table_5_1"].items():
        d = np.asarray(table["distance"], dtype=float)  # models × examples, same order
        rows = int(sum(d[i].argmin() == i for i in range(len(d))))
        columns = int(sum(d[:, j].argmin() == j for j in range(d.shape[1])))
        got = figures["primitives"][primitive]
        assert (got["diagonal_rows"], got["diagonal_columns"], got["models"]) == (rows, columns, len(d))
        detail = report["style_recognition"]["per_model_detail"][primitive]
        assert got["recognition"] == {m: v["share"] for m, v in detail.items()}
    assert figures["autoencoder"]["test_mpjpe_m"] == report["autoencoder"]["test_mpjpe_m"] > 0
    assert figures["autoencoder"]["test_local_mpjpe_m"] == report["autoencoder"]["test_local_mpjpe_m"] > 0


def test_spreads_are_over_seeds(tiny_run, monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    report = json.loads((tiny_run.folder / "report" / "report.json").read_text())
    primitive = next(iter(report["table_5_1"]))
    shares = {0: 0.2, 1: 0.5, 2: 0.8}

    def fake(data, seed, out, workers, primitives=None, styles=None, alpha=None, extra=()):
        assert list(extra) == []  # the run's own report (--report-on all)
        out.mkdir(parents=True, exist_ok=True)  # what the reproduction leaves beside its report
        (out / "reproduce.json").write_text(json.dumps({"stages": [{"seconds": 30.0 * (seed + 1), "status": "done"}]}))
        copy = json.loads(json.dumps(report))
        for detail in copy["style_recognition"]["per_model_detail"][primitive].values():
            detail["share"] = shares[seed]
        return copy

    monkeypatch.setattr(style, "reproduce_seed", fake)
    args = argparse.Namespace(data="synthetic", runs=tmp_path, workers=1, primitives=None, sample_styles=None)
    results = style.run(args, [0, 1, 2])
    spread = results["summary"][primitive]["recognition"]["neutral"]
    assert spread["mean"] == pytest.approx(0.5) and spread["sd"] == pytest.approx(0.3)
    assert (spread["min"], spread["max"], spread["n"]) == (0.2, 0.8, 3)
    assert [results["per_seed"][s]["stage_minutes"] for s in "012"] == [0.5, 1.0, 1.5]
    record = {"results": results, "seeds": [0, 1, 2], "command": "c", "commit": "x", "started": "2026-01-01",
              "machine": {}, "seconds": 0}
    blocks = style.render(record)
    assert {"headline", "recognition", "variation", "variation_vs_style", "per_seed"} <= set(blocks)
    assert "Synthetic data" in blocks["headline"] and "0.500 ± 0.300" in blocks["recognition"]
    mpjpe_cm = 100 * report["autoencoder"]["test_mpjpe_m"]  # the same checkpoint in every seed: sd 0
    assert f"{mpjpe_cm:.2f} ± 0.00 ({mpjpe_cm:.2f}–{mpjpe_cm:.2f})" in blocks["autoencoder"]


def test_a_chosen_alpha_reaches_every_seed_and_its_table(tiny_run, monkeypatch: pytest.MonkeyPatch,
                                                         tmp_path: Path) -> None:
    report = json.loads((tiny_run.folder / "report" / "report.json").read_text())
    passed = []

    def fake(data, seed, out, workers, primitives=None, styles=None, alpha=None, extra=()):
        passed.append(alpha)
        out.mkdir(parents=True, exist_ok=True)
        (out / "reproduce.json").write_text(json.dumps({"stages": [{"seconds": 1.0, "status": "done"}]}))
        return report

    choice = {"candidates": [1.0, 5.0], "styles": ["a"], "seed": 100, "autoencoder_of_seed": 0, "chosen": 5.0,
              "values": {"1": {"p/a": {"val/style": 2.0, "val/mpjpe": 0.01}},
                         "5": {"p/a": {"val/style": 1.0, "val/mpjpe": 0.015}}},
              "scores": {"1": 0.693, "5": 0.405}, "rule": "r"}
    monkeypatch.setattr(style, "reproduce_seed", fake)
    monkeypatch.setattr(style, "choose_alpha", lambda args, seed, primitives, styles: choice)
    args = argparse.Namespace(data="synthetic", runs=tmp_path, workers=1, primitives=None, sample_styles=None,
                              alphas=[1.0, 5.0])
    results = style.run(args, [0, 1, 2])
    assert passed == [5.0, 5.0, 5.0] and results["alpha_choice"] == choice
    blocks = style.render({"results": results, "seeds": [0, 1, 2], "command": "c", "commit": "x",
                           "started": "2026-01-01", "machine": {}, "seconds": 0})
    assert "| **5** | 1.00 / 0.0150 / — | 0.405 |" in blocks["alpha"] and "α = 5, chosen" in blocks["headline"]
