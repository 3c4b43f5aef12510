"""Suite ``fat_graph``: Krüger §2.5.3's fat graph (Shin and Oh 2006) as a motion graph that synthesizes, against a
plain motion graph (Kovar et al. 2002) on the same features and index, on Bandai.

Per seed: Bandai is split by take (``TakeSet.split(seed, 0.1, 0.1)``, grouped by content and style). The **val**
takes are one motion database: both graphs are built on it for every candidate setting (fat graph: base-pose
``--radii`` × hub ``--min-members``; plain graph: transition ``--thresholds``), pruned to their largest strongly
connected component, and walked. Each graph's setting is chosen there: the largest SCC coverage among the
candidates whose walks' mean transition pose gap is at most ``--max-gap-cm`` and none of whose walks got stuck
(none passing: the smallest mean gap). The **test** takes are another database: both graphs are built on it with
the seed's choices and measured:

* **coverage**: the share of the database's frames on an edge of the SCC, and the share the seed's random walks
  played;
* **walks**: ``--walks`` seeded random walks of ``--seconds`` s from random nodes (uniform choice among the edges
  out of a node, but kept to the take until ``--min-play`` s have played since the last transition), synthesized
  with the project's stitching (``append_clip``, ``--blend`` frames); per walk the
  transitions per second, the pose and velocity gap at each transition before blending, foot skating
  (``stylemotion.synthesis.quality.skating``) and the acceleration ratio at transitions
  (``transition_speed_ratio``); a walk that reaches a node without an edge out is stuck, counted;
* **goals**: ``--goals`` walks from a random node towards a random database frame (shortest in frames); a goal no
  edge of the SCC plays is a failure, counted.

The test takes' own foot skating is the reference.
"""

from __future__ import annotations

import argparse
import os
import time
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, fmt_spread, md_table, provenance_line, spread, take_split_record

DESCRIPTION = ("Krüger §2.5.3 fat graphs that synthesize vs a plain motion graph on Bandai: SCC and walk coverage, "
               "transition gaps, foot skating, stuck walks and goals; radius / threshold chosen on val takes")
VAL_FRACTION, TEST_FRACTION = 0.1, 0.1
DEFAULT_SEEDS = (0, 1, 2)
METHODS = ("fat graph", "motion graph")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--contents", nargs="+", default=None, help="Bandai contents of the databases (all)")
    parser.add_argument("--features", default="E15x3", help="feature set of the shared index (both graphs)")
    parser.add_argument("--radii", type=float, nargs="+", default=[0.2, 0.3, 0.5, 0.8],
                        help="fat graph: base-pose radius candidates (feature units)")
    parser.add_argument("--min-members", type=int, nargs="+", default=[10, 30],
                        help="fat graph: least frames of a hub cluster, candidates")
    parser.add_argument("--fat-k", type=int, default=64, help="fat graph: most neighbours per frame")
    parser.add_argument("--thresholds", type=float, nargs="+", default=[0.2, 0.3, 0.5, 0.8],
                        help="motion graph: transition threshold candidates (feature units)")
    parser.add_argument("--graph-k", type=int, nargs="+", default=[32, 128],
                        help="motion graph: most candidates per frame, candidates")
    parser.add_argument("--min-gap", type=int, default=10, help="motion graph: min_gap_frames")
    parser.add_argument("--walks", type=int, default=10, help="random walks per graph and seed")
    parser.add_argument("--seconds", type=float, default=20.0, help="length of a random walk")
    parser.add_argument("--goals", type=int, default=30, help="goal walks per graph and seed")
    parser.add_argument("--blend", type=int, default=10, help="blend frames at a transition")
    parser.add_argument("--min-play", type=float, default=0.5,
                        help="random walks: seconds played in a take after a transition before the next")
    parser.add_argument("--max-gap-cm", type=float, default=3.0,
                        help="val rule: largest mean transition pose gap of an eligible setting")


# -- run ----------------------------------------------------------------------------------------------------


def _mean(values: list[Any]) -> float | None:
    kept = [v for v in values if v is not None]
    return float(np.mean(kept)) if kept else None


def _evaluate(graph, rng: np.random.Generator, args: argparse.Namespace) -> dict[str, Any]:
    """Prune ``graph`` and measure its SCC, walks and goals (module docstring)."""
    from stylemotion.search.clip_graph import goal_walk, largest_scc, random_walk, synthesize, walk_figures, walk_frames

    scc = largest_scc(graph)
    db = graph.database
    played = np.zeros(db.num_frames, dtype=bool)
    walks = []
    for _ in range(args.walks):
        walk = random_walk(scc, args.seconds, rng, min_play_s=args.min_play)
        if walk.stuck:
            walks.append({"stuck": True})
            continue
        motion = synthesize(scc, walk, args.blend)
        played[motion.played] = True
        walks.append({"stuck": False, **walk_figures(scc, motion)})
    goals = []
    for _ in range(args.goals):
        goal = int(rng.integers(db.num_frames))
        start = int(rng.integers(scc.num_nodes)) if scc.num_nodes else -1
        found = goal_walk(scc, start, goal) if scc.num_nodes else None
        goals.append({"goal": goal, "reached": found is not None,
                      "seconds": None if found is None else (walk_frames(scc, found.edges) - 1) / db.fps})
    done = [w for w in walks if not w["stuck"]]
    covered = scc.covered()
    content = np.asarray(db.contents)[db.take_id]
    by_content = {str(c): float(covered[content == c].mean()) for c in sorted(set(db.contents))}
    return {"graph": graph.records(), "scc": scc.records(), "walk_coverage": float(played.mean()),
            "coverage_by_content": by_content,
            "walks": walks, "goals": goals,
            "stuck": len(walks) - len(done),
            "mean_pose_gap_cm": _mean([w["pose_gap_cm"] for w in done]),
            "mean_skating": _mean([w["foot_skating"] for w in done])}


def _build(method: str, index, frames, setting: dict[str, Any], args: argparse.Namespace, clusters=None):
    from stylemotion.search.fat_graph import fat_graph
    from stylemotion.search.motion_graph import motion_graph

    if method == "fat graph":
        return fat_graph(index, setting["radius"], args.fat_k, setting["min_members"], clusters=clusters, frames=frames)
    return motion_graph(index, setting["threshold"], setting["k"], args.min_gap, frames=frames)


def _candidates(method: str, args: argparse.Namespace) -> list[dict[str, Any]]:
    if method == "fat graph":
        return [{"radius": r, "min_members": m} for r in args.radii for m in args.min_members]
    return [{"threshold": t, "k": k} for t in args.thresholds for k in args.graph_k]


def _label(setting: dict[str, Any]) -> str:
    if "radius" in setting:
        return f"radius {setting['radius']:g}, hubs ≥ {setting['min_members']}"
    return f"threshold {setting['threshold']:g}, k {setting['k']}"


def _choose(outcomes: list[dict[str, Any]], max_gap_cm: float) -> int:
    """Index of the chosen candidate: the largest SCC coverage among the eligible (mean gap ≤ bound, no stuck walk;
    a graph whose walks made no transition has gap 0); none eligible: the smallest mean gap."""
    def gap(o: dict[str, Any]) -> float:
        return 0.0 if o["mean_pose_gap_cm"] is None else o["mean_pose_gap_cm"]

    eligible = [i for i, o in enumerate(outcomes) if o["stuck"] == 0 and gap(o) <= max_gap_cm]
    if eligible:
        return max(eligible, key=lambda i: (outcomes[i]["scc"]["coverage"], -i))
    return min(range(len(outcomes)), key=lambda i: (outcomes[i]["stuck"] > 0, gap(outcomes[i]), i))


def _database(takes, fps: float, name: str):
    from stylemotion.reconstruct.benchmark import database_of

    return database_of(name, takes, fps)


def _take_skating(takes) -> float:
    from stylemotion.synthesis.quality import skating

    return float(np.mean([skating(np.asarray(t.positions), t.fps)[0] for t in takes if len(t.positions) >= 2]))


def _graphs_on(takes, fps: float, name: str, args: argparse.Namespace, settings: dict[str, list[dict[str, Any]]],
               seed: int) -> dict[str, list[dict[str, Any]]]:
    """Per method, the outcome of every setting in ``settings[method]`` on the database of ``takes``; the walks of
    each graph draw from a generator of their own (``[seed, part, method, setting]``), so no setting's walks depend
    on another's."""
    from stylemotion.search.clip_graph import DatabaseFrames
    from stylemotion.search.fat_graph import base_poses
    from stylemotion.search.index import FrameIndex

    database = _database(takes, fps, name)
    index = FrameIndex(database, args.features)
    frames = DatabaseFrames.of(database)
    out: dict[str, list[dict[str, Any]]] = {}
    clusters_by_radius: dict[float, Any] = {}
    part = 0 if name == "val" else 1
    for m, method in enumerate(METHODS):
        out[method] = []
        for c, setting in enumerate(settings[method]):
            rng = np.random.default_rng([seed, part, m, c])
            started = time.perf_counter()
            clusters = None
            if method == "fat graph":
                if setting["radius"] not in clusters_by_radius:
                    clusters_by_radius[setting["radius"]] = base_poses(index, setting["radius"], args.fat_k)
                clusters = clusters_by_radius[setting["radius"]]
            graph = _build(method, index, frames, setting, args, clusters)
            outcome = {"setting": setting, **_evaluate(graph, rng, args),
                       "seconds": round(time.perf_counter() - started, 2)}
            print(f"  {name} {method} {_label(setting)}: SCC {outcome['scc']['nodes']} nodes, coverage "
                  f"{outcome['scc']['coverage']:.3f}, walks {outcome['walk_coverage']:.3f}, gap "
                  f"{fmt(outcome['mean_pose_gap_cm'], 2)} cm, stuck {outcome['stuck']}", flush=True)
            out[method].append(outcome)
    return out


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    from stylemotion.datasets.registry import load_dataset

    bandai = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"))
    per_seed, splits = [], []
    for seed in seeds:
        started = time.perf_counter()
        parts = bandai.split(seed, VAL_FRACTION, TEST_FRACTION, group_by=("content", "style"))
        val_takes = [t for t in parts["val"] if not args.contents or t.content in args.contents]
        test_takes = [t for t in parts["test"] if not args.contents or t.content in args.contents]
        splits.append(take_split_record(parts, seed, VAL_FRACTION, TEST_FRACTION))
        print(f"seed {seed}: val {len(val_takes)} takes, test {len(test_takes)} takes", flush=True)
        candidates = {m: _candidates(m, args) for m in METHODS}
        val = _graphs_on(val_takes, bandai.fps, "val", args, candidates, seed)
        chosen = {m: _choose(val[m], args.max_gap_cm) for m in METHODS}
        test = _graphs_on(test_takes, bandai.fps, "test", args, {m: [candidates[m][chosen[m]]] for m in METHODS},
                          seed)
        per_seed.append({"seed": seed, "val": val, "chosen": {m: candidates[m][chosen[m]] for m in METHODS},
                         "test": {m: test[m][0] for m in METHODS}, "test_take_skating": _take_skating(test_takes),
                         "test_frames": int(sum(len(t.positions) for t in test_takes)),
                         "seconds": round(time.perf_counter() - started, 1)})
    return {"splits": {"kind": "by take, one split per seed", "choose": "val (its takes are the database)",
                       "report": "test (its takes are the database)", "per_seed": splits},
            "settings": {"contents": args.contents or "all", "features": args.features, "radii": args.radii,
                         "min_members": args.min_members, "fat_k": args.fat_k, "thresholds": args.thresholds,
                         "graph_k": args.graph_k, "min_gap_frames": args.min_gap, "walks": args.walks,
                         "walk_seconds": args.seconds, "goals": args.goals, "blend_frames": args.blend,
                         "min_play_s": args.min_play,
                         "max_gap_cm": args.max_gap_cm},
            "rule": ("per seed and graph, on the val database: the largest SCC coverage among the settings whose "
                     f"walks' mean transition pose gap ≤ {args.max_gap_cm:g} cm and no walk stuck (none: the "
                     "smallest gap)"),
            "per_seed": per_seed}


# -- render -------------------------------------------------------------------------------------------------


def _walks(r: dict[str, Any], method: str) -> list[dict[str, Any]]:
    return [w for x in r["per_seed"] for w in x["test"][method]["walks"]]


def _per_seed(r: dict[str, Any], method: str, fn) -> dict[str, Any]:
    return spread([fn(x["test"][method]) for x in r["per_seed"]])


def _walk_stat(walks: list[dict[str, Any]], key: str, how=np.mean, scale: float = 1.0) -> float | None:
    values = [w[key] for w in walks if not w["stuck"] and w.get(key) is not None]
    return float(how(values)) * scale if values else None


HEADER = ["graph", "SCC nodes / edges", "SCC coverage", "walk coverage", "walks stuck", "transitions / s",
          "pose gap, cm: mean (max)", "velocity gap, m/s: mean (max)", "foot skating %", "accel. ratio at transitions",
          "goals reached", "s to goal"]


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    s = r["settings"]
    prov = provenance_line(record)
    n = len(r["per_seed"])
    rows = []
    for method in METHODS:
        walks = _walks(r, method)
        goals = [g for x in r["per_seed"] for g in x["test"][method]["goals"]]
        nodes = _per_seed(r, method, lambda t: t["scc"]["nodes"])
        edges = _per_seed(r, method, lambda t: t["scc"]["edges"])
        reached = [g for g in goals if g["reached"]]
        rows.append([
            method, f"{fmt(nodes.get('mean'), 0)} / {fmt(edges.get('mean'), 0)}",
            fmt_spread(_per_seed(r, method, lambda t: t["scc"]["coverage"] * 100.0), 1, " %"),
            fmt_spread(_per_seed(r, method, lambda t: t["walk_coverage"] * 100.0), 1, " %"),
            f"{sum(w['stuck'] for w in walks)} / {len(walks)}",
            fmt(_walk_stat(walks, "transitions_per_s"), 1),
            f"{fmt(_walk_stat(walks, 'pose_gap_cm'), 2)} ({fmt(_walk_stat(walks, 'pose_gap_cm_max', np.max), 1)})",
            f"{fmt(_walk_stat(walks, 'velocity_gap_mps'), 3)} "
            f"({fmt(_walk_stat(walks, 'velocity_gap_mps_max', np.max), 2)})",
            f"{fmt(_walk_stat(walks, 'foot_skating', scale=100.0), 1)} "
            f"(max {fmt(_walk_stat(walks, 'foot_skating', np.max, 100.0), 1)})",
            f"{fmt(_walk_stat(walks, 'transition_accel_ratio'), 2)} "
            f"(max {fmt(_walk_stat(walks, 'transition_accel_ratio', np.max), 2)})",
            f"{len(reached)} / {len(goals)}",
            fmt(float(np.mean([g["seconds"] for g in reached])) if reached else None, 1)])
    take_skating = float(np.mean([x["test_take_skating"] for x in r["per_seed"]])) * 100.0
    frames = int(np.mean([x["test_frames"] for x in r["per_seed"]]))
    chosen = "; ".join(f"seed {x['seed']}: fat graph {_label(x['chosen']['fat graph'])}, motion graph "
                       f"{_label(x['chosen']['motion graph'])}" for x in r["per_seed"])
    contents = s["contents"] if isinstance(s["contents"], str) else ", ".join(s["contents"])
    note = (f"Test: per seed the test takes ({contents} contents, {frames:,} frames on average) are the database; "
            f"both graphs on its {s['features']} index, pruned to the largest SCC; {s['walks']} random walks of "
            f"{s['walk_seconds']:g} s and {s['goals']} goal walks per graph and seed × {n} seeds. SCC coverage and "
            f"walk coverage: share of the database's frames on an SCC edge / played by the seed's walks (mean ± sd "
            f"over seeds). Gaps at transitions before blending (body-frame pose, mean over joints; joint velocities); "
            f"foot skating: stylemotion.synthesis.quality.skating of each walk (mean, max over walks; the test takes' "
            f"own: {fmt(take_skating, 1)} %); accel. ratio: transition_speed_ratio's peak acceleration at transitions "
            f"over the 99th percentile inside clips (mean, max over walks). A goal (a random database frame) no SCC "
            f"edge plays is a failure, counted; s to goal: the shortest walk's length. Settings chosen on val "
            f"({r['rule']}): {chosen}. Blend {s['blend_frames']} frames; a walk plays {s['min_play_s']:g} s in a "
            f"take after a transition before it may take the next (not tuned). {prov}")
    crows = []
    for method in METHODS:
        for i, setting in enumerate(r["per_seed"][0]["val"][method]):
            row = [method, _label(setting["setting"])]
            for x in r["per_seed"]:
                o = x["val"][method][i]
                row.append(f"{o['scc']['coverage'] * 100:.1f} %, {fmt(o['mean_pose_gap_cm'], 2)} cm, "
                           f"{o['stuck']} stuck")
            crows.append(row)
    choice = (md_table(["graph", "setting", *[f"seed {x['seed']}: SCC coverage, gap, stuck" for x in r["per_seed"]]],
                       crows)
              + f"\n\nVal: per seed the val takes are the database. Rule: {r['rule']}. {prov}")
    fat, plain = rows[0], rows[1]
    left_out = {m: sum(any(v < 0.1 for v in x["test"][m]["coverage_by_content"].values()) for x in r["per_seed"])
                for m in METHODS}
    summary = (f"Krüger §2.5.3 fat graph that synthesizes vs a plain motion graph (Bandai test takes as the database, "
               f"{n} seeds, settings chosen on val takes; [benchmarks/search.md](benchmarks/search.md)): SCC coverage "
               f"{fat[2]} vs {plain[2]} (seeds whose SCC leaves out a whole content, < 10 % of its frames: "
               f"{left_out['fat graph']} / {n} vs {left_out['motion graph']} / {n}), transition pose gap {fat[6]} vs "
               f"{plain[6]} cm, foot skating {fat[8]} vs {plain[8]} % (the takes' {fmt(take_skating, 1)} %), walks "
               f"stuck {fat[4]} vs {plain[4]}, goals reached {fat[10]} vs {plain[10]}.")
    grids = {"radius": s["radii"], "min_members": s["min_members"], "threshold": s["thresholds"], "k": s["graph_k"]}
    edges = sorted({key for x in r["per_seed"] for m in METHODS for key, value in x["chosen"][m].items()
                    if len(grids[key]) > 1 and value in (min(grids[key]), max(grids[key]))})
    if edges:
        choice += (f"\n\n{', '.join(edges)}: a choice lies at the edge of its candidates; values beyond them were not "
                   f"tried.")
    contents_seen = sorted({c for x in r["per_seed"] for c in x["test"]["fat graph"]["coverage_by_content"]})
    crow = [[c, *[fmt_spread(spread([x["test"][m]["coverage_by_content"].get(c, 0.0) * 100.0
                                      for x in r["per_seed"]]), 1, " %") for m in METHODS]]
            for c in contents_seen]
    by_content = (md_table(["content", *[f"{m}: SCC coverage" for m in METHODS]], crow)
                  + f"\n\nShare of each content's test frames on an edge of the largest SCC (mean ± sd over seeds), "
                    f"the settings above. {prov}")
    return {"table": md_table(HEADER, rows) + "\n\n" + note, "choice": choice, "summary": summary,
            "by_content": by_content}
