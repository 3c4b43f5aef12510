"""Suite ``contact_loss`` (scripts/suites/contact_loss.py): its rule takes the lowest validation skating among the
candidates that keep the reconstruction and the recognition, never samples without contacts, and falls back to weight 0
(hand-made figures, no training)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import contact_loss  # noqa: E402


def _fig(skating: float, mpjpe: float, recognition: float = 0.9) -> dict:
    return {"val_mpjpe": mpjpe, "val": {"samples": {"ratio": skating}, "recognition": recognition}}


def test_rule_takes_the_lowest_skating_within_the_tolerances() -> None:
    figures = {0.0: _fig(0.30, 0.030), 10.0: _fig(0.20, 0.031), 100.0: _fig(0.10, 0.0329),
               1000.0: _fig(0.05, 0.040)}
    chosen, why = contact_loss.choose_weight(figures, tolerance=0.10, recognition_drop=0.05)
    assert chosen == 100.0  # 1000 skates least but reconstructs 33 % worse
    assert why["1000"].startswith("val reconstruction error 1.33×") and why["100"] == "eligible"
    figures[100.0] = _fig(0.10, 0.0329, recognition=0.80)  # recognition falls by more than 0.05
    chosen, why = contact_loss.choose_weight(figures, tolerance=0.10, recognition_drop=0.05)
    assert chosen == 10.0 and why["100"] == "recognition dropped"
    chosen, _ = contact_loss.choose_weight(figures, tolerance=0.10, recognition_drop=None)  # the autoencoder's rule
    assert chosen == 100.0
    figures[10.0] = _fig(0.30, 0.030)  # a tie with weight 0: the smaller weight
    chosen, _ = contact_loss.choose_weight(figures, tolerance=0.10, recognition_drop=0.05)
    assert chosen == 0.0


def test_samples_without_contacts_and_failed_trainings_are_never_chosen() -> None:
    figures = {0.0: _fig(0.30, 0.030), 10.0: _fig(math.nan, 0.030), 100.0: _fig(0.01, math.nan)}
    chosen, why = contact_loss.choose_weight(figures, tolerance=0.10, recognition_drop=0.05)
    assert chosen == 0.0
    assert why["10"] == "no contact foot-frame in the samples" and why["100"] == "failed"
    figures[0.0] = _fig(math.nan, 0.030)  # nothing eligible: the default stays
    assert contact_loss.choose_weight(figures, tolerance=0.10, recognition_drop=0.05)[0] == 0.0
