"""Suite ``style_duration`` (scripts/suites/style_duration.py): its arms, the duration cases from the stance figures,
the rule (eligible as in suite contact_template, then the lowest mean duration error beyond the tie band, in order of
γ) and the blocks (hand-made reports, no training)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import contact_template, style_channels, style_duration  # noqa: E402

REAL_S = 0.6


def report(share: float = 0.95, v_sd: float = 0.5) -> dict:
    """One stance, style a (a reproduction report's parts the suite reads)."""
    return {"table_5_1": {"p": {"diagonal": {"rows": ["a"]}}},
            "style_recognition": {"per_model_detail": {"p": {"a": {"share": share}}}},
            "variation_vs_style": {"p": {"a": {"v_sd": v_sd, "step_sd": 0.5, "diversity": 0.5}}},
            "foot_skating_detail": {"p": {"a": {
                "samples": {"ratio": 0.3, "no_plant_share": 0.0, "planted_mid_mps": 0.1},
                "real": {"ratio": 0.1, "no_plant_share": 0.0, "planted_mid_mps": 0.02}}}}}


def run(drawn_s: float, **kwargs) -> dict:
    """An arm's record whose draws of style a last ``drawn_s`` against real clips of 0.6 s."""
    rep = report(**kwargs)
    stance = {"p/neutral": {"duration_s": 0.55}, "p/a": {"duration_s": drawn_s}}
    return {"cases": style_channels.case_figures(rep, ["a"]), "stance": contact_template.case_stance(rep, ["a"]),
            "cvae_minutes": 10.0,
            "durations": style_duration.duration_cases(stance, {"p/a": {"duration_s": REAL_S},
                                                                "p/neutral": {"duration_s": 0.55}})}


def choice(*runs: dict) -> dict:
    names = ["off", "duration50", "duration500"][:len(runs)]
    return style_duration.choose({n: style_duration.arm_summary([r]) for n, r in zip(names, runs)})


def test_the_arms_are_off_then_each_weight_in_order() -> None:
    assert style_duration.arms([500.0, 50.0, 0.0]) == {
        "off": ["++model.style_duration_weight=0"], "duration50": ["++model.style_duration_weight=50"],
        "duration500": ["++model.style_duration_weight=500"]}


def test_duration_cases_are_log_ratios_of_styled_draws_only() -> None:
    cases = run(0.48)["durations"]
    assert list(cases) == ["p/a"] and math.isclose(cases["p/a"]["log_ratio"], math.log(0.8))
    summary = style_duration.arm_summary([run(0.48), run(0.75)])
    assert math.isclose(summary["duration_error"]["mean"], (-math.log(0.8) + math.log(1.25)) / 2)
    assert math.isclose(summary["duration_log_ratio"]["mean"], 0.0, abs_tol=1e-12)


def test_the_lowest_eligible_duration_error_wins_beyond_the_tie_band() -> None:
    assert choice(run(0.48), run(0.54), run(0.59))["chosen"] == "duration500"
    # errors log(0.6/0.57) = 0.0513 and log(0.6/0.5705) = 0.0504: 500 is within 5 % of 50's: 50 holds
    assert choice(run(0.48), run(0.57), run(0.5705))["chosen"] == "duration50"
    assert choice(run(0.48), run(0.47))["chosen"] == "off"
    lost = choice(run(0.48), run(0.54), run(0.6, share=0.5))  # the exact duration, but recognition lost
    assert lost["eligible"]["duration500"] is False and lost["chosen"] == "duration50"
    narrower = choice(run(0.48), run(0.6, v_sd=0.4))  # capped log variation down ≈ 0.074 > the 0.05 tie
    assert narrower["eligible"]["duration50"] is False and narrower["chosen"] == "off"


def test_the_blocks_state_the_verdict_and_the_durations_per_style() -> None:
    per_seed = {"100": {"off": run(0.48), "duration500": run(0.59)}}
    summary = {n: style_duration.arm_summary([per_seed["100"][n]]) for n in ("off", "duration500")}
    results = {"data": "bandai", "arms": {"off": [], "duration500": []}, "overrides": [], "stance_samples": 300,
               "per_seed": per_seed, "summary": summary, "choice": style_duration.choose(summary)}
    record = {"suite": "style_duration", "command": "c", "commit": "0" * 40, "started": "2026-12-07T06:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [100], "seconds": 1.0, "results": results}
    blocks = style_duration.render(record)
    assert "Verdict: **duration500** is chosen" in blocks["headline"]
    assert "| off | -0.223 ± 0.000 (-0.223–-0.223) | 0.223 ± 0.000 (0.223–0.223) | 1/1 |" in blocks["headline"]
    assert ("| a | 0.600 (0.600–0.600) | 0.480 (0.480–0.480) | 0.590 (0.590–0.590) |" in blocks["styles"])
