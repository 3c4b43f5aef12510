"""Suite ``style`` (scripts/suites/style.py): a report's figures per seed and their spreads over seeds, from planted
reports; the shift baseline rows (``shift:<style>``, no recognition and no style of their own) stay in the variation
table and out of the recognition and variation-vs-style tables and the styled mean."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style  # noqa: E402

PRIMITIVE = "walk_leftStance"


def planted_report(share: float, v_sd: float) -> dict:
    """A report.json as stylemotion-eval writes it, cut to what the suite reads: a neutral VAE, one CVAE
    (angry, recognition ``share``) and the shift baseline of the angry column."""
    ratios = {"pose_sd": 0.9, "v_sd": v_sd, "step_sd": 1.1}
    return {
        "table_5_1": {PRIMITIVE: {"models": ["neutral", "angry"],
                                  "diagonal": {"rows": ["neutral", "angry"], "columns": ["angry"]}}},
        "style_recognition": {
            "per_model_detail": {PRIMITIVE: {"neutral": {"share": 0.95}, "angry": {"share": share}}},
            "per_model": {"neutral": 0.95, "angry": share},
            "per_primitive": {PRIMITIVE: {"heldout_accuracy": 0.99, "heldout_clips": 40, "train_clips": 100}},
            "classifier_heldout_accuracy": 0.99},
        "variance_ratio": {PRIMITIVE: {"training_data": {"pose_sd": 1, "v_sd": 1, "step_sd": 1},
                                       "neutral": ratios, "angry": ratios, "shift:angry": ratios}},
        "variation_vs_style": {PRIMITIVE: {m: {"style": m, "pose_across_sd": 0.5, "v_sd": v_sd, "step_sd": 0.4,
                                               "diversity": 0.3} for m in ("neutral", "angry")}},
        "autoencoder": {"test_mpjpe_m": 0.02, "test_local_mpjpe_m": 0.01, "test_windows": 10, "window_frames": 64},
        "meta": {"data": {"split": {"train": 0.8}}},
    }


def test_spreads_over_seeds_and_the_shift_rows_only_where_they_have_figures():
    per_seed = {"0": style.seed_figures(planted_report(0.8, 0.5)), "1": style.seed_figures(planted_report(0.9, 0.7)),
                "2": style.seed_figures(planted_report(1.0, 0.6))}
    summary, overall = style.summarize(per_seed)
    s = summary[PRIMITIVE]
    assert s["models"] == 2 and s["diagonal_rows"]["mean"] == 2 and s["diagonal_columns"]["mean"] == 1
    assert set(s["recognition"]) == {"neutral", "angry"}
    assert s["recognition"]["angry"]["mean"] == pytest.approx(0.9) and s["recognition"]["angry"]["sd"] == \
        pytest.approx(0.1) and s["recognition"]["angry"]["missing"] == 0
    assert set(s["variance_ratio"]) == {"neutral", "angry", "shift:angry"}
    assert s["variance_ratio"]["shift:angry"]["v_sd"]["mean"] == pytest.approx(0.6)
    assert set(s["variation_vs_style"]) == {"neutral", "angry"}
    assert overall["recognition_mean_styled"]["mean"] == pytest.approx(0.9)  # the CVAE's only, not the shift row
    # rendered into the committed Bandai record (its provenance and per-seed rows) with this summary
    record = json.loads((ROOT / "benchmarks" / "results" / "style_bandai.json").read_text())
    record["results"]["summary"][PRIMITIVE] = s
    blocks = style.render(record)
    assert "| walk_leftStance | shift:angry |" in blocks["variation"]
    assert "shift:angry" not in blocks["recognition"] and "shift:angry" not in blocks["variation_vs_style"]
    assert "| walk_leftStance | angry |" in blocks["recognition"]


def with_skating(report: dict, samples: float, real: float, no_plant: float) -> dict:
    """``report`` with its ``foot_skating_detail``: the CVAE's samples slide ``samples``, its real clips ``real``."""
    detail = {"angry": {"samples": {"ratio": samples, "no_plant_share": no_plant, "planted_mid_mps": 0.3},
                        "real": {"ratio": real, "no_plant_share": 0.0, "planted_mid_mps": 0.02}}}
    return {**report, "foot_skating_detail": {PRIMITIVE: detail}}


def test_raw_skating_is_read_per_seed_with_its_ratio_to_the_real_clips():
    per_seed = {str(i): style.seed_figures(with_skating(planted_report(0.9, 0.5), samples, 0.1, no_plant))
                for i, (samples, no_plant) in enumerate([(0.2, 0.0), (0.4, 0.5), (0.3, 0.1)])}
    summary, _ = style.summarize(per_seed)
    angry = summary[PRIMITIVE]["foot_skating"]["angry"]
    assert angry["samples_ratio"]["mean"] == pytest.approx(0.3) and angry["real_ratio"]["mean"] == pytest.approx(0.1)
    assert [angry["times_real"]["min"], angry["times_real"]["max"]] == pytest.approx([2.0, 4.0])
    assert angry["samples_no_plant_share"]["max"] == pytest.approx(0.5)
    record = json.loads((ROOT / "benchmarks" / "results" / "style_bandai.json").read_text())
    record["results"]["summary"] = {PRIMITIVE: summary[PRIMITIVE]}
    record["results"]["primitives"] = [PRIMITIVE]
    block = style.render(record)["skating"]
    assert "| walk_leftStance | angry | 0.300 ± 0.100 (0.200–0.400) | 0.100 ± 0.000 | 3.0 ± 1.0 (2.0–4.0) |" in block
    line = style.render(record)["skating_line"]
    assert "walk_leftStance: neutral VAE —×, style CVAEs 3.0–3.0× (stance foot never planted in up to 0.20" in line


def test_a_report_without_skating_figures_renders_no_skating_block():
    per_seed = {"0": style.seed_figures(planted_report(0.9, 0.5))}
    summary, _ = style.summarize(per_seed)
    assert summary[PRIMITIVE]["foot_skating"] == {}
    record = json.loads((ROOT / "benchmarks" / "results" / "style_bandai.json").read_text())
    record["results"]["summary"] = {PRIMITIVE: summary[PRIMITIVE]}
    record["results"]["primitives"] = [PRIMITIVE]
    assert "skating" not in style.render(record)


def test_the_test_report_suite_asks_for_test_clips_only_and_says_so():
    """Suite ``style_test``: the runs of ``style_bandai`` with a second report that reads test-split clips only; its
    blocks name the split, the default suite's do not claim it."""
    import argparse

    from suites import style_test

    parser = argparse.ArgumentParser()
    style_test.add_arguments(parser)
    args = parser.parse_args([])
    assert (args.data, args.report_on) == ("bandai", "test")
    folder, overrides = style.REPORTS[args.report_on]
    assert folder == "report_test" and set(overrides) == {
        "report=report_test", "evaluation.heldout_splits=[test]", "evaluation.style_truth=heldout"}
    record = json.loads((ROOT / "benchmarks" / "results" / "style_bandai.json").read_text())
    plain = style.render(record)
    record["results"]["report_on"] = "test"
    test = style.render(record)
    assert "**test split only**" in test["recognition"] and "scored on test clips" in test["recognition"]
    assert "test-split clips of its own style" in test["variation_vs_style"]
    assert "test split" not in plain["headline"] and "scored on val+test clips" in plain["recognition"]
