"""Suite ``search_actors`` (scripts/suites/search_actors.py): the block puts each left-out actor's cross-actor row
beside its same-actor row, counts queries without a match and names the lowest cross-actor precision (hand-made
record, no search)."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import search_actors  # noqa: E402
from suites.common import spread  # noqa: E402


def retrieval(p10: list[float], none: list[float]) -> dict:
    figures = {"p10": spread(p10), "none": spread(none), "found_precision": spread([0.9] * len(p10)),
               "found": spread([9.0] * len(p10)), "queries": spread([20.0] * len(p10))}
    return {"all": figures, "by_content": {"walk": figures, "run": figures}, "queries_per_seed": 18}


def both(lng: dict, command: dict) -> dict:
    return {"lng": lng, "command": command}


def record() -> dict:
    actors = [{"styles": ["active", "elderly"], "query_takes": 20,
               "database_frames": {"cross_actor": 1000, "same_actor": 3000},
               "cross_actor": both(retrieval([0.5, 0.6, 0.7], [2, 4, 3]), retrieval([0.7, 0.8, 0.9], [0, 0, 0])),
               "same_actor": both(retrieval([0.8, 0.9, 1.0], [0, 1, 0]), retrieval([0.9, 0.9, 0.9], [0, 0, 0]))},
              {"styles": ["normal"], "query_takes": 20, "database_frames": {"cross_actor": 2000, "same_actor": 3000},
               "cross_actor": both(retrieval([0.7, 0.7, 0.7], [0, 0, 0]), retrieval([0.6, 0.6, 0.6], [0, 0, 0])),
               "same_actor": both(retrieval([0.9, 0.9, 0.9], [0, 0, 0]), retrieval([1.0, 1.0, 1.0], [0, 0, 0]))}]
    return {"command": "python scripts/benchmarks.py run search_actors", "commit": "abc", "started": "2026-12-08",
            "seeds": [0, 1, 2], "machine": {},
            "results": {"k": 1024, "query_s": 2.0, "actors": actors,
                        "command_options": {"k_max": 16384, "grow": "stable", "stable_for": 1, "refine": 8,
                                            "verify": True}}}


def test_the_block_sets_each_actors_cross_actor_rows_beside_its_same_actor_rows() -> None:
    text = search_actors.render(record())["headline"]
    lines = [line for line in text.splitlines() if line.startswith("| active/elderly |")]
    assert [line.split(" | ")[1:4:2] for line in lines] == [
        ["other actors only", "LNG, k = 1024"], ["other actors only", "the command's defaults"],
        ["every actor (the query's too)", "LNG, k = 1024"], ["every actor (the query's too)", "the command's defaults"]]
    assert "| 1,000 | LNG, k = 1024 | 18 of 20 | 0.600 ± 0.100 | 4 |" in lines[0]
    assert "| 3,000 | the command's defaults | 18 of 20 | 0.900 ± 0.000 | 0 |" in lines[3]
    assert "Lowest cross-actor precision@10 of an actor: LNG, k = 1024 0.600, the command's defaults 0.600." in text
    assert "k from 1024 growing (stable) up to 16,384, refine 8, verify true" in text
    assert "| walk | 0.80 ± 0.10 | 0.90 ± 0.00 | 0.60 ± 0.00 | 1.00 ± 0.00 |" in text  # the command's, by content
