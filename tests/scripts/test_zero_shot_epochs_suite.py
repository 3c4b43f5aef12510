"""Suite ``zero_shot_epochs`` (scripts/suites/zero_shot_epochs.py): the rule that picks the networks' epochs (the
qualifying arm with the most variation, fewest epochs within the tie band; else recognition), the networks' minutes
read from their records, and the blocks (hand-made rows, no training)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_method, zero_shot_epochs  # noqa: E402


def model(recognition: float, own: bool, v_sd: float) -> dict:
    return {"recognition": recognition, "own_column_is_minimum": own,
            "variation": {"pose_sd": 1.0, "v_sd": v_sd, "step_sd": 2.0, "diversity": 0.5}}


def case(zs: dict) -> dict:
    """One left-out style against a CVAE recognized at 0.97 with V_SD share 0.25 (real V_SD 0.4)."""
    return style_method.case_figures({
        "zero_shot": zs, "cvae_unseen": model(0.97, True, 0.1), "cvae": model(0.99, True, 0.1),
        "real": {"variation": {"pose_sd": 2.0, "v_sd": 0.4, "step_sd": 4.0, "diversity": 1.0}}})


def arm(*zero_shot_rows: dict) -> dict:
    cases = [case(z) for z in zero_shot_rows]
    summaries = {k: style_method.summary([c[k] for c in cases]) for k in (*style_method.METHODS,
                                                                          style_method.REFERENCE)}
    return {"summary": summaries, "network_minutes": {"mean": 1.0}, "choice": style_method.choose(summaries)}


def test_the_qualifying_arm_with_the_most_variation_wins_and_ties_go_to_fewer_epochs() -> None:
    arms = {"10": arm(model(0.95, True, 0.2)), "30": arm(model(0.93, True, 0.3)), "100": arm(model(0.6, False, 0.4))}
    chosen = zero_shot_epochs.choose_epochs(arms)
    assert chosen["qualifying"] == ["10", "30"] and chosen["epochs"] == 30 and chosen["method"] == "zero_shot"
    # 30 epochs' V_SD share 0.52 against 10's 0.5: capped logs differ by log(1.04)/3 ≈ 0.013 < 0.05: 10 epochs
    tied = zero_shot_epochs.choose_epochs({"10": arm(model(0.95, True, 0.2)), "30": arm(model(0.95, True, 0.208))})
    assert tied["epochs"] == 10


def test_without_a_qualifying_arm_recognition_decides_and_cvae_stays() -> None:
    arms = {"10": arm(model(0.85, True, 0.3)), "30": arm(model(0.80, True, 0.3)), "100": arm(model(0.95, False, 0.4))}
    chosen = zero_shot_epochs.choose_epochs(arms)
    assert chosen["qualifying"] == [] and chosen["how"].startswith("no arm qualifies")
    assert chosen["epochs"] == 10 and chosen["method"] == "cvae"  # 100 has fewer own-column rows despite 0.95
    near = zero_shot_epochs.choose_epochs({"30": arm(model(0.855, True, 0.3)), "10": arm(model(0.85, True, 0.3))})
    assert near["epochs"] == 10  # within RECOGNITION_TIE of the best


def test_network_minutes_come_from_the_records_also_when_reused(tmp_path) -> None:
    for style, seconds in (("elderly", 90.0), ("active", 30.0)):
        folder = tmp_path / "models" / f"walk_leftStance_without_{style}"
        folder.mkdir(parents=True)
        (folder / "done.json").write_text(json.dumps({"seconds": seconds}))
    minutes = zero_shot_epochs.network_minutes(str(tmp_path), {"walk_leftStance/elderly": {},
                                                               "walk_leftStance/active": {}})
    assert minutes == [1.5, 0.5]


def test_the_blocks_state_the_verdict_and_the_arms() -> None:
    cases = {"10": {"walk_leftStance/exhausted": case(model(0.95, True, 0.2))},
             "100": {"walk_leftStance/exhausted": case(model(0.6, False, 0.4))}}
    per_arm = {e: {"100": {"cases": c}, "101": {"cases": c}} for e, c in cases.items()}
    arms = {"10": arm(model(0.95, True, 0.2), model(0.95, True, 0.2)),
            "100": arm(model(0.6, False, 0.4), model(0.6, False, 0.4))}
    results = {"data": "bandai", "experiment_epochs": 100, "samples": 10,
               "narrowed": {"primitives": None, "styles": None}, "per_arm": per_arm, "arms": arms,
               "cvae_unseen_same_in_every_arm": True, "choice": zero_shot_epochs.choose_epochs(arms)}
    record = {"suite": "zero_shot_epochs", "command": "c", "commit": "0" * 40, "started": "2026-12-07T06:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [100, 101], "seconds": 1.0, "results": results}
    blocks = zero_shot_epochs.render(record)
    assert ("experiment=zero_shot trains **10 epochs** (qualifying arm with the most variation; the experiment had "
            "100), and at that count style_method's rule gives **method=zero_shot**") in blocks["headline"]
    assert "| zero-shot, 100 epochs | 0/2 | 0.600 ± 0.000 (0.600–0.600)" in blocks["headline"]
    assert "| exhausted | 0.950 ± 0.000 (0.950–0.950) | 2/2 | 0.600 ± 0.000 (0.600–0.600) | 0/2 |" in blocks["styles"]
    narrowed = {**results, "narrowed": {"primitives": ["walk_leftStance"], "styles": None}}
    assert "**not applied**: a narrowed run" in zero_shot_epochs.render({**record, "results": narrowed})["headline"]


@pytest.mark.parametrize("value", ["0", "-3", "ten"])
def test_an_epoch_count_that_is_not_a_positive_integer_is_refused_by_the_parser(value, capsys) -> None:
    parser = argparse.ArgumentParser(prog="zero_shot_epochs")
    zero_shot_epochs.add_arguments(parser)
    assert parser.parse_args(["--epochs", "10", "30"]).epochs == [10, 30]
    with pytest.raises(SystemExit) as exit_:
        parser.parse_args(["--epochs", "10", value])
    assert exit_.value.code == 2 and "argument --epochs" in capsys.readouterr().err
