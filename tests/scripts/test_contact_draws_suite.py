"""Suite ``contact_draws`` (scripts/suites/contact_draws.py): the base read from suite contact_full's results, the
rule (eligible by rows, recognition and variation against β = 0, then the least styled skating ÷ real) and the
block (hand-made reports, no training)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import contact_draws, style_channels  # noqa: E402


def report(styled: float, share: float = 0.95, rows: tuple[str, ...] = ("a",), v_sd: float = 0.5) -> dict:
    """One stance, style a: its samples skating ``styled`` against real clips skating 0.1."""
    return {"table_5_1": {"p": {"diagonal": {"rows": list(rows)}}},
            "style_recognition": {"per_model_detail": {"p": {"a": {"share": share}}}},
            "variation_vs_style": {"p": {"a": {"v_sd": v_sd, "step_sd": 0.5, "diversity": 0.5}}},
            "foot_skating_detail": {"p": {"a": {"samples": {"ratio": styled}, "real": {"ratio": 0.1}}}}}


def run(rep: dict) -> dict:
    return {"cases": style_channels.case_figures(rep, ["a"]), "cvae_minutes": 10.0}


def choice(*reports: dict) -> dict:
    names = ["0", "10", "100"][:len(reports)]
    return contact_draws.choose({n: contact_draws.candidate_summary([run(r)]) for n, r in zip(names, reports)})


def test_the_least_skating_eligible_weight_is_chosen() -> None:
    assert choice(report(0.5), report(0.3), report(0.2))["chosen"] == "100"
    assert choice(report(0.5), report(0.3), report(0.3))["chosen"] == "10"  # a tie goes to the smaller β
    assert choice(report(0.5), report(0.6))["chosen"] == "0"  # skating more: β = 0 stays


def test_a_weight_that_loses_a_row_recognition_or_variation_is_not_eligible() -> None:
    lost_row = choice(report(0.5), report(0.1, rows=()))
    assert lost_row["eligible"] == {"0": True, "10": False} and lost_row["chosen"] == "0"
    unrecognized = choice(report(0.5, share=0.95), report(0.1, share=0.85))  # floor min(0.9, 0.95) = 0.9
    assert unrecognized["recognition_floor"] == pytest.approx(0.9) and unrecognized["chosen"] == "0"
    # V_SD 0.5 → 0.4: the capped log variation falls by log(0.5/0.4)/3 ≈ 0.074 > the tie band 0.05
    narrower = choice(report(0.5), report(0.1, v_sd=0.4))
    assert narrower["eligible"]["10"] is False and narrower["chosen"] == "0"
    within = choice(report(0.5), report(0.1, v_sd=0.45))  # ≈ 0.035 < 0.05: still eligible
    assert within["eligible"]["10"] is True and within["chosen"] == "10"


def test_samples_that_never_plant_are_not_chosen() -> None:
    never = report(0.1)
    never["foot_skating_detail"]["p"]["a"]["samples"]["ratio"] = None
    assert choice(report(0.5), never)["chosen"] == "0"


def test_the_base_is_contact_fulls_chosen_arm_and_refused_in_one_line(tmp_path: Path) -> None:
    path = tmp_path / "contact_full.json"
    stages = {"autoencoder": ["model.contact_weight=0.1"], "cvae": ["model.style_channels=pose"]}
    path.write_text(json.dumps({"results": {"base": "pose-subset", "choice": {"chosen": "contact"},
                                            "per_seed": {"100": {"contact": {"stages": stages}}}}}))
    assert contact_draws.contact_base(path) == {"arm": "contact", "channels": "pose-subset",
                                                "folder": "pose-subset+contact", "stages": stages}
    path.write_text(json.dumps({"results": {"base": "pose-subset", "choice": {"chosen": "off"},
                                            "per_seed": {"100": {"off": {"stages": {"cvae": []}}}}}}))
    assert contact_draws.contact_base(path)["folder"] == "pose-subset"
    with pytest.raises(SystemExit, match="no contact_full choice"):
        contact_draws.contact_base(tmp_path / "missing.json")


def test_the_block_states_the_verdict() -> None:
    per_seed = {"100": {"0": run(report(0.5)), "10": run(report(0.2))}}
    summary = {n: contact_draws.candidate_summary([per_seed["100"][n]]) for n in ("0", "10")}
    results = {"data": "bandai", "weights": [0.0, 10.0], "overrides": [], "per_seed": per_seed, "summary": summary,
               "base": {"arm": "off", "channels": "pose-subset", "folder": "pose-subset",
                        "stages": {"cvae": ["model.style_channels=pose"]}},
               "choice": contact_draws.choose(summary)}
    record = {"suite": "contact_draws", "command": "c", "commit": "0" * 40, "started": "2026-12-07T06:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [100], "seconds": 1.0, "results": results}
    text = contact_draws.render(record)["headline"]
    assert "Verdict: β = **10** is chosen" in text
    assert "| **10** | 20.0 ± 0.0 (20.0–20.0) | 10.0 ± 0.0 (10.0–10.0) | 2.00 ± 0.00 (2.00–2.00) | 1/1 |" in text
