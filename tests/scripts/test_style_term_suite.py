"""Suite ``style_term`` (scripts/suites/style_term.py): each candidate trains with its own term options and no
other value of those keys, the choice reads the samples' style distance (not the logged val/style), and the block
marks the choice (hand-made figures, no training)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style, style_term  # noqa: E402


def test_a_candidate_replaces_the_stage_values_of_its_keys() -> None:
    stage = ["experiment=style_cvae", "model.style_weight=5.0", "model.style_latents=both", "trainer.max_epochs=9",
             "callbacks.samples=4"]
    got = style.candidate_overrides(stage, style_term.CANDIDATES["margin2-both"])
    assert got == ["experiment=style_cvae", "model.style_weight=5.0", "trainer.max_epochs=9",
                   "model.style_term=margin", "model.style_latents=both", "model.style_margin=2.0",
                   "callbacks.samples=null"]
    assert style.candidate_overrides(stage, ["model.style_weight=50"])[1:3] == ["model.style_latents=both",
                                                                                  "trainer.max_epochs=9"]


def test_the_choice_reads_the_samples_style_distance(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    def figures(logged: float, samples: float) -> dict[str, float]:
        return {"val/style": logged, "samples/style": samples, "val/mpjpe": 0.01, "samples/pose_across_sd": 2.0}

    values = {"distance-both": {"p/a": figures(9.0, 2.0)}, "distance-posterior": {"p/a": figures(1.0, 3.0)}}
    seen = {}

    def fake(args, seed, primitives, styles, candidates, subfolder, metrics):
        from stylemotion.training.style_weight import choose_style_weight, style_weight_scores

        seen.update(candidates=candidates, subfolder=subfolder, metrics=metrics)
        return {"styles": ["a"], "seed": 100, "autoencoder_of_seed": seed, "values": values,
                "scores": style_weight_scores(values, metrics), "chosen": choose_style_weight(values, metrics)}

    monkeypatch.setattr(style, "choose_cvae_setting", fake)
    args = argparse.Namespace(data="bandai", runs=tmp_path, primitives=["p"], sample_styles=None, alpha_seed=100,
                              terms=["distance-both", "distance-posterior"])
    results = style_term.run(args, [0])
    assert list(seen["candidates"]) == ["distance-both", "distance-posterior"] and seen["subfolder"] == "term"
    assert "samples/style" in seen["metrics"] and "val/style" not in seen["metrics"]
    assert results["choice"]["chosen"] == "distance-both"
    record = {"suite": "style_term", "command": "c", "commit": "0" * 40, "started": "2026-12-04T19:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [0], "seconds": 1.0, "results": results}
    text = style_term.render(record)["headline"]
    assert "| **distance-both** | style_term=distance, style_latents=both, style_margin=1.0 | 2.00 / 0.0100 / 2.00 |" \
        in text
    assert "the config's default (the thesis' distance term on posterior and prior decodes) stays" in text
