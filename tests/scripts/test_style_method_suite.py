"""Suite ``style_method`` (scripts/suites/style_method.py): the case figures of a leave-one-style-out row, the rule
(zero-shot only when it keeps the own-column rows and the recognition and has more variation than the CVAE on the
same autoencoder, by more than the tie band) and the block (hand-made rows, no training)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_method  # noqa: E402
from suites.common import capped_log  # noqa: E402


def model(recognition: float, own: bool, v_sd: float) -> dict:
    return {"recognition": recognition, "own_column_is_minimum": own,
            "variation": {"pose_sd": 1.0, "v_sd": v_sd, "step_sd": 2.0, "diversity": 0.5}}


def row(zs: dict, cvae_unseen: dict) -> dict:
    """One left-out style: real clips with V_SD 0.4, step_SD 4, diversity 1."""
    return {"zero_shot": zs, "cvae_unseen": cvae_unseen, "cvae": model(0.99, True, 0.1),
            "real": {"variation": {"pose_sd": 2.0, "v_sd": 0.4, "step_sd": 4.0, "diversity": 1.0}}}


def choice(*rows: dict) -> dict:
    cases = [style_method.case_figures(r) for r in rows]
    return style_method.choose({k: style_method.summary([c[k] for c in cases]) for k in style_method.METHODS})


def test_case_figures_are_shares_of_the_real_clips() -> None:
    figures = style_method.case_figures(row(model(0.9, True, 0.2), model(0.95, False, 0.1)))
    assert figures["zero_shot"] == {"recognition": 0.9, "own_column": True, "v_sd": 0.5, "step_sd": 0.5,
                                    "diversity": 0.5}
    assert figures["cvae_unseen"]["v_sd"] == 0.25 and figures["cvae"]["own_column"] is True
    assert math.isclose(capped_log([figures["zero_shot"][k] for k in style_method.VARIATION]),
                        math.log(0.5))


def test_zero_shot_wins_only_with_its_rows_its_recognition_and_more_variation() -> None:
    wins = choice(row(model(0.95, True, 0.3), model(0.97, True, 0.1)))
    assert wins["default"] == "zero_shot" and all(wins["tests"].values())
    assert wins["recognition_floor"] == 0.9
    lost_row = choice(row(model(0.95, False, 0.3), model(0.97, True, 0.1)))
    assert lost_row["default"] == "cvae" and lost_row["tests"]["own_column"] is False
    unrecognized = choice(row(model(0.85, True, 0.3), model(0.97, True, 0.1)))
    assert unrecognized["default"] == "cvae" and unrecognized["tests"]["recognition"] is False
    # V_SD share 0.26 against 0.25: the capped log variation differs by log(0.26/0.25)/3 ≈ 0.013 < 0.05: a tie
    tied = choice(row(model(0.95, True, 0.104), model(0.97, True, 0.1)))
    assert tied["default"] == "cvae" and tied["tests"]["variation"] is False


def test_the_block_states_the_verdict() -> None:
    cases = {"walk_leftStance/elderly": style_method.case_figures(row(model(0.95, True, 0.3),
                                                                       model(0.97, True, 0.1)))}
    summaries = {k: style_method.summary([c[k] for c in cases.values()])
                 for k in (*style_method.METHODS, style_method.REFERENCE)}
    results = {"data": "bandai", "epochs": None, "samples": 1000, "narrowed": {"primitives": ["walk_leftStance"]},
               "per_seed": {"100": {"cases": cases}}, "summary": summaries, "choice": style_method.choose(summaries)}
    record = {"suite": "style_method", "command": "c", "commit": "0" * 40, "started": "2026-12-07T06:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [100], "seconds": 1.0, "results": results}
    text = style_method.render(record)["headline"]
    assert "Verdict: zero-shot by the rule, **not applied**: a narrowed run" in text
    assert "**Narrowed:** primitives walk_leftStance" in text
    assert "network epochs: the zero_shot experiment's at commit 000000000000)" in text  # results before the record
    recorded = {**record, "results": {**results, "experiment_epochs": 10}}
    assert "network epochs: 10, the zero_shot experiment's)" in style_method.render(recorded)["headline"]
    full = {**results, "narrowed": {"primitives": None, "styles": None},
            "per_seed": {"100": {"cases": cases}, "101": {"cases": cases}}}
    assert "Verdict: **method=zero_shot becomes the default**" in style_method.render({**record, "results": full})[
        "headline"]
    assert "| zero-shot network (method=zero_shot) | 1/1 | 0.950 ± 0.000 (0.950–0.950) | 0.75 ± 0.00" in text


def test_the_styles_block_pools_seeds_and_primitives_per_left_out_style() -> None:
    left = style_method.case_figures(row(model(0.6, False, 0.2), model(0.97, True, 0.1)))
    right = style_method.case_figures(row(model(0.8, True, 0.2), model(0.99, True, 0.1)))
    per_seed = {"100": {"cases": {"walk_leftStance/exhausted": left, "walk_rightStance/exhausted": right}},
                "101": {"cases": {"walk_leftStance/exhausted": left, "walk_rightStance/exhausted": right}}}
    text = style_method.render_styles({"per_seed": per_seed})
    # zero-shot recognition 0.6, 0.8, 0.6, 0.8: mean 0.7, sd 0.115; own column in the right stance only
    assert "| exhausted | 0.700 ± 0.115 (0.600–0.800) | 2/4 | 0.50 ± 0.00 (0.50–0.50) | 0.980 ± 0.012" in text
    assert text.count("| exhausted |") == 1
