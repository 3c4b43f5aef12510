"""Benchmark: motion completion and texturing with the motion database (Krüger §4.2) on Bandai (JSON lines).

Queries: test takes of walk, run, wave and raise-up (``--contents``, ``--takes`` each); database = every train take.
Completion: the legs (hips and legs) of the take given, the upper body synthesized; error per upper-body joint in
cm against the take, and the nearest-neighbour baseline (per frame the nearest database pose in the same features,
its hips on the take's). Texturing: keys every ``--every`` frames (3, 6 and 10 by default) of the take joined by a
cubic spline, then textured; error per joint against the take, against the spline alone, and the foot-skating ratio
of the take, the spline and the result. One line per query and mode, a ``summary`` line per mode (frame-weighted means).

    python scripts/bench_texture.py --data bandai > benchmarks/texture.jsonl
    python scripts/bench_texture.py --tiny      # synthetic, walk and run, 1 take, 40 frames: checks the script only
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

from stylemotion.datasets import TakeSet
from stylemotion.reconstruct.benchmark import benchmark_queries, benchmark_split
from stylemotion.reconstruct.texture import LEG_JOINTS, MotionTexturer, key_spline
from stylemotion.search.database import MotionDatabase
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX
from stylemotion.synthesis.quality import skating

UPPER = [JOINT_INDEX[j] for j in CANONICAL_JOINTS if j not in LEG_JOINTS]


def emit(record: dict) -> None:
    print(json.dumps(record), flush=True)


def cm(a: np.ndarray, b: np.ndarray, joints: list[int] | None = None) -> float:
    idx = list(range(a.shape[1])) if joints is None else joints
    return float(np.linalg.norm(a[:, idx] - b[:, idx], axis=-1).mean() * 100.0)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", choices=("bandai", "synthetic"), default="bandai")
    parser.add_argument("--root", default=None, help="Bandai folder or data.zip (default: $STYLEMOTION_DATA/...)")
    parser.add_argument("--contents", default="walk,run,wave-both-hands,raise-up-both-hands")
    parser.add_argument("--takes", type=int, default=3, help="test takes per content, taken in turn from each style")
    parser.add_argument("--frames", type=int, default=0, help="first frames of each query take (0 = all)")
    parser.add_argument("--every", default="3,6,10", help="texturing: frames between keys (comma-separated)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--tiny", action="store_true", help="synthetic, walk and run, 1 take, 40 frames")
    args = parser.parse_args(argv)
    if args.tiny:
        args.data, args.contents, args.takes, args.frames = "synthetic", "walk,run", 1, 40
    try:
        data, train, test = benchmark_split(args.data, args.root, args.seed)
        queries = benchmark_queries(test, args.contents, args.takes)
    except ValueError as exc:
        raise SystemExit(str(exc)) from None
    database = MotionDatabase.from_takeset(TakeSet(data.name, train, data.fps))
    started = time.perf_counter()
    texturers = {mode: MotionTexturer(database, mode) for mode in ("complete", "texture")}
    everies = [int(e) for e in args.every.split(",") if e]
    emit({"kind": "setup", "data": data.name, "fps": data.fps, "db_frames": database.num_frames,
          "queries": [q.name for q in queries], "every": everies, "build_s": round(time.perf_counter() - started, 2)})
    rows: dict[str, list[dict]] = {"complete": [], **{f"texture@{e}": [] for e in everies}}
    for q in queries:
        truth = np.asarray(q.positions[: args.frames] if args.frames else q.positions, dtype=np.float64)
        legs = truth.copy()
        legs[:, UPPER] = np.nan
        t0 = time.perf_counter()
        done = texturers["complete"].apply(legs)
        row = {"kind": "query", "mode": "complete", "take": q.name, "content": q.content, "frames": len(truth),
               "upper_cm": round(cm(done.positions, truth, UPPER), 3),
               "nn_upper_cm": round(cm(done.nearest_neighbour, truth, UPPER), 3),
               "seconds": round(time.perf_counter() - t0, 3)}
        emit(row)
        rows["complete"].append(row)
        for every in everies:
            spline = key_spline(truth, every)
            t0 = time.perf_counter()
            textured = texturers["texture"].apply(spline)
            row = {"kind": "query", "mode": f"texture@{every}", "take": q.name, "content": q.content,
                   "frames": len(truth), "textured_cm": round(cm(textured.positions, truth), 3),
                   "spline_cm": round(cm(spline, truth), 3), "skating_take": round(skating(truth, data.fps)[0], 4),
                   "skating_spline": round(skating(spline, data.fps)[0], 4),
                   "skating_textured": round(skating(textured.positions, data.fps)[0], 4),
                   "seconds": round(time.perf_counter() - t0, 3)}
            emit(row)
            rows[f"texture@{every}"].append(row)
    for mode, found in rows.items():
        frames = sum(r["frames"] for r in found)
        keys = [k for k in found[0] if k.endswith("_cm") or k.startswith("skating")]
        summary = {"kind": "summary", "mode": mode, "queries": len(found), "frames": frames,
                   **{k: round(sum(r[k] * r["frames"] for r in found) / frames, 4) for k in keys},
                   "frames_per_s": round(frames / sum(r["seconds"] for r in found), 1)}
        emit(summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
