"""Suite ``contact_full`` (scripts/suites/contact_full.py): the neutral and styled skating figures it reads, the rule
(all three tests must pass to adopt the contact weights) and the block (hand-made reports, no training)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import contact_full, style_channels  # noqa: E402


def report(neutral: float, styled: float, share: float = 0.95, rows: tuple[str, ...] = ("a",)) -> dict:
    """One stance: the neutral row skating ``neutral`` and style a skating ``styled``, both against real 0.1."""
    skating = {m: {"samples": {"ratio": v}, "real": {"ratio": 0.1}} for m, v in (("neutral", neutral), ("a", styled))}
    return {"table_5_1": {"p": {"diagonal": {"rows": list(rows)}}},
            "style_recognition": {"per_model_detail": {"p": {"neutral": {"share": 1.0}, "a": {"share": share}}}},
            "variation_vs_style": {"p": {"a": {"v_sd": 0.5, "step_sd": 0.5, "diversity": 0.5}}},
            "foot_skating_detail": {"p": skating}}


def arm(rep: dict) -> dict:
    return {"neutral": contact_full.neutral_skating(rep), "cases": style_channels.case_figures(rep, ["a"]),
            "autoencoder_val_mpjpe_m": 0.01}


def choice(off: dict, on: dict) -> dict:
    per_seed = {"100": {"off": arm(off), "contact": arm(on)}}
    return contact_full.choose({a: contact_full.arm_summary(per_seed, a) for a in ("off", "contact")})


def test_neutral_figures_and_relative_skating() -> None:
    got = contact_full.neutral_skating(report(0.3, 0.2))
    assert got == {"p": {"samples": 0.3, "real": 0.1, "recognition": 1.0}}
    assert contact_full.relative(0.3, 0.1) == pytest.approx(3.0)
    assert contact_full.relative(None, 0.1) is None and contact_full.relative(0.3, 0.0) is None


def test_the_contact_weights_are_adopted_only_when_every_test_passes() -> None:
    assert choice(report(0.3, 0.2), report(0.15, 0.2))["chosen"] == "contact"
    worse = choice(report(0.3, 0.2), report(0.3, 0.2))  # the neutral VAE does not skate less
    assert worse["tests"]["neutral_skates_less"] is False and worse["chosen"] == "off"
    styled = choice(report(0.3, 0.2), report(0.15, 0.25))  # styled samples skate more
    assert styled["tests"]["styled_skate_no_more"] is False and styled["chosen"] == "off"
    lost = choice(report(0.3, 0.2), report(0.15, 0.2, rows=()))  # a Table 5.1 row lost
    assert lost["tests"]["styled_eligible"] is False and lost["chosen"] == "off"


def test_the_base_is_read_from_the_channels_results_and_refused_in_one_line(tmp_path: Path) -> None:
    path = tmp_path / "style_channels.json"
    path.write_text(json.dumps({"results": {"choice": {"chosen": "pose"}}}))
    assert contact_full.chosen_channels(path) == "pose"
    with pytest.raises(SystemExit, match="no style_channels choice"):
        contact_full.chosen_channels(tmp_path / "missing.json")


def test_the_block_states_the_verdict() -> None:
    per_seed = {"100": {"off": arm(report(0.3, 0.2)), "contact": arm(report(0.15, 0.2))}}
    summary = {a: contact_full.arm_summary(per_seed, a) for a in ("off", "contact")}
    results = {"data": "bandai", "base": "pose", "arms": contact_full.ARMS, "overrides": [], "per_seed": per_seed,
               "summary": summary, "choice": contact_full.choose(summary)}
    record = {"suite": "contact_full", "command": "c", "commit": "0" * 40, "started": "2026-12-07T03:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [100], "seconds": 1.0, "results": results}
    text = contact_full.render(record)["headline"]
    assert "the weights of the narrowed run are **adopted**" in text
    assert "| **contact** | autoencoder: model.contact_weight=0.1; vae: model.contact_weight=100; cvae: " \
           "model.contact_weight=0 | 15.0 ± 0.0 (15.0–15.0) | 10.0 ± 0.0 (10.0–10.0) | 1.50 ± 0.00" in text


def test_an_arm_whose_samples_never_plant_is_not_adopted() -> None:
    never = report(0.3, 0.2)
    never["foot_skating_detail"]["p"]["neutral"]["samples"]["ratio"] = None  # no contact frame in any sample
    got = choice(report(0.3, 0.2), never)
    assert got["tests"]["neutral_skates_less"] is False and got["chosen"] == "off"
