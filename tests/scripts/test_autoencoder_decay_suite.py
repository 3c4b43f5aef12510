"""Suite ``autoencoder_decay`` (scripts/suites/autoencoder_decay.py): its rule picks the lowest validation MPJPE,
never a failed candidate, and the rendered block marks the choice and a grid edge (hand-made records, no training)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import autoencoder_decay  # noqa: E402


def _val(mpjpe: float | None, local: float | None = 0.003) -> dict[str, float | None]:
    return {"val/mpjpe": mpjpe, "val/mpjpe_local": local}


def test_rule_takes_the_lowest_validation_mpjpe_and_skips_failures() -> None:
    values = {0.9: _val(0.0120), 0.94: _val(0.0113), 0.97: _val(0.0118), 0.99: _val(math.nan)}
    assert autoencoder_decay.choose_decay(values) == 0.94
    values[0.99] = _val(None)
    assert autoencoder_decay.choose_decay(values) == 0.94
    values[0.9] = _val(0.0113)  # a tie: the gentler (larger) decay
    assert autoencoder_decay.choose_decay(values) == 0.94
    with pytest.raises(ValueError, match="every decay candidate failed"):
        autoencoder_decay.choose_decay({0.9: _val(None), 0.97: _val(math.inf)})


def test_render_marks_the_choice_and_the_grid_edge() -> None:
    results = {"data": "bandai", "stage_overrides": ["experiment=autoencoder", "trainer.max_epochs=60"],
               "candidates": [0.9, 0.97], "seed": 100, "rule": "lowest val/mpjpe", "chosen": 0.9,
               "values": {"0.9": _val(0.0112, 0.0031), "0.97": _val(0.0120, None)}}
    record = {"suite": "autoencoder_decay", "command": "python scripts/benchmarks.py run autoencoder_decay",
              "commit": "0" * 40, "started": "2026-12-03T21:00:00", "machine": {"cpu": "x", "cores": 2},
              "seeds": [0], "seconds": 1.0, "results": results}
    text = autoencoder_decay.render(record)["headline"]
    assert "| 0.9 **(chosen)** | 1.120 | 0.310 |" in text
    assert "| 0.97 | 1.200 | failed |" in text
    assert "an edge of the grid" in text
    results["candidates"], results["chosen"] = [0.85, 0.9, 0.97], 0.9
    results["values"]["0.85"] = _val(0.0130)
    assert "an edge of the grid" not in autoencoder_decay.render(record)["headline"]
