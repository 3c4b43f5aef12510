"""Suite ``autoencoder_schedule`` (scripts/suites/autoencoder_schedule.py): its rule takes the fewest epochs among
candidates no worse than the reference on both validation figures, never a failed one (hand-made records)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import autoencoder_schedule as suite  # noqa: E402

REF = suite.REFERENCE


def _val(mpjpe: float | None, local: float | None = 0.003) -> dict[str, float | None]:
    return {"val/mpjpe": mpjpe, "val/mpjpe_local": local}


def test_fewest_epochs_among_those_no_worse_on_both_figures() -> None:
    epochs = {REF: 60, "a": 20, "b": 30, "c": 40}
    values = {REF: _val(0.0112, 0.0028), "a": _val(0.0098, 0.0038),  # better trajectory, worse pose: out
              "b": _val(0.0111, 0.0028), "c": _val(0.0100, 0.0025)}
    assert suite.choose_schedule(values, epochs) == "b"
    values["b"] = _val(math.nan, 0.0020)  # a failed candidate is never chosen
    assert suite.choose_schedule(values, epochs) == "c"
    values["c"] = _val(0.0113, 0.0025)  # none fits: the reference stays
    assert suite.choose_schedule(values, epochs) == REF
    with pytest.raises(ValueError, match="reference candidate"):
        suite.choose_schedule({REF: _val(None), "a": _val(0.01)}, {REF: 60, "a": 20})


def test_every_candidate_names_its_epochs_schedule_and_root_weight() -> None:
    for name, overrides in suite.CANDIDATES.items():
        keys = {o.split("=", 1)[0] for o in overrides}
        assert keys == {"trainer.max_epochs", "model.lr_schedule", "model.lr", "model.root_weight"} | (
            {"model.lr_gamma"} if name == REF else {"model.warmup_epochs"}), name
        assert f"_e{suite.epochs_of(overrides)}" in name


def test_the_test_block_reports_every_seed_and_their_spread() -> None:
    per_seed = {str(s): {"test_mpjpe_m": v, "test_local_mpjpe_m": w, "test_windows": 344, "window_frames": 60,
                         "val": {}, "train_seconds": 600.0, "reused": False}
                for s, v, w in ((0, 0.0090, 0.0027), (1, 0.0100, 0.0029), (2, 0.0110, 0.0028))}
    record = {"command": "python scripts/benchmarks.py run autoencoder_schedule", "commit": "abc",
              "started": "2026-12-06T00:00", "seeds": [0],
              "results": {"seed": 100, "test": {"candidate": "cos_lr2e-3_e40_root2", "seeds": [0, 1, 2],
                                                "per_seed": per_seed}}}
    block = suite._test_block(record["results"], record)
    assert "| 1 | 1.000 | 0.290 | 10.0 |" in block
    assert "1.000 ± 0.100 (0.900–1.100)" in block and "0.280 ± 0.010 (0.270–0.290)" in block
    assert "344 windows of 60 frames" in block and "seed 100" in block
    assert "Not run" in suite._test_block({"test": {}}, record)
