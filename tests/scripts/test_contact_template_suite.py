"""Suite ``contact_template`` (scripts/suites/contact_template.py): its arms, the stance figures read from the
report, the rule (eligible by rows, recognition and variation against ``off``, then the lowest mid-stance speed
over real by more than the tie band) and the block (hand-made reports, no training)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import contact_template, style_channels  # noqa: E402


def report(mid: float, share: float = 0.95, rows: tuple[str, ...] = ("a",), v_sd: float = 0.5,
           no_plant: float = 0.0) -> dict:
    """One stance, style a: its samples' stance foot at ``mid`` m/s in mid-stance against real clips at 0.02."""
    return {"table_5_1": {"p": {"diagonal": {"rows": list(rows)}}},
            "style_recognition": {"per_model_detail": {"p": {"a": {"share": share}}}},
            "variation_vs_style": {"p": {"a": {"v_sd": v_sd, "step_sd": 0.5, "diversity": 0.5}}},
            "foot_skating_detail": {"p": {"a": {
                "samples": {"ratio": 0.3, "no_plant_share": no_plant, "planted_mid_mps": mid},
                "real": {"ratio": 0.1, "no_plant_share": 0.0, "planted_mid_mps": 0.02}}}}}


def run(rep: dict) -> dict:
    return {"cases": style_channels.case_figures(rep, ["a"]), "stance": contact_template.case_stance(rep, ["a"]),
            "cvae_minutes": 10.0}


def choice(*reports: dict) -> dict:
    names = ["off", "own100", "content100"][:len(reports)]
    return contact_template.choose({n: contact_template.arm_summary([run(r)]) for n, r in zip(names, reports)})


def test_the_arms_are_off_then_own_then_content_at_one_weight() -> None:
    assert contact_template.arms(100.0, ["off", "own", "content"]) == {
        "off": [], "own100": ["model.sample_contact_weight=100", "model.sample_contacts=own"],
        "content100": ["model.sample_contact_weight=100", "model.sample_contacts=content"]}
    assert list(contact_template.arms(1000.0, ["content"])) == ["off", "content1000"]


def test_the_stance_figures_come_from_the_reports_skating_detail() -> None:
    figures = contact_template.case_stance(report(0.4, no_plant=0.6), ["a"])
    assert figures == {"p/a": {"no_plant_samples": 0.6, "no_plant_real": 0.0, "mid_mps_samples": 0.4,
                               "mid_mps_real": 0.02}}
    summary = contact_template.arm_summary([run(report(0.4, no_plant=0.6))])
    assert abs(summary["mid_excess"]["mean"] - 0.38) < 1e-9 and summary["no_plant_samples"]["mean"] == 0.6


def test_the_slowest_eligible_mid_stance_wins_only_beyond_the_tie_band() -> None:
    assert choice(report(0.5), report(0.3), report(0.1))["chosen"] == "content100"
    # excess over real (0.02 m/s): own 0.08, content 0.077, within 5 % of own: own holds
    assert choice(report(0.5), report(0.1), report(0.097))["chosen"] == "own100"
    assert choice(report(0.5), report(0.49))["chosen"] == "off"  # excess 0.47 against 0.48: a tie, off stays
    assert choice(report(0.5), report(0.6))["chosen"] == "off"


def test_an_arm_that_loses_a_row_recognition_or_variation_is_not_eligible() -> None:
    lost_row = choice(report(0.5), report(0.1, rows=()))
    assert lost_row["eligible"] == {"off": True, "own100": False} and lost_row["chosen"] == "off"
    assert choice(report(0.5, share=0.95), report(0.1, share=0.85))["chosen"] == "off"
    narrower = choice(report(0.5), report(0.1, v_sd=0.4))  # capped log variation down ≈ 0.074 > 0.05
    assert narrower["eligible"]["own100"] is False and narrower["chosen"] == "off"


def test_the_block_states_the_verdict() -> None:
    per_seed = {"100": {"off": run(report(0.5, no_plant=0.5)), "content100": run(report(0.04))}}
    summary = {n: contact_template.arm_summary([per_seed["100"][n]]) for n in ("off", "content100")}
    results = {"data": "bandai", "weight": 100.0, "arms": {"off": [], "content100": []}, "overrides": [],
               "per_seed": per_seed, "summary": summary, "choice": contact_template.choose(summary)}
    record = {"suite": "contact_template", "command": "c", "commit": "0" * 40, "started": "2026-12-07T06:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [100], "seconds": 1.0, "results": results}
    text = contact_template.render(record)["headline"]
    assert "Verdict: **content100** is chosen" in text
    assert ("| **content100** | 0.04 ± 0.00 (0.04–0.04) | 0.020 ± 0.000 (0.020–0.020) | 0.02 ± 0.00 (0.02–0.02) |"
            in text)
    assert "| off | 0.50 ± 0.00 (0.50–0.50) |" in text and "0.50 ± 0.00 (0.50–0.50) | 30.0" in text


def test_the_stance_block_pools_seeds_and_stances_and_shows_the_shared_vae_once() -> None:
    def travel(ratio: float) -> dict:
        return {"travel_ratio": ratio, "foot_drift_m": 0.1, "root_speed_mps": 1.0, "duration_s": 0.5}

    per_seed = {seed: {arm: {"stance_travel": {"walk_leftStance/neutral": travel(0.9),
                                               "walk_rightStance/neutral": travel(0.9),
                                               "walk_leftStance/a": travel(ratio),
                                               "walk_rightStance/a": travel(ratio + 0.1)}}
                       for arm, ratio in (("off", 0.4), ("content100", 0.9))} for seed in ("100", "101")}
    real = {seed: {"walk_leftStance/neutral": travel(1.0), "walk_rightStance/neutral": travel(1.0),
                   "walk_leftStance/a": travel(1.0), "walk_rightStance/a": travel(1.0)} for seed in per_seed}
    results = {"summary": {"off": {}, "content100": {}}, "per_seed": per_seed, "stance_real": real,
               "stance_samples": 300}
    text = contact_template.render_stance(results)
    assert "| neutral | real clips (train + val) | 1.00 ± 0.00 (1.00–1.00) |" in text
    assert "|  | VAE samples (every arm's) | 0.90 ± 0.00 (0.90–0.90) |" in text
    assert text.count("VAE samples") == 1
    assert "|  | off | 0.45 ± 0.06 (0.40–0.50) |" in text and "|  | content100 | 0.95 ± 0.06 (0.90–1.00) |" in text


def test_the_reading_names_what_keeps_an_arm_out_and_what_it_changes() -> None:
    per_seed = {"100": {"off": run(report(0.5, no_plant=0.5)), "content100": run(report(0.04, v_sd=0.4))}}
    summary = {n: contact_template.arm_summary([per_seed["100"][n]]) for n in ("off", "content100")}
    results = {"data": "bandai", "weight": 100.0, "arms": {"off": [], "content100": []}, "overrides": [],
               "per_seed": per_seed, "summary": summary, "choice": contact_template.choose(summary)}
    text = contact_template.render_reading(results)
    assert "by the rule **off** is the default" in text
    assert "`content100` (not eligible: variation (mean capped log" in text
    assert "mid-stance speed over real falls from 0.48 to 0.02 m/s" in text and "V_SD 0.50 to 0.40" in text
    assert "Block `stance`" not in text  # no stance figures in these results


def spreads(root: float, leg: float) -> dict:
    """Stance spreads of one model: root and leg travel SD (m) and speed SD (m/s, over a middle half of 0.25 s)."""
    return {"root_travel_sd_m": root, "leg_travel_sd_m": leg, "root_speed_sd_mps": root * 4,
            "leg_speed_sd_mps": leg * 4}


def test_the_second_look_rules_on_leg_spreads_not_on_the_roots_that_sliding_widens() -> None:
    # off: the root spread is the real clips' but the legs keep half of it (sliding); content100: root and legs
    # both at 0.6 of the real clips', its first-rule V_SD lower (capped log ≈ 0.074 below off's: not eligible)
    per_seed = {"100": {"off": {**run(report(0.5)), "stance_travel": {"p/neutral": spreads(1, 1),
                                                                       "p/a": spreads(0.1, 0.05)}},
                        "content100": {**run(report(0.04, v_sd=0.4)), "stance_travel": {"p/a": spreads(0.06, 0.06)}}}}
    real = {"100": {"p/neutral": spreads(1, 1), "p/a": spreads(0.1, 0.1)}}
    summary = {n: contact_template.arm_summary([per_seed["100"][n]]) for n in ("off", "content100")}
    assert contact_template.choose(summary)["chosen"] == "off"
    cases = contact_template.spread_cases(per_seed, real)
    assert len(cases["off"]) == 1 and len(cases["content100"]) == 1  # the neutral VAE is not a styled case
    assert cases["off"][0]["root_travel_sd_m"] == 1.0 and cases["off"][0]["leg_travel_sd_m"] == 0.5
    assert cases["content100"][0]["leg_speed_sd_mps"] == 0.6 and cases["content100"][0]["diversity"] == 0.5
    look = contact_template.choose_sliding_free(per_seed, real, summary)
    # sliding-free capped logs: off (log .5 + log .5 + log .5) / 3, content (2 log .6 + log .5) / 3: content higher
    assert abs(look["capped_log_sliding_free"]["off"] - math.log(0.5)) < 1e-12
    assert look["eligible"] == {"off": True, "content100": True} and look["chosen"] == "content100"
    # content's legs at 0.3 of the real clips': below off's minus the tie, not eligible, off stays
    per_seed["100"]["content100"]["stance_travel"]["p/a"] = spreads(0.03, 0.03)
    assert contact_template.choose_sliding_free(per_seed, real, summary)["chosen"] == "off"


def test_the_sliding_block_and_the_reading_state_the_second_look() -> None:
    per_seed = {"100": {"off": {**run(report(0.5)), "stance_travel": {"p/a": spreads(0.1, 0.05)}},
                        "content100": {**run(report(0.04, v_sd=0.4)), "stance_travel": {"p/a": spreads(0.06, 0.06)}}}}
    real = {"100": {"p/a": spreads(0.1, 0.1)}}
    summary = {n: contact_template.arm_summary([per_seed["100"][n]]) for n in ("off", "content100")}
    results = {"data": "bandai", "weight": 100.0, "arms": {"off": [], "content100": []}, "overrides": [],
               "per_seed": per_seed, "summary": summary, "choice": contact_template.choose(summary),
               "sliding_free": contact_template.choose_sliding_free(per_seed, real, summary)}
    text = contact_template.render_sliding(results)
    assert "Verdict: **content100** is chosen" in text
    assert "| off | 1.00 ± 0.00 (1.00–1.00) | 0.50 ± 0.00 (0.50–0.50) |" in text
    assert "| **content100** | 0.60 ± 0.00 (0.60–0.60) | 0.60 ± 0.00 (0.60–0.60) |" in text
    reading = contact_template.render_reading(results)
    assert "by the rule **off** is the default" in reading
    assert "Second look (block `sliding`): by its rule **content100** is the default" in reading
    assert "`off` root travel SD 1.00 and leg travel SD 0.50 of the real clips'" in reading
    assert "Root spread above the legs' (variation a sliding foot makes) in off." in reading
    assert "To train with the template anyway" not in reading
