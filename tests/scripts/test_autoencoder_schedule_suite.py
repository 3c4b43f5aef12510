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
