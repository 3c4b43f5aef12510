"""Suite ``zero_shot_contact`` (scripts/suites/zero_shot_contact.py): the rule that picks the zero-shot network's
foot-contact loss weight (an arm qualifies with ≥ 10 % less skating than weight 0, style_method's own-column and
recognition tests, and variation within the tie of weight 0's; the lowest skating wins, ties to the smaller weight),
each arm's networks in a folder of their own, and the blocks (hand-made rows, no training)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_method, zero_shot_contact  # noqa: E402

REAL = {"variation": {"pose_sd": 2.0, "v_sd": 0.4, "step_sd": 4.0, "diversity": 1.0}, "foot_skating": {"ratio": 0.05}}


def row(recognition: float, v_sd: float, skating: float, own: bool = True) -> dict:
    return {"recognition": recognition, "own_column_is_minimum": own, "foot_skating": {"ratio": skating},
            "variation": {"pose_sd": 1.0, "v_sd": v_sd, "step_sd": 2.0, "diversity": 0.5}}


def per_seed(recognition: float, v_sd: float, skating: float, own: bool = True) -> dict:
    case = style_method.case_figures({"zero_shot": row(recognition, v_sd, skating, own),
                                      "cvae_unseen": row(0.97, 0.1, 0.3), "cvae": row(0.99, 0.1, 0.3), "real": REAL})
    return {"100": {"cases": {"walk_leftStance/active": case}, "out": "x"},
            "101": {"cases": {"walk_leftStance/active": case}, "out": "y"}}


def arm(recognition: float, v_sd: float, skating: float, own: bool = True) -> dict:
    summaries = style_method.method_summaries(per_seed(recognition, v_sd, skating, own))
    return {"summary": summaries, "choice": style_method.choose(summaries)}


def test_the_arm_with_the_lowest_skating_that_keeps_style_and_variation_wins() -> None:
    arms = {"0": arm(0.95, 0.3, 0.4), "100": arm(0.95, 0.28, 0.2), "1000": arm(0.95, 0.3, 0.19)}
    chosen = zero_shot_contact.choose_weight(arms)
    assert chosen["qualifying"] == ["100", "1000"] and chosen["weight"] == 100.0  # 0.19 within 10 % of 0.2: tie
    failing = {"0": arm(0.95, 0.3, 0.4), "10": arm(0.95, 0.3, 0.38),  # 5 % less skating: not enough
               "100": arm(0.5, 0.3, 0.1),  # recognition under the CVAE's floor
               "1000": arm(0.95, 0.1, 0.1)}  # V_SD share 0.75 → 0.25: variation lost
    chosen = zero_shot_contact.choose_weight(failing)
    assert chosen["weight"] == 0.0 and chosen["qualifying"] == []
    assert chosen["why"] == {"10": "fails skating", "100": "fails recognition", "1000": "fails variation"}


def test_each_arm_trains_its_networks_in_a_folder_of_its_own_and_samples_as_today() -> None:
    args = argparse.Namespace(data="bandai", runs=Path("r"))
    off, on = zero_shot_contact.arm_args(args, 0.0, 10), zero_shot_contact.arm_args(args, 100.0, 10)
    assert off.networks_tag == "" and off.epochs == 10 and off.centred
    assert on.network_overrides == ["model.contact_weight=100.0"] and on.networks_tag == "_contact100"
    assert off.network_overrides == ["model.contact_weight=0.0"]  # the folder holds weight 0 whatever the default


def test_the_blocks_state_the_verdict_the_skating_and_why_each_arm_failed() -> None:
    arms = {"0": arm(0.95, 0.3, 0.4), "100": arm(0.95, 0.28, 0.2)}
    results = {"data": "bandai", "epochs": 10, "samples": 10, "sampling": {"sample_temperature": 1.0,
                                                                           "sample_centred": True},
               "narrowed": {"primitives": None, "styles": None},
               "per_arm": {"0": per_seed(0.95, 0.3, 0.4), "100": per_seed(0.95, 0.28, 0.2)}, "arms": arms,
               "cvae_unseen_same_in_every_arm": True, "choice": zero_shot_contact.choose_weight(arms)}
    record = {"suite": "zero_shot_contact", "command": "c", "commit": "0" * 40, "started": "2026-12-07T06:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [100, 101], "seconds": 1.0, "results": results}
    blocks = zero_shot_contact.render(record)
    assert "**the network's contact_weight default becomes 100**" in blocks["headline"]
    assert "| zero-shot, contact weight 100 | 2/2 |" in blocks["headline"]
    assert "| 8.0 ± 0.0 (8.0–8.0) | the reference |" in blocks["headline"]  # 0.4 / 0.05
    assert "| 4.0 ± 0.0 (4.0–4.0) | qualifies |" in blocks["headline"]
    assert "they skate 0.050 ± 0.000" in blocks["headline"]
    assert "| active | 0.950 ± 0.000 (0.950–0.950) | 8.0 ± 0.0 (8.0–8.0) |" in blocks["styles"]
    narrowed = {**results, "narrowed": {"primitives": ["walk_leftStance"], "styles": None}}
    assert "**not applied**: a narrowed run" in zero_shot_contact.render({**record, "results": narrowed})["headline"]
