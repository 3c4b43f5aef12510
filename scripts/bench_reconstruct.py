"""Benchmark: reconstruction from six markers, Krüger's Tables 2.3/2.4 on Bandai (JSON lines on stdout).

Queries: test takes of walk, run, wave and raise-up (``--contents``); markers = hands, feet, head and hips
of the take with uniform noise of ± ``--noise-mm`` (thesis: 1 mm). Databases: ``HDM`` = every train take,
``CMU-`` = the train takes without the query's content (the thesis' "CMU without collection 86"). Per query
take, database and feature set one line: mean (max) per-joint error in cm, the nearest-neighbour baseline
(the nearest database pose placed at the markers) for marker-only sets, frames/s; a ``summary`` line per
database and feature set averages over the queries.

    OMP_NUM_THREADS=1 python scripts/bench_reconstruct.py --data bandai > benchmarks/reconstruct.jsonl
    python scripts/bench_reconstruct.py --tiny      # synthetic, a few frames: checks the script only
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")  # the per-frame SVDs are tiny: threads only cost

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from stylemotion.datasets import TakeSet  # noqa: E402
from stylemotion.reconstruct import (  # noqa: E402
    DEFAULT_MARKERS,
    SparseReconstructor,
    joint_errors_cm,
    tracks_from_positions,
)
from stylemotion.reconstruct.benchmark import benchmark_queries, benchmark_split  # noqa: E402
from stylemotion.search.database import MotionDatabase  # noqa: E402


def emit(record: dict) -> None:
    print(json.dumps(record), flush=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", choices=("bandai", "synthetic"), default="bandai")
    parser.add_argument("--root", default=None, help="Bandai folder or data.zip (default: $STYLEMOTION_DATA/...)")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--contents", default="walk,run,wave-both-hands,raise-up-both-hands",
                        help="query contents (test takes), comma-separated content labels of the data")
    parser.add_argument("--features", default="E15,E30,E39,E15x3,pca16")
    parser.add_argument("--databases", default="HDM,CMU-")
    parser.add_argument("--k", type=int, default=64)
    parser.add_argument("--takes", type=int, default=3, help="test takes per content, taken in turn from each style")
    parser.add_argument("--frames", type=int, default=0, help="first frames of each query take (0 = all)")
    parser.add_argument("--noise-mm", type=float, default=1.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--tiny", action="store_true", help="synthetic, walk and run, 1 take, 20 frames")
    args = parser.parse_args(argv)
    if args.tiny:
        args.data, args.contents, args.takes, args.frames = "synthetic", "walk,run", 1, 20
    try:
        data, train, test = benchmark_split(args.data, args.root, args.seed, args.workers)
        queries = benchmark_queries(test, args.contents, args.takes)
    except ValueError as exc:
        raise SystemExit(str(exc)) from None
    emit({"kind": "setup", "data": data.name, "fps": data.fps, "train_takes": len(train), "test_takes": len(test),
          "queries": [q.name for q in queries], "k": args.k, "noise_mm": args.noise_mm, "markers": DEFAULT_MARKERS})
    rng = np.random.default_rng(args.seed)
    noisy = {}
    for q in queries:
        truth = q.positions[: args.frames] if args.frames else q.positions
        markers = tracks_from_positions(truth, DEFAULT_MARKERS, data.fps).positions
        noisy[q.name] = (truth, markers + rng.uniform(-1, 1, markers.shape) * args.noise_mm / 1000.0)
    for db_name in [d for d in args.databases.split(",") if d]:
        for features in [f for f in args.features.split(",") if f]:
            rows, cache = [], {}
            for q in queries:
                content = q.content if db_name == "CMU-" else None
                if content not in cache:
                    takes = [t for t in train if content is None or t.content != content]
                    database = MotionDatabase.from_takeset(TakeSet(data.name, takes, data.fps))
                    t0 = time.perf_counter()
                    cache = {content: (SparseReconstructor(database, DEFAULT_MARKERS, features, args.k),
                                       time.perf_counter() - t0)}
                rec, build_s = cache[content]
                truth, markers = noisy[q.name]
                result = rec.reconstruct(markers)
                err = joint_errors_cm(result.positions, truth)
                row = {"kind": "query", "database": db_name, "features": features, "take": q.name,
                       "content": q.content, "frames": len(truth), "db_frames": rec.database.num_frames,
                       "mean_cm": round(err["mean_cm"], 3), "max_cm": round(err["max_cm"], 3),
                       "frames_per_s": round(result.frames_per_second, 1), "build_s": round(build_s, 2)}
                if not rec.guided:
                    base = joint_errors_cm(rec.nearest_neighbour(markers), truth)
                    row["nn_mean_cm"], row["nn_max_cm"] = round(base["mean_cm"], 3), round(base["max_cm"], 3)
                emit(row)
                rows.append(row)
            if rows:
                frames = sum(r["frames"] for r in rows)
                summary = {"kind": "summary", "database": db_name, "features": features, "queries": len(rows),
                           "mean_cm": round(sum(r["mean_cm"] * r["frames"] for r in rows) / frames, 3),
                           "max_cm": max(r["max_cm"] for r in rows),
                           "frames_per_s": round(frames / sum(r["frames"] / r["frames_per_s"] for r in rows), 1)}
                if "nn_mean_cm" in rows[0]:
                    summary["nn_mean_cm"] = round(sum(r["nn_mean_cm"] * r["frames"] for r in rows) / frames, 3)
                emit(summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
