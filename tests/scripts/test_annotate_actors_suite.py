"""Suite ``annotate_actors`` (scripts/suites/annotate_actors.py): per actor and document kind the cross-actor row
beside the same-actor row, and issue 28 item 5's aim counted per actor on the seeds' mean R1 (hand-made rows, no
annotation)."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import annotate_actors  # noqa: E402


def rows(actor: list[str], arm: str, kind: str, r1: list[float]) -> list[dict]:
    return [{"seed": seed, "actor": actor, "arm": arm, "kind": kind, "R1": r, "P1": 0.9, "F1": 0.8, "F2": 0.7}
            for seed, r in enumerate(r1)]


def test_the_aim_is_counted_per_actor_on_the_mean_over_seeds() -> None:
    a, b = ["active", "elderly"], ["normal"]
    table = (rows(a, "cross_actor", "takes", [0.7, 0.9, 0.85]) + rows(a, "same_actor", "takes", [0.9, 0.9, 0.9])
             + rows(b, "cross_actor", "takes", [0.79, 0.8, 0.8]) + rows(b, "same_actor", "takes", [0.9, 0.9, 0.9])
             + [dict(x, kind="cuts") for x in rows(a, "cross_actor", "takes", [0.5] * 3)
                + rows(a, "same_actor", "takes", [0.85] * 3) + rows(b, "cross_actor", "takes", [0.5] * 3)
                + rows(b, "same_actor", "takes", [0.5] * 3)])
    record = {"command": "python scripts/benchmarks.py run annotate_actors", "commit": "abc", "started": "2026-12-08",
              "seeds": [0, 1, 2], "machine": {},
              "results": {"actors": [a, b], "rows": table, "settings": {"seconds": 40.0, "blend": 8, "per_class": 9}}}
    text = annotate_actors.render(record)["headline"]
    assert "| active/elderly | whole test takes | other actors | 0.817 ± 0.104 | 0.900 ± 0.000 |" in text
    assert "| normal | their middle 2–3 s | every actor | 0.500 ± 0.000 |" in text
    assert ("whole takes 1 of 2 with templates from other actors (2 of 2 from every actor); short cuts 0 of 2 "
            "(1 of 2)") in text
