"""Suite ``distances`` (scripts/suites/distances.py): render writes every block from a planted record, with the
planted figures and no others."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import distances  # noqa: E402

NAMES = ["D_quat", "D_pc1", "D_pc11", "E15", "E15x3"]


def _s(mean: float) -> dict:
    return {"n": 3, "missing": 0, "mean": mean, "sd": 0.01, "min": mean - 0.01, "max": mean + 0.01}


def test_render_writes_every_block_from_the_record() -> None:
    rho = {a: {b: _s(1.0 if a == b else 0.5 + 0.1 * i) for i, b in enumerate(NAMES)} for a in NAMES}
    results = {"measures": NAMES, "rho": rho, "k": 512, "ks": [8, 512], "queries_per_seed": 256,
               "candidate_frames": 1000, "test_takes": 10,
               "curve": {"8": {b: _s(0.3) for b in NAMES}, "512": {b: _s(0.4) for b in NAMES}},
               "precision_at_10": {b: _s(0.7) for b in NAMES},
               "clips": {"per_content": 8, "seconds": 2.0, "k": 8, "stride": 3, "count_per_seed": [80, 80, 80],
                         "rho": rho,
                         "precision": {b: _s(0.9) for b in NAMES}},
               "splits": {"choose": "nothing tuned", "parameters": {
                   "point_cloud_windows_frames": {"D_pc1": 1, "D_pc11": 11}, "wb_weights": "equal",
                   "body_part_weights": {"lee": ["Hips"], "wb": ["UpperLeg_L"]}, "k": 512, "k_source": "thesis",
                   "rotations": "IK"}}}
    record = {"results": results, "command": "python scripts/benchmarks.py run distances", "commit": "abc",
              "started": "2026-12-03T19:00:00", "seeds": [0, 1, 2], "seconds": 1.0}
    blocks = distances.render(record)
    assert set(blocks) == {"matrix", "curve", "precision", "headline", "settings", "clips",
                           "clip_precision"}
    assert "| E15 | 0.50 | 0.60 | 0.70 | 1.00 | 0.90 |" in blocks["matrix"]
    assert "0.40 ± 0.01" in blocks["curve"] and "0.70 ± 0.01" in blocks["precision"]
    assert "D_pc1 is 0.60 ± 0.01" in blocks["headline"] and "× 3 seeds" in blocks["headline"]
    assert "| E15 | 0.50 | 0.60 | 0.70 | 1.00 | 0.90 |" in blocks["clips"] and "0.90 ± 0.01" in blocks["clip_precision"]
