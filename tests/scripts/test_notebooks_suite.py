"""Suite ``notebooks`` (scripts/suites/notebooks.py): per-notebook spreads over repetitions from planted pytest
runs; a failed test counts as failed, not as a time, and the aim is judged on the slowest finished run."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import notebooks  # noqa: E402

PLANTED = [  # one pytest run per repetition: seconds per notebook and the tests that failed
    {"seconds": {"02_styles.ipynb": 20.0, "03_new_style.ipynb": 50.0, "05_search_and_reconstruct.ipynb": 7.0},
     "failed": [], "exit": 0, "summary": "5 passed"},
    {"seconds": {"02_styles.ipynb": 24.0, "03_new_style.ipynb": 70.0, "05_search_and_reconstruct.ipynb": 9.0},
     "failed": ["test_05_search_and_reconstruct"], "exit": 1, "summary": "1 failed, 4 passed"},
]


def test_spreads_failures_and_the_aim(monkeypatch):
    planted = iter(PLANTED)
    monkeypatch.setattr(notebooks, "repetition", lambda timeout: next(planted))
    results = notebooks.run(argparse.Namespace(timeout=10.0), [0, 1])
    styles = results["notebooks"]["02_styles.ipynb"]
    assert (styles["n"], styles["min"], styles["max"], styles["failed"]) == (2, 20.0, 24.0, 0)
    search = results["notebooks"]["05_search_and_reconstruct.ipynb"]
    assert search["values"] == [7.0, None] and search["failed"] == 1  # the failed run's 9 s is not a time
    assert results["notebooks"]["06_annotate.ipynb"]["n"] == 0  # never recorded
    record = {"suite": "notebooks", "command": "python scripts/benchmarks.py run notebooks", "commit": "0" * 40,
              "started": "2026-12-04T00:00:00+00:00", "seconds": 1.0, "seeds": [0, 1], "uncommitted": [],
              "load_average_start": [0.1, 0.1, 0.1], "load_average_end": [0.2, 0.2, 0.2],
              "machine": {"cpu": "test", "cores": 2}, "results": results}
    text = notebooks.render(record)["headline"]
    assert "| `02_styles.ipynb` | 20.0–24.0 | 0 of 2 | met in 2 of 2 |" in text
    assert "| `03_new_style.ipynb` | 50.0–70.0 | 0 of 2 | **missed** (max 70.0 s) |" in text
    assert "| `05_search_and_reconstruct.ipynb` | 7.0–7.0 | 1 of 2 | met in 1 of 2 (the rest failed or did not run) |" \
        in text
    assert "| `06_annotate.ipynb` | — | 0 of 2 | no run finished |" in text
    assert "Failed tests: test_05_search_and_reconstruct." in text
