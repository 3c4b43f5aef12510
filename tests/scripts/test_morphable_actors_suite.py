"""Suite ``morphable_actors`` (scripts/suites/morphable_actors.py): the block sets each left-out actor's RMSE beside
the same-actor RMSE of the same models, per stance, as mean ± sd over seeds (hand-made record, no fitting)."""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import morphable_actors  # noqa: E402


def row(seed: int, actor: list[str], stance: str, same: float, other: float) -> dict:
    rmse = {m: {"train": same / 2, "val": same, "test": same, "other actor": other}
            for m in ("fpca", "normalized", "sfpca")}
    rmse["fpca"] = {k: 2 * v for k, v in rmse["fpca"].items()}
    quant = {"p50": other, "p95": 2 * other, "p100": 3 * other}
    return {"seed": seed, "stance": stance, "actor": actor, "rmse_m": rmse,
            "clips": {"train": 100, "val": 10, "test": 12, "other actor": 60},
            "per_clip_m": {m: {"test": quant, "other actor": quant} for m in ("fpca", "normalized", "sfpca")}}


def record() -> dict:
    rows = [row(s, ["active", "elderly"], "walk_leftStance", 0.01, 0.04 + 0.01 * s) for s in (0, 1, 2)]
    rows += [row(s, ["normal"], "walk_leftStance", 0.02, 0.03) for s in (0, 1, 2)]
    return {"command": "python scripts/benchmarks.py run morphable_actors", "commit": "abc", "started": "2026-12-08",
            "seeds": [0, 1, 2], "machine": {},
            "results": {"contents": ["walk"], "latent_dim": 20, "actors": [["active", "elderly"], ["normal"]],
                        "rows": rows}}


def test_the_block_sets_the_left_out_actor_beside_the_same_actors_per_method() -> None:
    text = morphable_actors.render(record())["headline"]
    lines = [line for line in text.splitlines() if line.startswith("| active/elderly |")]
    assert len(lines) == 1
    cells = lines[0].split(" | ")
    assert cells[1:3] == ["leftStance", "100 / 12 / 60"]
    assert cells[3:9] == ["2.00 ± 0.00", "10.00 ± 2.00", "1.00 ± 0.00", "5.00 ± 1.00", "1.00 ± 0.00", "5.00 ± 1.00"]
    assert cells[9] == "10.00 / 15.00 |"
    assert "left-out actor ÷ on the same actors, per seed and fold: 1.50–6.00× (median 2.75×)" in text
    assert "mean ± sd over 3 seeds" in text


def test_run_gathers_every_seed_and_stance_job_with_its_split_and_renders(monkeypatch) -> None:
    """``run`` (the workers' jobs stubbed, no fitting): one job per (seed, stance), a ``splits`` entry as the
    runner demands, and a record the block renders from."""
    import argparse
    from types import SimpleNamespace

    import stylemotion.datasets.actors as actors
    import stylemotion.datasets.registry as registry

    class Inline:  # the pool, run in this process
        def __init__(self, **_: object) -> None: ...
        def __enter__(self) -> Inline: return self
        def __exit__(self, *_: object) -> None: ...
        def map(self, fn, *columns): return map(fn, *columns)

    jobs = []

    def stance_rows(contents, seed, name):
        jobs.append((seed, name))
        return [row(seed, ["active", "elderly"], name, 0.01, 0.04), row(seed, ["normal"], name, 0.02, 0.03)]

    monkeypatch.setattr(morphable_actors, "ProcessPoolExecutor", Inline)
    monkeypatch.setattr(morphable_actors, "_stance_rows", stance_rows)
    monkeypatch.setattr(registry, "load_dataset", lambda *a, **k: SimpleNamespace(takes=[]))
    monkeypatch.setattr(actors, "actor_groups", lambda takes: SimpleNamespace(styles={0: ["active", "elderly"],
                                                                                      1: ["normal"]}))
    results = morphable_actors.run(argparse.Namespace(contents=["walk"], workers=1), [0, 1, 2])
    assert sorted(jobs) == [(s, n) for s in (0, 1, 2) for n in morphable_actors.STANCES]
    assert "splits" in results and len(results["rows"]) == 12
    full = {**record(), "results": results}
    text = morphable_actors.render(full)["headline"]
    assert text.count("| active/elderly |") == 2 and "mean ± sd over 3 seeds" in text
