"""Suite ``synthesis`` (scripts/suites/synthesis.py): its validation paths are seeded and never a reported path, and
its rule picks the candidate the module doc says from hand-made walks (no models needed)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import synthesis  # noqa: E402

from stylemotion.synthesis.generate import path_from_config  # noqa: E402


def test_validation_paths_are_seeded_about_12_m_and_not_reported() -> None:
    first = [synthesis.validation_path(i) for i in range(synthesis.VALIDATION_PATHS)]
    assert first == [synthesis.validation_path(i) for i in range(synthesis.VALIDATION_PATHS)]
    assert len({str(p) for p in first}) == len(first)
    for path in first:
        assert path["points"][0] == [0.0, 0.0] and len(path["points"]) == 5
        assert 9.0 < path_from_config(path).length < 15.0
        assert path not in synthesis.PATHS.values()


def _walk(mean_m: float, raw: float, seconds: float = 1.0) -> dict[str, float]:
    return {"mean_m": mean_m, "skating_raw": raw, "synthesis_s": seconds}


def test_rule_sums_log_ratios_to_the_best_and_breaks_ties_by_cost() -> None:
    rows = {"a": [_walk(0.10, 0.20), _walk(0.20, 0.40)],   # best deviation, worst skating
            "b": [_walk(0.20, 0.10), _walk(0.40, 0.20)],   # the mirror image: the same score as a
            "c": [_walk(0.12, 0.12), _walk(0.24, 0.24)]}   # a little worse on both: lower score than a and b
    chosen, scores = synthesis.choose(rows, [10.0, 10.0], {"a": 1.0, "b": 2.0, "c": 3.0})
    assert scores["a"]["score"] == pytest.approx(math.log(2.0))
    assert scores["b"]["score"] == pytest.approx(math.log(2.0))
    assert scores["c"]["score"] == pytest.approx(2 * math.log(1.2))
    assert chosen == "c"  # log 1.44 < log 2
    del rows["c"]
    chosen, _ = synthesis.choose(rows, [10.0, 10.0], {"a": 5.0, "b": 2.0})
    assert chosen == "b"  # tied scores: the cheaper candidate
    assert scores["a"]["median_s_per_m"] == pytest.approx(0.1)
