"""Suite ``morphable_joint`` (scripts/suites/morphable_joint.py): its validation paths are never a reported path,
and its rule picks the budget the module doc says from hand-made walks (no models needed)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import morphable_joint, synthesis  # noqa: E402


def test_validation_paths_are_not_the_reported_paths() -> None:
    paths = morphable_joint.validation_paths()
    assert len(paths) == 1 + synthesis.VALIDATION_PATHS
    assert not any(p in synthesis.PATHS.values() for p in paths.values())


def _walk(mean_m: float, accel: float) -> dict[str, float]:
    return {"mean_m": mean_m, "transition_accel": accel, "seconds": 1.0}


def test_the_smallest_budget_within_the_tie_of_the_best_score_is_chosen() -> None:
    rows = {0: [_walk(0.030, 3.0), _walk(0.020, 2.0)],
            5: [_walk(0.020, 2.5), _walk(0.015, 2.0)],
            10: [_walk(0.0199, 2.5), _walk(0.0149, 2.0)],      # within 1 % of 5: a tie, the smaller wins
            20: [_walk(0.010, 2.5), _walk(0.015, 2.0)]}        # clearly better: chosen
    chosen, scores = morphable_joint.choose(rows)
    assert chosen == 20
    assert scores[20]["score"] == pytest.approx(0.0, abs=0.01)
    del rows[20]
    chosen, _ = morphable_joint.choose(rows)
    assert chosen == 5


def test_switching_off_wins_when_line_9_does_not_help() -> None:
    rows = {0: [_walk(0.02, 2.0)], 5: [_walk(0.02, 2.1)], 10: [_walk(0.021, 2.0)]}
    assert morphable_joint.choose(rows)[0] == 0
