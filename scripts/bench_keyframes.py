"""Benchmark: motion from keyframes with dynamic motion graphs (Krüger §4.3.5) on Bandai (JSON lines on stdout).

Keys: from test takes of walk, the turns and run (``--contents``, ``--takes`` each), one key every 1, 2 and 4 s
(``--spacings``) from 0.2 s to the end of the take; database = every train take (the query takes are not in it).
Per take and spacing one line: key pairs joined (success), the intermediate result's mean per-joint distance to
each key (cm; the cleaned result holds the keys exactly), the duration error of the joined paths before
retiming (s), foot skating of the take, the intermediate and the cleaned result, the mean per-joint distance of
the result to the take itself between the first and last key (cm; one of many plausible motions, so an
indication only), seconds per key pair. ``summary`` lines per spacing. Then the thesis' "rotate second key frame"
experiment (Fig. 4.19/4.20): keys 2 s apart from ``--rotate-take``, the second turned about its Hips by
``--rotate-step`` degree steps: per angle success, frames and cost of the joined path (no retiming).

    python scripts/bench_keyframes.py --data bandai > benchmarks/keyframes.jsonl
    python scripts/bench_keyframes.py --tiny      # synthetic, walk, 1 take, 2 s: checks the script only
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

from stylemotion.datasets import TakeSet
from stylemotion.geometry import rotate_yaw
from stylemotion.reconstruct.benchmark import benchmark_queries, benchmark_split
from stylemotion.reconstruct.keyframes import DynamicMotionGraph, Keyframe, NoConnectionError, keys_from_motion
from stylemotion.search.database import MotionDatabase
from stylemotion.skeleton import JOINT_INDEX
from stylemotion.synthesis.quality import skating

START_S = 0.2


def emit(record: dict) -> None:
    print(json.dumps(record), flush=True)


def turned(pose: np.ndarray, degrees: float) -> np.ndarray:
    hips = pose[JOINT_INDEX["Hips"]] * np.array([1.0, 0.0, 1.0])
    return rotate_yaw(pose - hips, np.deg2rad(degrees)) + hips


def keys_run(graph: DynamicMotionGraph, take, spacing: float, fps: float) -> dict:
    positions = np.asarray(take.positions, dtype=np.float64)
    keys = keys_from_motion(positions, fps, spacing, START_S)
    first = int(round(START_S * fps))
    row = {"kind": "query", "take": take.name, "content": take.content, "spacing_s": spacing, "keys": len(keys)}
    pairs, joined, seconds = [], 0, 0.0
    for a, b in zip(keys[:-1], keys[1:]):  # pair by pair: a failed pair does not hide the others
        t0 = time.perf_counter()
        try:
            pairs.append(graph.connect(a, b).figures)
            joined += 1
        except NoConnectionError:
            pass
        seconds += time.perf_counter() - t0
    row.update({"pairs": len(keys) - 1, "joined": joined, "seconds_per_pair": round(seconds / (len(keys) - 1), 3)})
    if pairs:
        row["duration_error_s"] = round(float(np.mean([abs(p["duration_error_s"]) for p in pairs])), 4)
        row["iterations"] = round(float(np.mean([p["iterations"] for p in pairs])), 2)
    if joined == len(keys) - 1:
        result = graph.synthesize(keys)
        truth = positions[first:first + len(result.positions)]
        errors = [result.settings["intermediate_first_key_error_cm"]]
        errors += [p["intermediate_key_error_cm"] for p in result.pairs]
        row.update({"key_error_cm": round(float(np.mean(errors)), 3),
                    "skating_take": round(skating(truth, fps)[0], 4),
                    "skating_intermediate": round(skating(result.intermediate, fps)[0], 4),
                    "skating_result": round(skating(result.positions, fps)[0], 4),
                    "to_take_cm": round(float(np.linalg.norm(result.positions - truth, axis=-1).mean() * 100), 3),
                    "clean_s": result.timings["clean"]})
    return row


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", choices=("bandai", "synthetic"), default="bandai")
    parser.add_argument("--root", default=None, help="Bandai folder or data.zip (default: $STYLEMOTION_DATA/...)")
    parser.add_argument("--contents", default="walk,walk-turn-left,walk-turn-right,run")
    parser.add_argument("--takes", type=int, default=4, help="test takes per content, taken in turn from each style")
    parser.add_argument("--spacings", default="1,2,4", help="seconds between keys (comma-separated)")
    parser.add_argument("--rotate-take", default="", help="take of the rotation experiment (default: first walk)")
    parser.add_argument("--rotate-step", type=float, default=30.0, help="degrees between turned second keys")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--tiny", action="store_true", help="synthetic, walk, 1 take, keys 2 s apart, 2 angles")
    args = parser.parse_args(argv)
    if args.tiny:
        args.data, args.contents, args.takes, args.spacings, args.rotate_step = "synthetic", "walk", 1, "2", 180.0
    try:
        data, train, test = benchmark_split(args.data, args.root, args.seed)
        queries = benchmark_queries(test, args.contents, args.takes)
    except ValueError as exc:
        raise SystemExit(str(exc)) from None
    database = MotionDatabase.from_takeset(TakeSet(data.name, train, data.fps))
    t0 = time.perf_counter()
    graph = DynamicMotionGraph(database)
    emit({"kind": "setup", "data": data.name, "fps": data.fps, "db_frames": database.num_frames,
          "queries": [q.name for q in queries], "settings": graph.settings(),
          "build_s": round(time.perf_counter() - t0, 2)})
    for spacing in [float(s) for s in args.spacings.split(",") if s]:
        rows = []
        for q in queries:
            if (q.num_frames - 1) / data.fps - START_S < spacing:
                emit({"kind": "skipped", "take": q.name, "spacing_s": spacing,
                      "why": f"{q.num_frames} frames hold no two keys {spacing:g} s apart"})
                continue
            row = keys_run(graph, q, spacing, data.fps)
            emit(row)
            rows.append(row)
        if not rows:
            continue
        pairs, joined = sum(r["pairs"] for r in rows), sum(r["joined"] for r in rows)
        complete = [r for r in rows if "key_error_cm" in r]
        summary = {"kind": "summary", "spacing_s": spacing, "takes": len(rows), "pairs": pairs, "joined": joined,
                   "success": round(joined / pairs, 4),
                   "seconds_per_pair": round(float(np.average([r["seconds_per_pair"] for r in rows],
                                                              weights=[r["pairs"] for r in rows])), 3)}
        timed = [r for r in rows if "duration_error_s" in r]
        if timed:
            summary["duration_error_s"] = round(float(np.average([r["duration_error_s"] for r in timed],
                                                                 weights=[r["joined"] for r in timed])), 4)
        for key in ("key_error_cm", "skating_take", "skating_intermediate", "skating_result", "to_take_cm"):
            if complete:
                summary[key] = round(float(np.mean([r[key] for r in complete])), 4)
        emit(summary)
    walks = [t for t in test if t.content == "walk"]
    take = next((t for t in test if t.name == args.rotate_take), walks[0] if walks else queries[0])
    fps = data.fps
    a = Keyframe(0.0, np.asarray(take.positions[int(START_S * fps)], dtype=np.float64))
    second = np.asarray(take.positions[int(START_S * fps) + int(2 * fps)], dtype=np.float64)
    for angle in np.arange(0.0, 360.0, args.rotate_step):
        t0 = time.perf_counter()
        row = {"kind": "rotate", "take": take.name, "angle_deg": float(angle)}
        try:
            figures = graph.connect(a, Keyframe(2.0, turned(second, float(angle)))).figures
            row.update({"joined": True, "frames": figures["frames"], "cost_m": figures["cost_m"],
                        "iterations": figures["iterations"]})
        except NoConnectionError:
            row["joined"] = False
        row["seconds"] = round(time.perf_counter() - t0, 3)
        emit(row)
    return 0


if __name__ == "__main__":
    sys.exit(main())
