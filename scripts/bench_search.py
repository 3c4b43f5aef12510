"""Motion-database search benchmark (issue 13, Krüger ch. 2): one JSON object per line.

    python scripts/bench_search.py --out bench_search.jsonl                 # everything, on all of Bandai
    python scripts/bench_search.py --parts table21 --features E15 --copies 1,2,3
    python scripts/bench_search.py --smoke --out /tmp/smoke.jsonl            # tiny synthetic run (seconds)

Parts (``--parts``, comma-separated):

* ``table21`` — Table 2.1: ms per query for ``--ks`` neighbours (16, 256), every feature set, exact engines
  (``ckdtree``, ``pykdtree``, ``faiss`` flat, when installed) single (one query per call) and batched (all
  queries in one call), the brute-force time of the same queries in the same run as the ratio's base, and
  ``faiss-hnsw`` (approximate) with its recall against the exact neighbours. Database sizes: ``--copies``
  copies of the dataset: copy 0 is the data, copy 1 its mirror image (left and right swapped, x negated),
  copy c ≥ 2 copy ``c mod 2`` with every joint displaced by seeded Gaussian noise (σ ``--jitter`` m) —
  rotated copies would not do: the features are invariant under rotation, so they would duplicate frames.
  Query frames (``--queries``): ``heldout`` (default) random frames of the test takes, the database built from
  the train and val takes; ``jitter`` random database frames of copy 0 with the same jitter (so none is in the
  database; farther from the data than a real motion, which makes kd-trees visit many more cells).
* ``lng`` — LNG vs subsequence DTW: ``--lng-queries`` random 1 s and as many 3 s queries cut from test takes
  (``TakeSet.split`` with the data config's split) against the train takes; Spearman ρ between the LNG's and
  DTW's best global costs, the share of queries where both return the same best segment (same take and
  frames) and where the segments overlap, and the alignment time per query without the k-NN search.
* ``rank`` — rank correlations between feature sets (Fig. 2.5/2.7): for ``--rank-frames`` random frames, the
  ``--rank-k`` nearest frames under set A; Spearman ρ between their distances under A and under B, averaged.
* ``retrieval`` — Table 2.2 in spirit: a ``--retrieval-seconds`` segment from the middle of every test take as
  query against the train and val takes; precision of the top 10 and 50 matches by content per content and
  feature set (E15, E15x3, EP17 by default); and how often walk-turn-left queries return walk-turn-right
  matches and vice versa (the physics sets should confuse them less, §2.6.2).

Everything runs on this process' threads (``--workers`` for cKDTree and faiss); the machine's load is recorded.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np
from scipy.stats import spearmanr

from stylemotion.datasets import TakeSet, load_dataset
from stylemotion.datasets.base import Take
from stylemotion.search import ENGINES, FrameIndex, MotionDatabase, feature_names, feature_spec, search_features
from stylemotion.search.dtw import subsequence_dtw_features
from stylemotion.search.lng import TakeBounds, lng_match
from stylemotion.skeleton import CANONICAL_MIRROR

PARTS = ("table21", "lng", "rank", "retrieval")
Emit = Callable[[dict[str, Any]], None]


def available_engines() -> list[str]:
    import importlib.util

    have = {"ckdtree": True, "pykdtree": importlib.util.find_spec("pykdtree") is not None,
            "faiss": importlib.util.find_spec("faiss") is not None}
    have["faiss-hnsw"] = have["faiss"]
    return [e for e in ENGINES if have[e]]


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
           "exact": index.engine != "faiss-hnsw", "k": k, "build_s": round(built_s, 3), "workers": args.workers,
           "batched_queries": len(queries), "single_queries": len(single_q),
           "ms_per_query_batched": round(batched_ms, 5),
           "ms_per_query_single": round(1000 * single_s / len(single_q), 5),
           "brute_queries": len(brute_q), "brute_ms_per_query": round(brute_ms, 5),
           "speedup_batched_vs_brute": round(brute_ms / max(batched_ms, 1e-12), 2),
           "krueger_ms_per_query": {"E15": {16: 1.11, 256: 4.53}}.get(index.feature_set, {}).get(k)}
    if index.engine == "faiss-hnsw":
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


def _random_queries(takes: list[Take], frames: int, count: int, rng: np.random.Generator) -> list[tuple[Take, int]]:
    usable = [t for t in takes if t.num_frames >= frames]
    if not usable:
        return []
    picks = rng.integers(0, len(usable), count)
    return [(usable[p], int(rng.integers(0, usable[p].num_frames - frames + 1))) for p in picks]


def lng_vs_dtw(takeset: TakeSet, args: argparse.Namespace, emit: Emit) -> None:
    split = _split(takeset, args)
    database = MotionDatabase.from_takeset(TakeSet(f"{takeset.name}-train", split["train"], takeset.fps))
    bounds = TakeBounds.from_next_in_take(database.next_in_take, database.take_id)
    rng = np.random.default_rng(args.seed)
    for fs in args.lng_features:
        index = FrameIndex(database, fs, workers=args.workers)
        for seconds in (1.0, 3.0):
            m = int(round(seconds * takeset.fps))
            lng_costs, dtw_costs, same, overlap, no_path, align_ms, knn_ms = [], [], 0, 0, 0, [], []
            for take, start in _random_queries(split["test"], m, args.lng_queries, rng):
                features = index.features_of(take.positions[start:start + m])
                knn_s, (d, i) = timed(index.query, features, args.lng_k)
                lng_s, found = timed(lng_match, i, d, bounds, top=1)
                reference = subsequence_dtw_features(features, index.features, bounds).best
                knn_ms.append(1000 * knn_s)
                align_ms.append(1000 * lng_s)
                if not found:
                    no_path += 1
                    continue
                best = found[0]
                lng_costs.append(best.cost)
                dtw_costs.append(reference.cost)
                same += (best.start, best.end) == (reference.start, reference.end)
                overlap += best.take == reference.take and best.start <= reference.end and reference.start <= best.end
            done = len(lng_costs)
            rho = float(spearmanr(lng_costs, dtw_costs).statistic) if done >= 3 else None
            emit({"part": "lng", "dataset": takeset.name, "features": fs, "k": args.lng_k, "query_s": seconds,
                  "query_frames": m, "queries": done + no_path, "no_path": no_path, "train_takes": database.num_takes,
                  "train_frames": database.num_frames, "spearman_rho": rho,
                  "same_best_segment": round(same / done, 4) if done else None,
                  "overlapping_best_segment": round(overlap / done, 4) if done else None,
                  "lng_cost_ge_dtw": bool(np.all(np.array(lng_costs) >= np.array(dtw_costs) - 1e-9)) if done else None,
                  "align_ms_per_query": round(float(np.mean(align_ms)), 4) if align_ms else None,
                  "knn_ms_per_query": round(float(np.mean(knn_ms)), 4) if knn_ms else None})


def rank_correlations(takeset: TakeSet, args: argparse.Namespace, emit: Emit) -> None:
    database = MotionDatabase.from_takeset(takeset)
    rng = np.random.default_rng(args.seed)
    frames = rng.choice(database.num_frames, size=min(args.rank_frames, database.num_frames), replace=False)
    k = min(args.rank_k, database.num_frames)
    indexes = {fs: FrameIndex(database, fs, workers=args.workers) for fs in args.features}
    for a, ia in indexes.items():
        _, near = ia.query(ia.features[frames], k)
        for b, ib in indexes.items():
            dist_b = np.linalg.norm(ib.features[near] - ib.features[frames][:, None, :], axis=-1)
            dist_a = np.linalg.norm(ia.features[near] - ia.features[frames][:, None, :], axis=-1)
            rhos = [spearmanr(x, y).statistic for x, y in zip(dist_a, dist_b)]
            emit({"part": "rank", "dataset": takeset.name, "a": a, "b": b, "frames": len(frames), "k": k,
                  "mean_spearman_rho": round(float(np.nanmean(rhos)), 4)})


def retrieval(takeset: TakeSet, args: argparse.Namespace, emit: Emit) -> None:
    split = _split(takeset, args)
    database = MotionDatabase.from_takeset(TakeSet(f"{takeset.name}-train+val", split["train"] + split["val"],
                                                   takeset.fps))
    m = int(round(args.retrieval_seconds * takeset.fps))
    queries = [t for t in split["test"] if t.num_frames >= m]
    for fs in args.retrieval_features:
        index = FrameIndex(database, fs, workers=args.workers)
        per_content: dict[str, list[tuple[float | None, float | None, int]]] = {}
        turns = {"walk-turn-left": [0, 0], "walk-turn-right": [0, 0]}  # [opposite-turn matches, all matches]
        for take in queries:
            start = (take.num_frames - m) // 2
            found = search_features(index.features_of(take.positions[start:start + m]), index, args.lng_k, 50).matches
            contents = [f.content for f in found]
            p10 = _precision(contents[:10], take.content)
            p50 = _precision(contents[:50], take.content)
            per_content.setdefault(take.content, []).append((p10, p50, len(found)))
            if take.content in turns:
                other = "walk-turn-right" if take.content == "walk-turn-left" else "walk-turn-left"
                turns[take.content][0] += contents.count(other)
                turns[take.content][1] += len(contents)
        for content, rows in sorted(per_content.items()):
            emit({"part": "retrieval", "dataset": takeset.name, "features": fs, "k": args.lng_k, "content": content,
                  "query_s": args.retrieval_seconds, "queries": len(rows),
                  "precision_at_10": _mean(r[0] for r in rows), "precision_at_50": _mean(r[1] for r in rows),
                  "mean_matches_returned": round(float(np.mean([r[2] for r in rows])), 2)})
        emit({"part": "retrieval_turns", "dataset": takeset.name, "features": fs, "k": args.lng_k,
              **{f"{c}_share_opposite_turn": round(n / total, 4) if total else None for c, (n, total) in turns.items()},
              **{f"{c}_matches": total for c, (_, total) in turns.items()}})


def _precision(contents: list[str], wanted: str) -> float | None:
    return sum(c == wanted for c in contents) / len(contents) if contents else None


def _mean(values: Iterable[float | None]) -> float | None:
    kept = [v for v in values if v is not None]
    return round(float(np.mean(kept)), 4) if kept else None


def parse(argv: list[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", choices=("bandai", "synthetic"), default="bandai")
    parser.add_argument("--root", default=None, help="Bandai folder or data.zip (default: $STYLEMOTION_DATA/...)")
    parser.add_argument("--parts", default=",".join(PARTS), help=f"comma-separated subset of {','.join(PARTS)}")
    parser.add_argument("--features", default=",".join(feature_names()), help="feature sets (table21, rank)")
    parser.add_argument("--engines", default=",".join(ENGINES))
    parser.add_argument("--ks", default="16,256", help="neighbours per query (table21)")
    parser.add_argument("--copies", default="1,2,3", help="database sizes as copies of the data (table21)")
    parser.add_argument("--jitter", type=float, default=0.01, help="σ of the copies' and queries' joint noise, m")
    parser.add_argument("--queries", choices=("heldout", "jitter"), default="heldout",
                        help="table21 queries: test-take frames (database: train + val) or jittered database frames")
    parser.add_argument("--table-queries", type=int, default=2000)
    parser.add_argument("--single-queries", type=int, default=200)
    parser.add_argument("--brute-queries", type=int, default=200)
    parser.add_argument("--lng-features", default="E15,E15x3,pca16")
    parser.add_argument("--lng-queries", type=int, default=128, help="per query length (1 s and 3 s)")
    parser.add_argument("--lng-k", type=int, default=256, help="neighbours per query frame (lng, retrieval)")
    parser.add_argument("--rank-frames", type=int, default=1024)
    parser.add_argument("--rank-k", type=int, default=512)
    parser.add_argument("--retrieval-features", default="E15,E15x3,EP17")
    parser.add_argument("--retrieval-seconds", type=float, default=2.0)
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
        args.lng_queries, args.lng_k, args.rank_frames, args.rank_k = 4, 64, 32, 16
        args.lng_features, args.retrieval_seconds = "E15", 1.0
    args.parts = [p for p in args.parts.split(",") if p]
    unknown = sorted(set(args.parts) - set(PARTS))
    if unknown:
        parser.error(f"--parts: unknown {unknown}; valid: {list(PARTS)}")
    for key in ("features", "engines", "lng_features", "retrieval_features"):
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
        for part, run in (("table21", table21), ("lng", lng_vs_dtw), ("rank", rank_correlations),
                          ("retrieval", retrieval)):
            if part in args.parts:
                run(takeset, args, emit)
        emit({"part": "done", "seconds": round(time.perf_counter() - started, 2)})
    finally:
        if sink is not None:
            sink.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
