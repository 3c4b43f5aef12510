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

``turn_radius_m``, ``max_iterations`` and ``facing_first_iterations`` are chosen together on the val takes among
``--radii`` × ``--iterations`` × ``--facing-first`` (by default 1, 1.5, 2.5 m × 12, 24 × 0, 6, 12; radius 0 — D_node
of eq. 4.12 with the facing term — and 12 iterations are the search before this suite, measured on the test cases as
"before"; ``facing_first_iterations`` > 0 runs that search first and the turn-aware one only when its trees do not
meet). The val cases are the val walk's turned second keys and, since the choice also decides keys that need no
turn, **straight** key pairs: every pair ``--straight-spacings`` s apart of ``--straight-val-takes`` val take(s) per
``--straight-contents`` (walks, turning walks, runs). Rule: fewest failed val cases, then the lowest sum of the two
kinds' mean |duration error| of the joined pairs (turned, straight). Test cases are joined with (0, 12, 0)
(**before**) and with the seed's choice (**after**): joined / attempted (a pair whose
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
    parser.add_argument("--facing-first", type=int, nargs="+", default=[0, 6, 12],
                        help="candidates of DynamicMotionGraph.facing_first_iterations (0: the turn-aware search "
                             "alone)")
    parser.add_argument("--straight-contents", nargs="+", default=["walk", "walk-turn-left", "walk-turn-right", "run"],
                        help="contents of the val takes whose own (straight) key pairs join the val cases")
    parser.add_argument("--straight-val-takes", type=int, default=1, help="straight val takes per content and seed")
    parser.add_argument("--straight-spacings", type=float, nargs="+", default=[1.0, 2.0, 4.0],
                        help="seconds between the straight val keys")


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


def _straight_cases(takes, fps: float, args: argparse.Namespace) -> list[dict[str, Any]]:
    """Every key pair ``--straight-spacings`` apart of ``takes``, the keys as recorded."""
    from stylemotion.reconstruct.benchmark import key_pairs

    return [{"take": t.name, "kind": "straight", "angle_deg": 0.0, "scale": 1.0, "first": a, "second": b}
            for t in takes for spacing in args.straight_spacings for a, b in key_pairs(t.positions, fps, spacing)]


def _val_score(figures: dict[str, Any]) -> list[float]:
    """(failed cases, Σ over the kinds (turned, straight) present of the mean |duration error| s of the joined ones)
    from :func:`_val_figures`: lower is better, compared in that order; a kind none of whose cases joined adds
    infinity."""
    kinds = [figures[kind] for kind in ("turned", "straight") if figures[kind]["attempted"]]
    total = sum(float("inf") if k["duration_error_s"] is None else k["duration_error_s"] for k in kinds)
    return [float(figures["attempted"] - figures["joined"]), total]


def _budget_outcomes(graph, cases: list[dict[str, Any]], radius: float, budgets: list[int]
                     ) -> dict[int, list[dict[str, Any]]]:
    """The outcomes of one search (``turn_radius_m = radius``, no facing-first) at every iteration budget: one
    search per case at the largest budget; a smaller budget's outcome is the same search cut short — joined when
    it met before its last iteration (identical path), rerun when it met at that iteration (it stops without the
    extra iteration), failed otherwise."""
    top = max(budgets)
    graph.turn_radius_m, graph.max_iterations, graph.facing_first_iterations = float(radius), top, 0
    full = _outcomes(graph, cases, quality=False)
    by_budget = {}
    for budget in sorted(budgets):
        outcomes = []
        for case, o in zip(cases, full):
            met = o.get("met_at_iteration") if o["joined"] else None
            if met is not None and met == budget and budget < top:
                graph.max_iterations = budget
                o = _outcomes(graph, [case], quality=False)[0]
                graph.max_iterations = top
            elif met is None or met > budget:
                o = {**{k: o[k] for k in ("take", "kind", "angle_deg", "scale", "spacing_s", "seconds")},
                     "joined": False}
            outcomes.append(o)
        by_budget[budget] = outcomes
    return by_budget


def _val_figures(outcomes: list[dict[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {"joined": sum(o["joined"] for o in outcomes), "attempted": len(outcomes)}
    for kind in ("turned", "straight"):
        of_kind = [o for o in outcomes if o["kind"] == kind]
        joined = [abs(o["duration_error_s"]) for o in of_kind if o["joined"]]
        out[kind] = {"joined": len(joined), "attempted": len(of_kind),
                     "duration_error_s": float(np.mean(joined)) if joined else None,
                     "seconds": float(np.mean([o["seconds"] for o in of_kind])) if of_kind else None}
    return out


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
        straight_takes = choose_queries(parts["val"], args.straight_contents, args.straight_val_takes, rng)
        val_cases = ([c for t in val_takes for c in _cases(t, fps, args, moved=False)]
                     + _straight_cases(straight_takes, fps, args))
        # eq. 4.12's search alone at each facing-first budget, then each turn-aware search at each iteration budget;
        # a candidate's outcome is the library's: the facing search's when it joined, else the turn-aware one's
        # (which starts afresh), its seconds the sum of both
        first_budgets = [f for f in args.facing_first if f > 0]
        facing = _budget_outcomes(graph, val_cases, 0.0, first_budgets) if first_budgets else {}
        scores, val_figures = {}, {}
        for radius in args.radii:
            turning = _budget_outcomes(graph, val_cases, radius, args.iterations)
            for budget in sorted(args.iterations):
                for first_budget in sorted(args.facing_first):
                    outcomes = []
                    for i, o in enumerate(turning[budget]):
                        f = facing[first_budget][i] if first_budget > 0 else None
                        if f is not None and f["joined"]:
                            o = f
                        elif f is not None:
                            o = {**o, "seconds": round(o["seconds"] + f["seconds"], 3)}
                        outcomes.append(o)
                    key = f"{radius:g}/{budget}/{first_budget}"
                    val_figures[key] = _val_figures(outcomes)
                    scores[key] = _val_score(val_figures[key])
                    print(f"seed {seed} val turn_radius_m {radius:g}, max_iterations {budget}, facing_first "
                          f"{first_budget}: {scores[key]}", flush=True)
        best = min(scores, key=lambda c: tuple(scores[c]))
        chosen, iterations, first_iterations = float(best.split("/")[0]), int(best.split("/")[1]), \
            int(best.split("/")[2])
        test_cases = [c for t in test_takes for c in _cases(t, fps, args, moved=True)]
        test: dict[str, list] = {}
        before = (0.0, min(args.iterations), 0)
        for label, (radius, budget, first_budget) in (("before", before),
                                                      ("after", (chosen, iterations, first_iterations))):
            if label == "after" and (radius, budget, first_budget) == before:
                test["after"] = test["before"]
                continue
            graph.turn_radius_m, graph.max_iterations, graph.facing_first_iterations = radius, budget, first_budget
            test[label] = _outcomes(graph, test_cases, quality=True)
            joined = sum(o["joined"] for o in test[label])
            print(f"seed {seed} test {label} (turn_radius_m {radius:g}, max_iterations {budget}, facing_first "
                  f"{first_budget}): {joined} / {len(test[label])}", flush=True)
        per_seed.append({"seed": seed, "val_takes": [t.name for t in val_takes],
                         "straight_val_takes": [t.name for t in straight_takes],
                         "facing_first_iterations": first_iterations,
                         "test_takes": [t.name for t in test_takes], "val_score_by_radius": scores,
                         "val_figures": val_figures, "turn_radius_m": chosen, "max_iterations": iterations,
                         "test": test,
                         "take_skating": {t.name: _take_skating(t, fps, args.spacing) for t in test_takes},
                         "settings": graph.settings(), "seconds": round(time.perf_counter() - started, 1)})
    counts = Counter(f"{r['turn_radius_m']:g}/{r['max_iterations']}/{r['facing_first_iterations']}"
                     for r in per_seed)
    top = max(counts.values())
    default = min((c for c in counts if counts[c] == top),
                  key=lambda c: tuple(np.mean([r["val_score_by_radius"][c] for r in per_seed], axis=0)))
    return {"splits": {"kind": "by take, one split per seed", "choose": "val", "report": "test",
                       "database": "train", "per_seed": splits},
            "settings": {"contents": args.contents, "takes": args.takes, "val_takes": args.val_takes,
                         "spacing_s": args.spacing, "angles_deg": args.angles, "scales": args.scales,
                         "move_angles_deg": args.move_angles, "radius_candidates": args.radii,
                         "iteration_candidates": args.iterations, "facing_first_candidates": args.facing_first,
                         "straight_contents": args.straight_contents, "straight_val_takes": args.straight_val_takes,
                         "straight_spacings_s": args.straight_spacings, "clean": False},
            "choice": {"turn_radius_m": float(default.split("/")[0]), "max_iterations": int(default.split("/")[1]),
                       "facing_first_iterations": int(default.split("/")[2]),
                       "rule": "each seed chooses (turn_radius_m, max_iterations, facing_first_iterations) on its val "
                               "takes' turned keys and straight key pairs: fewest failed cases, then the lowest sum "
                               "over the two kinds of the mean |duration error| of the joined ones; the default is "
                               "the most frequent choice (ties: the lowest mean val score)"},
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
    chosen = ", ".join(f"{fmt(x['turn_radius_m'], 2)} m / {x['max_iterations']} / {x['facing_first_iterations']}"
                       for x in r["per_seed"])
    take_skating = float(np.mean([v for x in r["per_seed"] for v in x["take_skating"].values()])) * 100.0
    note = (f"Test: {s['takes']} {', '.join(s['contents'])} test take(s) per seed × {n} seeds, the first key pair "
            f"{s['spacing_s']:g} s apart; database = the seed's train takes; no cleaning. before: turn_radius_m = 0 "
            f"(D_node of eq. 4.12 with the facing term), max_iterations = {min(s['iteration_candidates'])}; after: "
            f"the seed's val choice of turn_radius_m / max_iterations / facing_first_iterations ({chosen}). "
            f"Duration error: "
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
    radii, budgets, firsts = s["radius_candidates"], s["iteration_candidates"], s["facing_first_candidates"]
    crows = []

    def kind_cell(f: dict, kind: str) -> str:
        k = f[kind]
        return f"{k['joined']}/{k['attempted']}, {fmt(k['duration_error_s'], 2)} s, {fmt(k['seconds'], 1)} s/pair"

    for radius in radii:
        for budget in budgets:
            for first in firsts:
                key = f"{radius:g}/{budget}/{first}"
                row = [fmt(radius, 2), str(budget), str(first)]
                for x in r["per_seed"]:
                    f = x["val_figures"][key]
                    row.append(f"turned {kind_cell(f, 'turned')}; straight {kind_cell(f, 'straight')}")
                crows.append(row)
    crows.append(["chosen", "", ""] + [f"{fmt(x['turn_radius_m'], 2)} / {x['max_iterations']} / "
                                       f"{x['facing_first_iterations']}" for x in r["per_seed"]])
    c = r["choice"]
    edges = [name for name, value, grid in (("turn_radius_m", c["turn_radius_m"], radii),
                                             ("max_iterations", c["max_iterations"], budgets),
                                             ("facing_first_iterations", c["facing_first_iterations"], firsts))
             if len(grid) > 1 and value in (max(grid), min(grid))]
    edge = (f" {' and '.join(edges)}: the choice lies at the edge of the candidates; values beyond them were not "
            f"tried." if edges else "")
    straight = sum(x["val_figures"][f"{radii[0]:g}/{budgets[0]}/{firsts[0]}"]["straight"]["attempted"]
                   for x in r["per_seed"])
    choice = (md_table(["turn_radius_m", "max_iterations", "facing_first_iterations",
                        *[f"seed {x['seed']}" for x in r["per_seed"]]], crows)
              + f"\n\nVal: {s['val_takes']} {', '.join(s['contents'])} val take(s) per seed, the turned second keys "
                f"({len(s['angles_deg'])} angles), and the straight key pairs "
                f"{', '.join(fmt(v, 0) for v in s['straight_spacings_s'])} s apart of {s['straight_val_takes']} val "
                f"take(s) per {', '.join(s['straight_contents'])} "
                f"({straight} pairs over the seeds); each cell: joined / attempted, the mean abs. duration error of "
                f"the joined pairs and the mean seconds per pair (a failed facing-first search's time included; at a "
                f"cut-short budget the time of the longer search). A smaller budget is the same search cut short (a "
                f"pair that met at its last iteration rerun with it); a facing-first candidate takes eq. 4.12's path "
                f"where that search joined and the turn-aware search's otherwise, as the library does. Rule: "
                f"{c['rule']}. Default: turn_radius_m = {fmt(c['turn_radius_m'], 2)} m, max_iterations = "
                f"{c['max_iterations']}, facing_first_iterations = {c['facing_first_iterations']}.{edge} {prov}")
    tb, ta = len([o for o in all_b if o["joined"]]), len([o for o in all_a if o["joined"]])
    mb = len([o for o in _select(r, "before") if o["kind"] == "moved" and o["joined"]])
    ma = len([o for o in _select(r, "after") if o["kind"] == "moved" and o["joined"]])
    nm = len([o for o in _select(r, "after") if o["kind"] == "moved"])
    summary = (f"Krüger §4.3 turned / moved second key (Bandai walk test takes, {n} seeds; "
               f"[benchmarks/reconstruct.md](benchmarks/reconstruct.md)): joined {tb} / {len(all_b)} turned and "
               f"{mb} / {nm} moved keys before, **{ta} / {len(all_a)}** and **{ma} / {nm}** with the turning-aware "
               f"search (turn_radius_m = {fmt(r['choice']['turn_radius_m'], 2)} m, max_iterations = "
               f"{r['choice']['max_iterations']}, facing_first_iterations = "
               f"{r['choice']['facing_first_iterations']}, chosen on val takes); mean abs. "
               f"duration error of the joined turned pairs {fmt(_mean(all_a, 'duration_error_s', absolute=True), 2)} "
               f"s (the detour), foot skating {fmt(_mean(all_a, 'skating', 100.0), 1)} % (the takes' "
               f"{fmt(take_skating, 1)} %).")
    return {"turned": md_table(HEADER, turned) + "\n\n" + note, "moved": md_table(HEADER, moved) + "\n\n" + note,
            "choice": choice, "summary": summary}
