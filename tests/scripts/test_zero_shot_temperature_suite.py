"""Suite ``zero_shot_temperature`` (scripts/suites/zero_shot_temperature.py): the rule that picks the networks'
sampling temperature (an arm qualifies when style_method's whole rule gives zero_shot on it; the most variation wins,
ties to the larger τ; else the CVAE stays at τ = 1), the blocks, and the options (hand-made rows, no training)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_method, zero_shot_temperature  # noqa: E402


def row(recognition: float, own: bool, v_sd: float) -> dict:
    return {"recognition": recognition, "own_column_is_minimum": own,
            "variation": {"pose_sd": 1.0, "v_sd": v_sd, "step_sd": 2.0, "diversity": 0.5}}


def arm(recognition: float, own: bool, v_sd: float, cases: int = 2) -> dict:
    """An arm whose zero-shot rows all read as given, against a CVAE recognized at 0.97 with V_SD share 0.25."""
    case = style_method.case_figures({
        "zero_shot": row(recognition, own, v_sd), "cvae_unseen": row(0.97, True, 0.1), "cvae": row(0.99, True, 0.1),
        "real": {"variation": {"pose_sd": 2.0, "v_sd": 0.4, "step_sd": 4.0, "diversity": 1.0}}})
    summaries = {k: style_method.summary([case[k]] * cases) for k in (*style_method.METHODS, style_method.REFERENCE)}
    return {"summary": summaries, "network_minutes": {"mean": 1.0}, "choice": style_method.choose(summaries)}


def test_the_qualifying_arm_with_the_most_variation_wins_and_ties_go_to_the_larger_temperature() -> None:
    arms = {"1": arm(0.85, True, 0.4), "0.7": arm(0.93, True, 0.3), "0.5": arm(0.95, True, 0.2)}
    chosen = zero_shot_temperature.choose_temperature(arms)
    assert chosen["qualifying"] == ["0.7", "0.5"] and chosen["temperature"] == 0.7 and chosen["method"] == "zero_shot"
    # V_SD shares 0.52 and 0.5: capped logs differ by log(1.04)/3 ≈ 0.013 < 0.05: the larger τ
    tied = zero_shot_temperature.choose_temperature({"0.7": arm(0.95, True, 0.2), "0.5": arm(0.95, True, 0.208)})
    assert tied["temperature"] == 0.7


def test_without_a_qualifying_arm_the_cvae_stays_and_the_temperature_stays_one() -> None:
    arms = {"1": arm(0.85, True, 0.4), "0.5": arm(0.95, False, 0.2),
            "0.3": arm(0.99, True, 0.1)}  # passes rows and recognition, not variation (the CVAE's 0.25 V_SD share)
    assert not arms["0.3"]["choice"]["tests"]["variation"]
    chosen = zero_shot_temperature.choose_temperature(arms)
    assert chosen == {"qualifying": [], "temperature": 1.0, "method": "cvae",
                      "how": "no arm passes style_method's rule: the CVAE stays, τ stays 1"}


def test_the_blocks_state_the_verdict_the_arms_and_the_failed_tests() -> None:
    arms = {"1": arm(0.85, False, 0.4), "0.5": arm(0.95, True, 0.3)}
    real = {"variation": {"pose_sd": 2.0, "v_sd": 0.4, "step_sd": 4.0, "diversity": 1.0}}
    per_arm = {t: {"100": {"cases": {"walk_leftStance/active": style_method.case_figures({
        "zero_shot": row(r, o, 0.3), "cvae_unseen": row(0.97, True, 0.1), "cvae": row(0.99, True, 0.1),
        "real": real})}}, "101": {"cases": {}}} for t, (r, o) in (("1", (0.85, False)), ("0.5", (0.95, True)))}
    results = {"data": "bandai", "epochs": 10, "samples": 10, "narrowed": {"primitives": None, "styles": None},
               "per_arm": per_arm, "arms": arms, "cvae_unseen_same_in_every_arm": True,
               "choice": zero_shot_temperature.choose_temperature(arms)}
    record = {"suite": "zero_shot_temperature", "command": "c", "commit": "0" * 40,
              "started": "2026-12-07T06:00:00", "machine": {"cpu": "x", "cores": 2}, "seeds": [100, 101],
              "seconds": 1.0, "results": results}
    blocks = zero_shot_temperature.render(record)
    assert "**method=zero_shot becomes the default, sampled at τ = 0.5**" in blocks["headline"]
    assert "| zero-shot, τ = 1 | 0/2 | 0.850 ± 0.000 (0.850–0.850)" in blocks["headline"]
    assert "| own_column, recognition | no |" in blocks["headline"]  # τ = 1's failed tests
    assert blocks["headline"].index("τ = 1 |") < blocks["headline"].index("τ = 0.5 |")
    assert "| active | 0.850 ± 0.000 (0.850–0.850) | 0/1 |" in blocks["styles"]
    narrowed = {**results, "narrowed": {"primitives": ["walk_leftStance"], "styles": None}}
    again = zero_shot_temperature.render({**record, "results": narrowed})
    assert "**not applied**: a narrowed run" in again["headline"]


@pytest.mark.parametrize("value", ["-0.1", "warm", "nan"])
def test_a_temperature_that_is_not_a_number_at_least_zero_is_refused_by_the_parser(value, capsys) -> None:
    parser = argparse.ArgumentParser(prog="zero_shot_temperature")
    zero_shot_temperature.add_arguments(parser)
    assert parser.parse_args(["--temperatures", "1", "0.5"]).temperatures == [1.0, 0.5]
    assert parser.parse_args([]).temperatures == [1.0, 0.7, 0.5] and parser.parse_args([]).epochs is None
    with pytest.raises(SystemExit) as exit_:
        parser.parse_args(["--temperatures", "1", value])
    assert exit_.value.code == 2 and "argument --temperatures" in capsys.readouterr().err


def test_the_centred_suite_samples_centred_at_the_prior_and_says_so() -> None:
    from suites import zero_shot_centred

    parser = argparse.ArgumentParser(prog="zero_shot_centred")
    zero_shot_centred.add_arguments(parser)
    args = parser.parse_args([])
    assert args.centred and args.temperatures == [1.0]
    arms = {"1": arm(0.95, True, 0.3)}
    results = {"data": "bandai", "epochs": 10, "samples": 10, "centred": True,
               "narrowed": {"primitives": None, "styles": None},
               "per_arm": {"1": {"100": {"cases": {}}, "101": {"cases": {}}}}, "arms": arms,
               "cvae_unseen_same_in_every_arm": True,
               "choice": zero_shot_temperature.choose_temperature(arms)}
    record = {"suite": "zero_shot_centred", "command": "c", "commit": "0" * 40, "started": "2026-12-07T06:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [100, 101], "seconds": 1.0, "results": results}
    headline = zero_shot_centred.render(record)["headline"]
    assert "| zero-shot, centred, τ = 1 |" in headline
    assert "sampled at τ = 1 with the variation centred on the example**" in headline
