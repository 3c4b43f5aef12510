"""Suite ``moved_keys``: Krüger §4.3's experiments with a turned and a moved second key (Figs. 4.19–4.22) on Bandai
walks, before and after the turning-aware search (``DynamicMotionGraph.turn_radius_m``), chosen on val takes.

Per seed: Bandai is split by take (``TakeSet.split(seed, 0.1, 0.1)``, grouped by content and style); the train
takes are the motion database, val takes choose, test takes report. From each chosen walk take the first key pair
``--spacing`` s apart (from 0.2 s, :func:`~stylemotion.reconstruct.benchmark.key_pairs`) gives the cases:

* **turned**: the second key turned about the vertical through its Hips by each of ``--angles`` (thesis: 10° steps;
  here 30°), :func:`~stylemotion.reconstruct.keyframes.turn_key`;
* **moved**: the second key's distance from the first scaled by each of ``--scales`` and the key turned with its
  offset about the first key's vertical by each of ``--move-angles`` (the thesis' "Move second key frame":
  0.5–1.5 × in 0.2 steps, 30° steps), :func:`~stylemotion.reconstruct.keyframes.move_key`.

``turn_radius_m`` and ``max_iterations`` are chosen on the val takes' turned cases among ``--radii`` × ``--iterations``
(by default 1, 1.5, 2.5 m × 12, 24; radius 0 — D_node of eq. 4.12 with the facing term — and 12 iterations are the
search before this suite, measured on the test cases as "before"): fewest failures, then the lowest mean |duration
error| of the joined pairs. Test cases are joined with (0, 12) (**before**) and with
the seed's choice (**after**): joined / attempted (a pair whose
trees do not meet is a failure, counted), the duration error of the joined path (its frames against the keys' time
difference; a key turned against the direction of travel needs a detour, so this grows with the angle, as in the
thesis' Fig. 4.20), the path's end against the key, and foot skating of the joined path before cleaning
(:func:`stylemotion.synthesis.quality.skating`) beside the skating of the take's own frames between the keys.
"""

from __future__ import annotations

import argparse
import os
import time
from collections import Counter
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, md_table, provenance_line, take_split_record

DESCRIPTION = ("Krüger §4.3 turned and moved second keys on Bandai walks: joined / attempted per angle and move, "
               "before and after the turning-aware search; turn_radius_m chosen on val takes")
VAL_FRACTION, TEST_FRACTION = 0.1, 0.1
DEFAULT_SEEDS = (0, 1, 2)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--contents", nargs="+", default=["walk"], help="contents of the key takes")
    parser.add_argument("--takes", type=int, default=2, help="test takes per content and seed")
    parser.add_argument("--val-takes", type=int, default=1, help="val takes per content and seed")
    parser.add_argument("--spacing", type=float, default=2.0, help="seconds between the two keys")
    parser.add_argument("--angles", type=float, nargs="+", default=[float(a) for a in range(0, 360, 30)],
                        help="turns of the second key about its own vertical, degrees")
    parser.add_argument("--scales", type=float, nargs="+", default=[0.5, 1.5],
                        help="moved key: distance from the first key, × the original")
    parser.add_argument("--move-angles", type=float, nargs="+", default=[0.0, 90.0, 180.0],
                        help="moved key: turn about the first key's vertical, degrees")
    parser.add_argument("--radii", type=float, nargs="+", default=[1.0, 1.5, 2.5],
                        help="candidates of DynamicMotionGraph.turn_radius_m (0: off, the search before)")
    parser.add_argument("--iterations", type=int, nargs="+", default=[12, 24],
                        help="candidates of DynamicMotionGraph.max_iterations (12: the default before)")


# -- run ----------------------------------------------------------------------------------------------------


def _cases(take, fps: float, args: argparse.Namespace, moved: bool) -> list[dict[str, Any]]:
    """The turned (and, with ``moved``, the moved) second keys of ``take``'s first key pair."""
    from stylemotion.reconstruct.benchmark import key_pairs
    from stylemotion.reconstruct.keyframes import Keyframe, move_key, turn_key

    first, second = key_pairs(take.positions, fps, args.spacing)[0]
    cases = [{"take": take.name, "kind": "turned", "angle_deg": a, "scale": 1.0, "first": first,
              "second": Keyframe(second.time_s, turn_key(second.pose, np.deg2rad(a)))} for a in args.angles]
    if moved:
        cases += [{"take": take.name, "kind": "moved", "angle_deg": a, "scale": s, "first": first,
                   "second": Keyframe(second.time_s, move_key(first.pose, second.pose, s, np.deg2rad(a)))}
                  for s in args.scales for a in args.move_angles]
    return cases


def _outcomes(graph, cases: list[dict[str, Any]], quality: bool) -> list[dict[str, Any]]:
    from stylemotion.reconstruct.benchmark import pair_outcome

    return [{"take": c["take"], "kind": c["kind"], "angle_deg": c["angle_deg"], "scale": c["scale"],
             **pair_outcome(graph, c["first"], c["second"], quality=quality)} for c in cases]


def _val_score(outcomes: list[dict[str, Any]]) -> list[float]:
    """(failed pairs, mean |duration error| s of the joined ones): lower is better, compared in that order."""
    joined = [abs(o["duration_error_s"]) for o in outcomes if o["joined"]]
    return [float(len(outcomes) - len(joined)), float(np.mean(joined)) if joined else float("inf")]


def _take_skating(take, fps: float, spacing: float) -> float:
    from stylemotion.synthesis.quality import skating

    first = int(round(0.2 * fps))
    return float(skating(np.asarray(take.positions[first:first + int(round(spacing * fps)) + 1]), fps)[0])


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from stylemotion.datasets.registry import load_dataset
    from stylemotion.reconstruct.benchmark import choose_queries, database_of
    from stylemotion.reconstruct.keyframes import DynamicMotionGraph

    bandai = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"))
    fps = bandai.fps
    per_seed, splits = [], []
    for seed in seeds:
        started = time.perf_counter()
        parts = bandai.split(seed, VAL_FRACTION, TEST_FRACTION, group_by=("content", "style"))
        splits.append(take_split_record(parts, seed, VAL_FRACTION, TEST_FRACTION))
        rng = np.random.default_rng(seed)
        graph = DynamicMotionGraph(database_of("bandai-train", parts["train"], fps), clean=False)
        val_takes = choose_queries(parts["val"], args.contents, args.val_takes, rng)
        test_takes = choose_queries(parts["test"], args.contents, args.takes, rng)
        val_cases = [c for t in val_takes for c in _cases(t, fps, args, moved=False)]
        scores, val_figures = {}, {}
        for radius in args.radii:
            # one search per case at the largest budget; a smaller budget's outcome is the same search cut short:
            # joined when it met before its last iteration (identical path), rerun when it met at that iteration
            # (it stops without the extra iteration), failed otherwise
            graph.turn_radius_m, graph.max_iterations = float(radius), max(args.iterations)
            full = _outcomes(graph, val_cases, quality=False)
            for budget in sorted(args.iterations):
                outcomes = []
                for case, o in zip(val_cases, full):
                    met = o.get("met_at_iteration") if o["joined"] else None
                    if met is not None and met == budget and budget < max(args.iterations):
                        graph.max_iterations = budget
                        o = _outcomes(graph, [case], quality=False)[0]
                        graph.max_iterations = max(args.iterations)
                    elif met is None or met > budget:
                        o = {**{k: o[k] for k in ("take", "kind", "angle_deg", "scale", "spacing_s")},
                             "joined": False}
                    outcomes.append(o)
                key = f"{radius:g}/{budget}"
                scores[key] = _val_score(outcomes)
                val_figures[key] = {"joined": sum(o["joined"] for o in outcomes), "attempted": len(outcomes)}
                print(f"seed {seed} val turn_radius_m {radius:g}, max_iterations {budget}: {scores[key]}", flush=True)
        best = min(scores, key=lambda c: tuple(scores[c]))
        chosen, iterations = float(best.split("/")[0]), int(best.split("/")[1])
        test_cases = [c for t in test_takes for c in _cases(t, fps, args, moved=True)]
        test: dict[str, list] = {}
        before = (0.0, min(args.iterations))
        for label, (radius, budget) in (("before", before), ("after", (chosen, iterations))):
            if label == "after" and (radius, budget) == before:
                test["after"] = test["before"]
                continue
            graph.turn_radius_m, graph.max_iterations = radius, budget
            test[label] = _outcomes(graph, test_cases, quality=True)
            joined = sum(o["joined"] for o in test[label])
            print(f"seed {seed} test {label} (turn_radius_m {radius:g}, max_iterations {budget}): {joined} / "
                  f"{len(test[label])}", flush=True)
        per_seed.append({"seed": seed, "val_takes": [t.name for t in val_takes],
                         "test_takes": [t.name for t in test_takes], "val_score_by_radius": scores,
                         "val_figures": val_figures, "turn_radius_m": chosen, "max_iterations": iterations,
                         "test": test,
                         "take_skating": {t.name: _take_skating(t, fps, args.spacing) for t in test_takes},
                         "settings": graph.settings(), "seconds": round(time.perf_counter() - started, 1)})
    counts = Counter(f"{r['turn_radius_m']:g}/{r['max_iterations']}" for r in per_seed)
    top = max(counts.values())
    default = min((c for c in counts if counts[c] == top),
                  key=lambda c: tuple(np.mean([r["val_score_by_radius"][c] for r in per_seed], axis=0)))
    return {"splits": {"kind": "by take, one split per seed", "choose": "val", "report": "test",
                       "database": "train", "per_seed": splits},
            "settings": {"contents": args.contents, "takes": args.takes, "val_takes": args.val_takes,
                         "spacing_s": args.spacing, "angles_deg": args.angles, "scales": args.scales,
                         "move_angles_deg": args.move_angles, "radius_candidates": args.radii,
                         "iteration_candidates": args.iterations, "clean": False},
            "choice": {"turn_radius_m": float(default.split("/")[0]), "max_iterations": int(default.split("/")[1]),
                       "rule": "each seed chooses (turn_radius_m, max_iterations) on its val takes' turned keys: "
                               "fewest failed pairs, then the lowest mean |duration error| of the joined ones; the "
                               "default is the most frequent choice"},
            "per_seed": per_seed}


# -- render -------------------------------------------------------------------------------------------------


def _select(r: dict, label: str, **where: Any) -> list[dict[str, Any]]:
    return [o for x in r["per_seed"] for o in x["test"][label]
            if all(abs(o[k] - v) < 1e-9 for k, v in where.items())]


def _cell(outcomes: list[dict[str, Any]]) -> str:
    joined = [o for o in outcomes if o["joined"]]
    return f"{len(joined)} / {len(outcomes)}"


def _mean(outcomes: list[dict[str, Any]], key: str, scale: float = 1.0, absolute: bool = False) -> float | None:
    values = [abs(o[key]) if absolute else o[key] for o in outcomes if o["joined"]]
    return float(np.mean(values)) * scale if values else None


def _row(label: str, before: list[dict], after: list[dict]) -> list[str]:
    return [label, _cell(before), _cell(after), fmt(_mean(after, "duration_error_s", absolute=True), 2),
            fmt(_mean(after, "end_gap_cm"), 1), fmt(_mean(after, "skating", 100.0), 1),
            fmt(_mean(before, "skating", 100.0), 1)]


HEADER = ["second key", "joined / attempted: before", "after", "after: abs. duration error, s (joined)",
          "after: end gap, cm", "after: foot skating %", "before: foot skating %"]


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    s = r["settings"]
    prov = provenance_line(record)
    n = len(r["per_seed"])
    chosen = ", ".join(f"{fmt(x['turn_radius_m'], 2)} m / {x['max_iterations']}" for x in r["per_seed"])
    take_skating = float(np.mean([v for x in r["per_seed"] for v in x["take_skating"].values()])) * 100.0
    note = (f"Test: {s['takes']} {', '.join(s['contents'])} test take(s) per seed × {n} seeds, the first key pair "
            f"{s['spacing_s']:g} s apart; database = the seed's train takes; no cleaning. before: turn_radius_m = 0 "
            f"(D_node of eq. 4.12 with the facing term), max_iterations = {min(s['iteration_candidates'])}; after: "
            f"the seed's val choice of turn_radius_m / max_iterations ({chosen}). Duration error: "
            f"the joined path's frames against the keys' {s['spacing_s']:g} s (a turned key needs a detour, as in the "
            f"thesis' Fig. 4.20); end gap: the path's last Hips to the key's, on the ground; foot skating "
            f"(share of contact frames that skate, stylemotion.synthesis.quality.skating) of the joined path before "
            f"cleaning; the takes' own frames between the keys: {fmt(take_skating, 1)} %. A pair whose trees do not "
            f"meet is a failure, counted. {prov}")
    turned = [_row(f"turned {fmt(a, 0)}°", [o for o in _select(r, "before", angle_deg=a) if o["kind"] == "turned"],
                   [o for o in _select(r, "after", angle_deg=a) if o["kind"] == "turned"]) for a in s["angles_deg"]]
    all_b = [o for o in _select(r, "before") if o["kind"] == "turned"]
    all_a = [o for o in _select(r, "after") if o["kind"] == "turned"]
    turned.append(_row("all angles", all_b, all_a))
    moved = []
    for scale in s["scales"]:
        for a in s["move_angles_deg"]:
            moved.append(_row(f"moved: {fmt(scale, 1)} × the distance, turned {fmt(a, 0)}° about the first key",
                              [o for o in _select(r, "before", angle_deg=a, scale=scale) if o["kind"] == "moved"],
                              [o for o in _select(r, "after", angle_deg=a, scale=scale) if o["kind"] == "moved"]))
    moved.append(_row("all moves", [o for o in _select(r, "before") if o["kind"] == "moved"],
                      [o for o in _select(r, "after") if o["kind"] == "moved"]))
    radii, budgets = s["radius_candidates"], s["iteration_candidates"]
    crows = []
    for radius in radii:
        for budget in budgets:
            key = f"{radius:g}/{budget}"
            row = [fmt(radius, 2), str(budget)]
            for x in r["per_seed"]:
                _, dur = x["val_score_by_radius"][key]
                f = x["val_figures"][key]
                row.append(f"{f['joined']} / {f['attempted']} joined, {fmt(dur, 2)} s")
            crows.append(row)
    crows.append(["chosen", ""] + [f"{fmt(x['turn_radius_m'], 2)} / {x['max_iterations']}" for x in r["per_seed"]])
    c = r["choice"]
    edges = [name for name, value, grid in (("turn_radius_m", c["turn_radius_m"], radii),
                                             ("max_iterations", c["max_iterations"], budgets))
             if len(grid) > 1 and value in (max(grid), min(grid))]
    edge = (f" {' and '.join(edges)}: the choice lies at the edge of the candidates; values beyond them were not "
            f"tried." if edges else "")
    choice = (md_table(["turn_radius_m", "max_iterations", *[f"seed {x['seed']}" for x in r["per_seed"]]], crows)
              + f"\n\nVal: {s['val_takes']} {', '.join(s['contents'])} val take(s) per seed, the turned second keys "
                f"({len(s['angles_deg'])} angles); each cell: joined / attempted and the mean abs. duration error of "
                f"the joined pairs. A smaller max_iterations is the same search cut short (a pair that met at its last "
                f"iteration rerun with it). Rule: {c['rule']}. Default: turn_radius_m = {fmt(c['turn_radius_m'], 2)} "
                f"m, max_iterations = {c['max_iterations']}.{edge} {prov}")
    tb, ta = len([o for o in all_b if o["joined"]]), len([o for o in all_a if o["joined"]])
    mb = len([o for o in _select(r, "before") if o["kind"] == "moved" and o["joined"]])
    ma = len([o for o in _select(r, "after") if o["kind"] == "moved" and o["joined"]])
    nm = len([o for o in _select(r, "after") if o["kind"] == "moved"])
    summary = (f"Krüger §4.3 turned / moved second key (Bandai walk test takes, {n} seeds; "
               f"[benchmarks/reconstruct.md](benchmarks/reconstruct.md)): joined {tb} / {len(all_b)} turned and "
               f"{mb} / {nm} moved keys before, **{ta} / {len(all_a)}** and **{ma} / {nm}** with the turning-aware "
               f"search (turn_radius_m = {fmt(r['choice']['turn_radius_m'], 2)} m, max_iterations = "
               f"{r['choice']['max_iterations']}, chosen on val takes); mean abs. "
               f"duration error of the joined turned pairs {fmt(_mean(all_a, 'duration_error_s', absolute=True), 2)} "
               f"s (the detour), foot skating {fmt(_mean(all_a, 'skating', 100.0), 1)} % (the takes' "
               f"{fmt(take_skating, 1)} %).")
    return {"turned": md_table(HEADER, turned) + "\n\n" + note, "moved": md_table(HEADER, moved) + "\n\n" + note,
            "choice": choice, "summary": summary}
