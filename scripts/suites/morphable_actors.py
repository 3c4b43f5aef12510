"""Suite ``morphable_actors``: the Morphable Graph's reductions across Bandai's actors (issue 24 item 6: the
Morphable Graph's cross-actor figure beside its same-actor one).

    python scripts/benchmarks.py run morphable_actors

Bandai dataset-2's three actors are told apart by the rest poses of their files
(:func:`stylemotion.datasets.actors.actor_groups`, suite ``actors``); every actor walked in their own styles, so a
style never crosses actors. Suite ``morphable`` fits one style (``normal``, one actor's), which leaves no actor to
test on. Here each stance model holds the walks of **two actors in all their styles** and is scored on the third:

* per seed ``s`` the walk takes (contents ``walk``, ``walk-turn-left``, ``walk-turn-right``) are split by take with
  seed ``s`` (10 % val, 10 % test, grouped by content and style: :meth:`~stylemotion.datasets.TakeSet.split`);
* per left-out actor, FPCA, normalized FPCA and SFPCA at the default latent size
  (:class:`~stylemotion.morphable.FitSettings`, ``K`` by the 1 cm cut-off on train) are fitted on the *other*
  actors' train clips of the stance (:func:`stylemotion.morphable.heldout.compare_reductions`); SFPCA's kept
  weights are chosen on their val clips;
* joint-space RMSE (Fig. 3.10's measure) is reported on the other actors' **test** clips (same-actor: easier) and on
  **every** clip of the left-out actor (cross-actor), with the 95th percentile and maximum of the per-clip RMSE.

Nothing but SFPCA's kept weights is chosen, and that on val. Seeds change the split, so the spread is over splits.
Each (seed, stance) is one job of ``--workers`` processes (one thread each); a fold's seconds are loaded seconds.
"""

from __future__ import annotations

import argparse
import os
import time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from typing import Any

from suites.common import DATA_ROOT, fmt, md_table, provenance_line, quantiles, spread

DESCRIPTION = ("Morphable Graph reductions (FPCA / normalized / SFPCA) fitted on two Bandai actors' walks, "
               "joint RMSE on their test clips beside every clip of the third actor")
DEFAULT_SEEDS = (0, 1, 2)
STANCES = ("walk_leftStance", "walk_rightStance")
CONTENTS = ("walk", "walk-turn-left", "walk-turn-right")
PARTS = {"test": "same actors (their test clips)", "other actor": "left-out actor (every clip)"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--contents", nargs="+", default=list(CONTENTS), help="Bandai contents loaded")
    parser.add_argument("--workers", type=int, default=2, help="processes, one (seed, stance) each at a time")


def _fold(clips: dict[str, list], actor_of: dict[str, int], held: int, dims: int) -> dict[str, Any]:
    """One left-out actor of one stance and split: the reductions' RMSE per part."""
    from stylemotion.morphable.heldout import compare_reductions

    own = {p: [c for c in clips[p] if actor_of[c.take] != held] for p in ("train", "val", "test")}
    other = [c for p in ("train", "val", "test") for c in clips[p] if actor_of[c.take] == held]
    began = time.perf_counter()
    found = compare_reductions(own["train"], {"val": own["val"], "test": own["test"], "other actor": other}, [dims],
                               per_clip=True)
    return {"clips": {**{p: len(v) for p, v in own.items()}, "other actor": len(other)},
            "K": found["K"], "timeline": found["timeline"],
            "rmse_m": {row["method"]: row["rmse_m"] for row in found["rows"]},
            "per_clip_m": {row["method"]: {p: quantiles(row["rmse_per_clip_m"][p], (50, 95, 100)) for p in PARTS}
                           for row in found["rows"]},
            "sfpca": next(row.get("sfpca") for row in found["rows"] if row["method"] == "sfpca"),
            "seconds_loaded": round(time.perf_counter() - began, 1)}


def _stance_rows(contents: list[str], seed: int, name: str) -> list[dict[str, Any]]:
    """Every left-out actor's fold of one stance under the split of ``seed`` (one worker's job)."""
    import torch

    from stylemotion.datamodules.clips import ClipDataModule
    from stylemotion.datasets.actors import actor_groups
    from stylemotion.datasets.registry import load_dataset
    from stylemotion.morphable import FitSettings
    from stylemotion.primitives.segmentation import parse_primitive

    torch.set_num_threads(1)
    takeset = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"), contents=contents)
    groups = actor_groups(takeset.takes)
    action, primitive = parse_primitive(name)
    dm = ClipDataModule(takeset=takeset, action=action, primitives=[primitive], styles=None,
                        split={"seed": seed, "val_fraction": 0.1, "test_fraction": 0.1})
    dm.setup()
    clips = {p: list(c) for p, c in dm.clips.items()}
    rows = []
    for held in sorted(groups.styles):
        fold = _fold(clips, groups.takes, held, FitSettings().latent_dim)
        rows.append({"seed": seed, "stance": name, "actor": list(groups.styles[held]), **fold})
        print(f"morphable_actors: seed {seed} {name} without {'/'.join(groups.styles[held])}: SFPCA "
              f"{fold['rmse_m']['sfpca']['test'] * 100:.2f} cm same actors, "
              f"{fold['rmse_m']['sfpca']['other actor'] * 100:.2f} cm other actor ({fold['seconds_loaded']} s)",
              flush=True)
    return rows


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.morphable import FitSettings

    jobs = [(list(args.contents), seed, name) for seed in seeds for name in STANCES]
    os.environ["OMP_NUM_THREADS"] = os.environ["OPENBLAS_NUM_THREADS"] = os.environ["MKL_NUM_THREADS"] = "1"
    with ProcessPoolExecutor(max_workers=max(1, args.workers), mp_context=get_context("spawn")) as pool:
        rows = [row for done in pool.map(_stance_rows, *zip(*jobs)) for row in done]
    return {"contents": list(args.contents), "latent_dim": FitSettings().latent_dim,
            "actors": list({tuple(row["actor"]): row["actor"] for row in rows}.values()),  # as the workers found
            "splits": "per seed: by take, 10 % val, 10 % test, grouped by content and style; a left-out actor's "
                     "clips of every part are its 'other actor' clips",
            "rows": rows}


# -- rendering

def _summary(rows: list[dict[str, Any]]) -> dict[tuple[str, str], list[dict[str, Any]]]:
    """The rows of each (left-out actor, stance), over seeds."""
    out: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in rows:
        key = ("/".join(r["actor"]), r["stance"])
        out.setdefault(key, []).append(r)
    return out


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    prov = provenance_line(record)
    seeds = sorted({row["seed"] for row in r["rows"]})
    table = []
    ratios = []
    for (actor, stance), rows in _summary(r["rows"]).items():
        cells = []
        for method in ("fpca", "normalized", "sfpca"):
            for part in PARTS:
                s = spread(row["rmse_m"][method][part] * 100 for row in rows)
                cells.append(f"{fmt(s['mean'])} ± {fmt(s['sd'])}")
        ratios += [row["rmse_m"]["sfpca"]["other actor"] / row["rmse_m"]["sfpca"]["test"] for row in rows]
        clips = rows[0]["clips"]
        worst = spread(row["per_clip_m"]["sfpca"]["other actor"]["p100"] * 100 for row in rows)
        p95 = spread(row["per_clip_m"]["sfpca"]["other actor"]["p95"] * 100 for row in rows)
        table.append([actor, stance.replace("walk_", ""), f"{clips['train']} / {clips['test']} / "
                      f"{clips['other actor']}", *cells, f"{fmt(p95['mean'])} / {fmt(worst['mean'])}"])
    header = ["left-out actor (styles)", "stance", "clips (first seed): train / same-actor test / left-out actor"]
    header += [f"{m}: {p} (cm)" for m in ("FPCA", "normalized", "SFPCA") for p in ("same actors", "left-out actor")]
    header += ["SFPCA, left-out actor's clips: p95 / max (cm)"]
    q = quantiles(ratios, (0, 50, 100))
    headline = (md_table(header, table)
                + f"\n\nJoint-space RMSE (Fig. 3.10's measure) of each reduction at {r['latent_dim']} dims, fitted "
                "on the other two actors' train clips of the stance (every style of theirs; SFPCA's kept weights "
                f"chosen on their val clips), mean ± sd over {len(seeds)} seeds (each seed a different split by "
                "take); p95 / max: of the per-clip RMSE, mean over seeds. Same actors: the model's actors' test "
                "clips (easier: the actor, style and content are in the training clips); left-out actor: every clip "
                "of the actor the model never saw. SFPCA on the left-out actor ÷ on the same actors, per seed and "
                f"fold: {fmt(q['p0'])}–{fmt(q['p100'])}× (median {fmt(q['p50'])}×). Contents "
                f"{', '.join(r['contents'])}. {prov}")
    return {"headline": headline}

