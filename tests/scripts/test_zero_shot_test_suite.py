"""Suite ``zero_shot_test`` (scripts/suites/zero_shot_test.py): the figures of a case with raw foot skating, issue
27's aims counted with unmeasured cases as misses, the blocks, the judges paired with the training seeds (a test
report made only when missing), and a judge of the wrong report refused (hand-made rows, no training)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_method, zero_shot_test  # noqa: E402


def row(recognition: float, v_sd: float, diversity: float, skating: float | None = None, own: bool = True) -> dict:
    out = {"recognition": recognition, "own_column_is_minimum": own,
           "variation": {"pose_sd": 1.0, "v_sd": v_sd, "step_sd": 2.0, "diversity": diversity}}
    if skating is not None:
        out["foot_skating"] = {"ratio": skating}
    return out


REAL = {"variation": {"pose_sd": 2.0, "v_sd": 0.4, "step_sd": 4.0, "diversity": 1.0}, "foot_skating": {"ratio": 0.05}}


def case(zero_shot: dict, cvae_unseen: dict | None = None) -> dict:
    return style_method.case_figures({"zero_shot": zero_shot, "cvae_unseen": cvae_unseen or row(0.97, 0.1, 0.2, 0.3),
                                      "cvae": row(0.99, 0.2, 0.2, 0.25), "real": REAL,
                                      "reconstructed": {"foot_skating": {"ratio": 0.1},
                                                        "foot_skating_timeline": {"ratio": 0.06},
                                                        "foot_skating_judge": {"ratio": 0.075}}})


def test_a_case_measures_skating_as_a_multiple_of_the_styles_real_clips_and_older_rows_have_none() -> None:
    figures = case(row(0.9, 0.36, 0.8, 0.06))
    assert figures["zero_shot"]["skating"] == 0.06 and figures["zero_shot"]["skating_vs_real"] == pytest.approx(1.2)
    assert figures["cvae_unseen"]["skating_vs_real"] == pytest.approx(6.0) and figures["real_skating"] == 0.05
    assert figures["zero_shot"]["v_sd"] == pytest.approx(0.9) and figures["zero_shot"]["diversity"] == 0.8
    assert figures["reconstructed_skating_vs_real"] == pytest.approx(2.0)
    summary = style_method.summary([figures["zero_shot"], case(row(0.8, 0.4, 0.5, 0.1))["zero_shot"]])
    assert summary["skating_vs_real"]["mean"] == pytest.approx(1.6) and summary["skating"]["max"] == 0.1
    old = style_method.case_figures({k: row(0.9, 0.3, 0.5) for k in ("zero_shot", "cvae_unseen", "cvae")}
                                    | {"real": {"variation": REAL["variation"]}})
    assert "skating" not in old["zero_shot"] and "real_skating" not in old
    assert "skating" not in style_method.summary([old["zero_shot"]])


def per_seed() -> dict:
    """Two seeds, two styles: active recognized 0.9 and 0.6 (mean 0.75 < 0.8), elderly 0.95 twice; skating 1.2×,
    2×, 1.4× and unmeasured (a miss)."""
    unmeasured = case(row(0.95, 0.4, 0.8))
    unmeasured["zero_shot"].pop("skating_vs_real", None)
    return {"100": {"cases": {"walk_leftStance/active": case(row(0.9, 0.36, 0.8, 0.06)),
                              "walk_leftStance/elderly": case(row(0.95, 0.2, 0.6, 0.1))}},
            "101": {"cases": {"walk_leftStance/active": case(row(0.6, 0.4, 0.7, 0.07)),
                              "walk_leftStance/elderly": unmeasured}}}


def test_the_aims_count_styles_by_their_mean_recognition_and_unmeasured_cases_as_misses() -> None:
    aims = zero_shot_test.aims(per_seed())["zero_shot"]
    assert aims["cases"] == 4 and aims["styles"] == 2
    assert aims["recognition_styles"] == 1 and aims["worst_style"] == "active"  # active's mean 0.75
    assert aims["skating"] == 2  # 1.2× and 1.4× (2× misses, the unmeasured case misses)
    assert aims["v_sd"] == 3 and aims["diversity"] == 3  # V_SD shares 0.9, 0.5, 1.0, 1.0; diversity 0.8, 0.6, 0.7, 0.8


def record(seeds: dict) -> dict:
    summaries = style_method.method_summaries(seeds)
    results = {"data": "bandai", "epochs": 10, "samples": 100,
               "sampling": {"sample_temperature": 1.0, "sample_centred": True}, "contact_weight": 100.0,
               "narrowed": {"primitives": None, "styles": None},
               "judges": {k: f"runs/benchmarks/style/bandai/full/seed{i}" for i, k in enumerate(seeds)},
               "per_seed": seeds, "summary": summaries, "aims": zero_shot_test.aims(seeds),
               "rule_on_test": style_method.choose(summaries)}
    return {"suite": "zero_shot_test", "command": "c", "commit": "0" * 40, "started": "2026-12-07T06:00:00",
            "machine": {"cpu": "x", "cores": 2}, "seeds": [int(k) for k in seeds], "seconds": 1.0,
            "results": results}


def test_the_blocks_state_test_clips_the_aims_and_what_the_rule_would_give_without_choosing() -> None:
    blocks = zero_shot_test.render(record(per_seed()))
    headline = blocks["headline"]
    assert "judged on **test** clips only" in headline and "**2 training seeds only (fewer than 3).**" in headline
    assert "networks of 10 epochs trained with foot-contact loss weight 100, sampled at τ = 1 with the variation " \
           "centred on the example" in headline
    assert "seed 100 → `runs/benchmarks/style/bandai/full/seed0`" in headline
    assert "it chooses nothing here" in headline
    line = next(x for x in headline.splitlines() if x.startswith("| zero-shot network"))
    assert "| 1/2 |" in line and line.endswith("| 2/4 |")  # styles recognized ≥ 0.8; cases ≤ 1.5× real
    assert "| active | 0.750 ± 0.212 (0.600–0.900) | 2/2 |" in blocks["styles"]
    assert "The style's test clips skate 0.050 ± 0.000 (0.050–0.050)" in blocks["styles"]
    assert "(no model; their own durations) skate 2.0 ± 0.0 (2.0–2.0)× the real clips'; only resampled to the " \
           "canonical timeline and back (no autoencoder), 1.2 ± 0.0 (1.2–1.2)×; through the judge's autoencoder, " \
           "which saw the style, 1.5 ± 0.0 (1.5–1.5)× (over 4 cases)" in blocks["styles"]
    three = per_seed() | {"102": per_seed()["100"]}
    assert "fewer than 3" not in zero_shot_test.render(record(three))["headline"]


def parsed(*argv: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="zero_shot_test")
    zero_shot_test.add_arguments(parser)
    return parser.parse_args(list(argv))


def test_each_training_seed_gets_its_judge_and_a_missing_test_report_is_made(monkeypatch, tmp_path) -> None:
    made = []
    for judge_seed in (0, 1):
        (tmp_path / f"seed{judge_seed}" / "report_test").mkdir(parents=True)
        (tmp_path / f"seed{judge_seed}" / "report_test" / "report.json").write_text("{}")
    monkeypatch.setattr(zero_shot_test, "reproduce_seed", lambda *a, **k: made.append((a, k)))
    args = parsed("--judge", str(tmp_path / "seed{seed}"), "--judge-seeds", "0", "1", "2")
    judges = zero_shot_test.judges(args, [100, 101, 102])
    assert judges == {100: (tmp_path / "seed0").resolve(), 101: (tmp_path / "seed1").resolve(),
                      102: (tmp_path / "seed2").resolve()}
    assert len(made) == 1 and made[0][0][1:3] == (2, tmp_path / "seed2")
    assert {"report=report_test", "evaluation.heldout_splits=[test]",
            "evaluation.style_truth=heldout"} <= set(made[0][1]["extra"])
    with pytest.raises(SystemExit, match="3 training seeds but 2 --judge-seeds"):
        zero_shot_test.judges(parsed("--judge-seeds", "0", "1"), [100, 101, 102])


@pytest.mark.parametrize(("report_on", "splits", "truth", "message"), [
    ("test", ["val"], "all", "test figures must read test clips only"),
    ("test", ["test"], "all", "test figures must read test clips only"),
    ("val", ["val", "test"], "all", "the choice must not read test clips")])
def test_a_judge_whose_report_reads_other_clips_is_refused(monkeypatch, report_on, splits, truth, message) -> None:
    from stylemotion.evaluation import zero_shot as library

    read = []
    source = SimpleNamespace(settings=SimpleNamespace(heldout_splits=splits, style_truth=truth))
    monkeypatch.setattr(library, "read_run", lambda folder, report: read.append(report) or source)
    args = argparse.Namespace(report_on=report_on)
    with pytest.raises(library.ZeroShotRunError, match=message):
        style_method.seed_record(args, 100, Path("judge"))
    assert read == [style_method.JUDGE_REPORTS[report_on][0]]
