"""Motion-database search SPEED (Krüger Table 2.1): k-NN ms per query, one JSON object per line.

    python scripts/bench_search.py --out bench_search.jsonl                 # Table 2.1 on all of Bandai
    python scripts/bench_search.py --features E15 --copies 1,2,3
    python scripts/bench_search.py --smoke --out /tmp/smoke.jsonl            # tiny synthetic run (seconds)

Only timing lives here; it must run alone on an idle machine, and its figures are not in benchmarks/search.md until
they are re-measured so (the search's quality figures — LNG against DTW, retrieval, other captures, rank agreement —
come from ``python scripts/benchmarks.py run search``). Table 2.1: ms per query for ``--ks`` neighbours (16, 256),
every feature set, exact engines (``ckdtree``, ``pykdtree``, ``faiss`` flat, when installed) single (one query per
call) and batched (all queries in one call), the brute-force time of the same queries in the same run as the ratio's
base, and ``faiss-hnsw`` / ``faiss-ivf`` (approximate) with their recall against the exact neighbours. The suite
``engines`` (``python scripts/benchmarks.py run engines``) measures the engines per feature set for
``engine=auto``'s rule. Database sizes: ``--copies`` copies of the dataset: copy 0 is the data, copy 1 its mirror
image (left and right swapped, x negated), copy c ≥ 2 copy ``c mod 2`` with every joint displaced by seeded Gaussian
noise (σ ``--jitter`` m) — rotated copies would not do: the features are invariant under rotation, so they would
duplicate frames. Query frames (``--queries``): ``heldout`` (default) random frames of the test takes, the database
built from the train and val takes; ``jitter`` random database frames of copy 0 with the same jitter.

Everything runs on this process' threads (``--workers`` for cKDTree and faiss); the machine's load is recorded.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from stylemotion.datasets import TakeSet, load_dataset
from stylemotion.datasets.base import Take
from stylemotion.search import APPROXIMATE_ENGINES, ENGINES, FrameIndex, MotionDatabase, feature_names, feature_spec
from stylemotion.skeleton import CANONICAL_MIRROR

PARTS = ("table21",)
Emit = Callable[[dict[str, Any]], None]


def available_engines() -> list[str]:
    import importlib.util

    have = {"ckdtree": True, "pykdtree": importlib.util.find_spec("pykdtree") is not None,
            "faiss": importlib.util.find_spec("faiss") is not None}
    have["faiss-hnsw"] = have["faiss-ivf"] = have["faiss"]
    return [e for e in ENGINES if have.get(e, False)]


def load(args: argparse.Namespace) -> TakeSet:
    """The dataset to measure on (all of Bandai, or the synthetic one)."""
    if args.data == "synthetic":
        return load_dataset("synthetic", takes_per_pair=args.takes_per_pair, duration_s=args.duration_s)
    root = args.root or os.path.join(os.environ.get("STYLEMOTION_DATA", "../shared/data"), "bandai-namco-motion-2",
                                     "data.zip")
    return load_dataset("bandai", root=root, workers=args.workers)


def mirrored(positions: np.ndarray) -> np.ndarray:
    """``(frames, 21, 3)`` the mirror image: left and right joints swapped, x negated."""
    out = positions[:, list(CANONICAL_MIRROR)].copy()
    out[..., 0] *= -1
    return out


def copies_of(takeset: TakeSet, copies: int, jitter: float, seed: int) -> TakeSet:
    """``copies`` copies of every take (see the module docstring), as one TakeSet."""
    rng = np.random.default_rng(seed)
    takes: list[Take] = []
    for c in range(copies):
        for t in takeset.takes:
            positions = t.positions if c % 2 == 0 else mirrored(np.asarray(t.positions))
            if c >= 2:
                positions = positions + rng.normal(0.0, jitter, positions.shape).astype(np.float32)
            takes.append(Take(f"{t.name}#copy{c}", np.asarray(positions, dtype=np.float32), t.fps, dict(t.labels)))
    return TakeSet(f"{takeset.name}x{copies}", takes, takeset.fps)


def brute_force(data: np.ndarray, queries: np.ndarray, k: int, chunk: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Exact k-NN by computing every distance (float32 matrix products, chunked): ``(m, k)`` distances, indices."""
    norms = np.einsum("ij,ij->i", data, data)
    out_d, out_i = np.empty((len(queries), k)), np.empty((len(queries), k), dtype=np.int64)
    for lo in range(0, len(queries), chunk):
        q = queries[lo:lo + chunk]
        sq = norms[None, :] - 2.0 * (q @ data.T) + np.einsum("ij,ij->i", q, q)[:, None]
        part = np.argpartition(sq, k - 1, axis=1)[:, :k]
        d = np.take_along_axis(sq, part, axis=1)
        order = np.argsort(d, axis=1)
        out_i[lo:lo + chunk] = np.take_along_axis(part, order, axis=1)
        out_d[lo:lo + chunk] = np.sqrt(np.maximum(np.take_along_axis(d, order, axis=1), 0.0))
    return out_d, out_i


def timed(fn: Callable[..., Any], *args: Any, **kwargs: Any) -> tuple[float, Any]:
    """Seconds of ``fn(*args, **kwargs)`` and its value."""
    t0 = time.perf_counter()
    value = fn(*args, **kwargs)
    return time.perf_counter() - t0, value


def table21(takeset: TakeSet, args: argparse.Namespace, emit: Emit) -> None:
    """Table 2.1 rows. ``--queries heldout`` (default): the database is the train and val takes (and their copies),
    the queries random frames of the test takes — motions the database does not hold, as a user's query is.
    ``--queries jitter``: the database is every take, the queries random database frames with every joint
    displaced by N(0, jitter) — farther from the data than a real motion and hard for kd-trees."""
    engines = [e for e in args.engines if e in available_engines()]
    rng = np.random.default_rng(args.seed)
    split = _split(takeset, args)
    held_out = args.queries == "heldout"
    base = TakeSet(takeset.name, split["train"] + split["val"], takeset.fps) if held_out else takeset
    for copies in args.copies:
        database = MotionDatabase.from_takeset(copies_of(base, copies, args.jitter, args.seed))
        if held_out:
            test_frames = [(t, f) for t in split["test"] for f in range(t.num_frames)]
            n_test = len(test_frames)
            chosen = rng.choice(n_test, size=args.table_queries, replace=n_test < args.table_queries)
            picks, query_positions = np.array([], dtype=np.int64), None
            held = [test_frames[c] for c in chosen]
        else:
            held = []
            picks = rng.choice(base.num_frames, size=args.table_queries, replace=base.num_frames < args.table_queries)
            query_positions = database.positions[picks] + rng.normal(0, args.jitter, (len(picks), 21, 3))
        for fs in args.features:
            features, fitted, queries = None, None, None
            brute: dict[int, tuple[float, np.ndarray, np.ndarray]] = {}
            for engine in engines:
                built_s, index = timed(FrameIndex, database, fs, features, fitted, engine=engine,
                                       workers=args.workers)
                features, fitted = index.features, index.fitted
                if queries is None:
                    queries = (_held_out_features(index, held) if held_out
                               else _query_features(index, database, picks, query_positions))
                for k in (k for k in args.ks if k <= index.size):
                    emit(_table_row(takeset, args, database, index, queries, brute, copies, k, built_s))


def _held_out_features(index: FrameIndex, frames: list[tuple[Take, int]]) -> np.ndarray:
    """Features of the chosen frames of test takes, each computed within its own take."""
    per_take: dict[str, np.ndarray] = {}
    for take, _ in frames:
        if take.name not in per_take:
            per_take[take.name] = index.features_of(np.asarray(take.positions))
    return np.stack([per_take[take.name][f] for take, f in frames]).astype(np.float32)


def _table_row(takeset: TakeSet, args: argparse.Namespace, database: MotionDatabase, index: FrameIndex,
               queries: np.ndarray, brute: dict[int, tuple[float, np.ndarray, np.ndarray]], copies: int, k: int,
               built_s: float) -> dict[str, Any]:
    """One Table 2.1 row: an engine's batched and single query times for ``k``, against brute force."""
    brute_q = queries[:args.brute_queries]
    if k not in brute:
        seconds, (bd, bi) = timed(brute_force, index.features, brute_q, k)
        brute[k] = (1000 * seconds / len(brute_q), bd, bi)
    brute_ms, bd, bi = brute[k]
    batch_s, (d, i) = timed(index.query, queries, k)
    single_q = queries[:args.single_queries]
    single_s, _ = timed(lambda: [index.query(q, k) for q in single_q])  # noqa: B023 - called at once
    batched_ms = 1000 * batch_s / len(queries)
    row = {"part": "table21", "dataset": takeset.name, "copies": copies, "frames": database.num_frames,
           "database_construction": "copy 0 the data, 1 its mirror, c>=2 copy c%2 + N(0, jitter) per joint",
           "queries": ("random frames of the test takes; database = train + val takes" if args.queries == "heldout"
                       else "random database frames + N(0, jitter) per joint; database = every take"),
           "jitter_m": args.jitter, "features": index.feature_set, "dim": index.dim, "engine": index.engine,
           "exact": index.engine not in APPROXIMATE_ENGINES, "k": k, "build_s": round(built_s, 3),
           "workers": args.workers,
           "batched_queries": len(queries), "single_queries": len(single_q),
           "ms_per_query_batched": round(batched_ms, 5),
           "ms_per_query_single": round(1000 * single_s / len(single_q), 5),
           "brute_queries": len(brute_q), "brute_ms_per_query": round(brute_ms, 5),
           "speedup_batched_vs_brute": round(brute_ms / max(batched_ms, 1e-12), 2),
           "krueger_ms_per_query": {"E15": {16: 1.11, 256: 4.53}}.get(index.feature_set, {}).get(k)}
    if index.engine in APPROXIMATE_ENGINES:
        row["recall"] = round(float(np.mean([len(set(a) & set(b)) / k for a, b in zip(i[:len(brute_q)], bi)])), 5)
    else:
        row["max_abs_distance_error_vs_brute"] = float(np.abs(d[:len(brute_q)] - bd).max())
    return row


def _query_features(index: FrameIndex, database: MotionDatabase, picks: np.ndarray,
                    query_positions: np.ndarray) -> np.ndarray:
    """Features of the jittered query frames: each frame replaces its database frame inside its take (the
    windowed and physics sets need the frames around it)."""
    out = np.empty((len(picks), index.dim), dtype=np.float32)
    window = feature_spec(index.feature_set).window_frames(database.fps)
    for n, (g, pose) in enumerate(zip(picks, query_positions)):
        take = int(database.take_id[g])
        first, last = int(database.take_start[take]), int(database.take_start[take + 1])
        lo, hi = max(first, int(g) - window - 2), min(last, int(g) + 3)  # physics terms read neighbouring frames
        clip = np.array(database.positions[lo:hi], dtype=np.float64)
        clip[int(g) - lo] = pose
        out[n] = index.features_of(clip)[int(g) - lo] if len(clip) >= window else index.features[g]
    return out


def _split(takeset: TakeSet, args: argparse.Namespace) -> dict[str, list[Take]]:
    return takeset.split(seed=args.split_seed, val_fraction=args.val_fraction, test_fraction=args.test_fraction)


def parse(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", choices=("bandai", "synthetic"), default="bandai")
    parser.add_argument("--root", default=None, help="Bandai folder or data.zip (default: $STYLEMOTION_DATA/...)")
    parser.add_argument("--parts", default=",".join(PARTS), help=f"comma-separated subset of {','.join(PARTS)}")
    parser.add_argument("--features", default=",".join(feature_names()), help="feature sets")
    parser.add_argument("--engines", default=",".join(e for e in ENGINES if e != "auto"))
    parser.add_argument("--ks", default="16,256", help="neighbours per query")
    parser.add_argument("--copies", default="1,2,3", help="database sizes as copies of the data")
    parser.add_argument("--jitter", type=float, default=0.01, help="σ of the copies' and queries' joint noise, m")
    parser.add_argument("--queries", choices=("heldout", "jitter"), default="heldout",
                        help="table21 queries: test-take frames (database: train + val) or jittered database frames")
    parser.add_argument("--table-queries", type=int, default=2000)
    parser.add_argument("--single-queries", type=int, default=200)
    parser.add_argument("--brute-queries", type=int, default=200)
    parser.add_argument("--workers", type=int, default=1, help="threads of cKDTree/faiss (-1: all cores)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--split-seed", type=int, default=0)
    parser.add_argument("--val-fraction", type=float, default=0.1)
    parser.add_argument("--test-fraction", type=float, default=0.1)
    parser.add_argument("--takes-per-pair", type=int, default=6, help="synthetic data only")
    parser.add_argument("--duration-s", type=float, default=8.0, help="synthetic data only")
    parser.add_argument("--smoke", action="store_true", help="tiny synthetic run: every part in seconds")
    parser.add_argument("--out", default=None, help="also append the JSON lines to this file")
    args = parser.parse_args(argv)
    if args.smoke:
        args.data, args.takes_per_pair, args.duration_s = "synthetic", 3, 4.0
        args.features, args.ks, args.copies = "E15,E15x3,pca8,EP17", "4,16", "1,2,3"
        args.table_queries, args.single_queries, args.brute_queries = 40, 10, 20
    args.parts = [p for p in args.parts.split(",") if p]
    unknown = sorted(set(args.parts) - set(PARTS))
    if unknown:
        parser.error(f"--parts: unknown {unknown}; valid: {list(PARTS)}")
    for key in ("features", "engines"):
        setattr(args, key, [v for v in getattr(args, key).split(",") if v])
    args.ks = [int(v) for v in args.ks.split(",")]
    args.copies = [int(v) for v in args.copies.split(",")]
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse(argv)
    sink = open(args.out, "a") if args.out else None  # noqa: SIM115 - closed below

    def emit(row: dict[str, Any]) -> None:
        line = json.dumps({**row, "load_avg_1m": round(os.getloadavg()[0], 2)})
        print(line, flush=True)
        if sink is not None:
            sink.write(line + "\n")
            sink.flush()

    try:
        started = time.perf_counter()
        takeset = load(args)
        emit({"part": "setup", "dataset": takeset.name, "takes": len(takeset.takes), "frames": takeset.num_frames,
              "fps": takeset.fps, "parts": args.parts, "engines_available": available_engines(),
              "machine": platform.machine(), "cpus": os.cpu_count(), "python": platform.python_version(),
              "workers": args.workers, "argv": sys.argv[1:]})
        if "table21" in args.parts:
            table21(takeset, args, emit)
        emit({"part": "done", "seconds": round(time.perf_counter() - started, 2)})
    finally:
        if sink is not None:
            sink.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
