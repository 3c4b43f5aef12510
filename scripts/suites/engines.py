"""Suite ``engines``: the k-NN engines of :class:`stylemotion.search.FrameIndex` per feature set — measured ALONE.

1. **Table.** The database is Bandai's ``train`` + ``val`` takes (the data config's split: every take but the
   ~10 % held out); the queries are seeded random clips of consecutive frames of the held-out ``test`` takes
   (motions the database does not hold, as a user's query is). Per feature set and engine: build time, memory
   (the process' resident set before and after the build), and 16-NN query time in ms per query frame — one
   call per clip ("batched", as ``stylemotion-search`` asks for a query's frames) and one call per frame
   ("single") — median and p95 over the clips / frames, at 1 thread and at the machine's default thread count.
   The engines are timed back to back: per clip (per frame) every engine in turn, the order rotated, so a
   change of load touches them all alike; compare them as ratios within one run.
0. **Validation** (the choices). A database of the ``train`` takes only, queried with seeded clips of the ``val``
   takes: per feature set, cKDTree and ``ckdtree-pca`` under each of :data:`FETCH_CANDIDATES` (its multi-step
   rounds), back to back, batched, 1 thread. Chosen: the rounds with the least geometric mean of the mean ms per
   query over the sets, then the ``auto`` rule (:func:`implied_rule` on those means) — against the library's
   :data:`stylemotion.search.index.FILTER_FETCH` and :data:`stylemotion.search.index.AUTO_ENGINES`.
2. **Check on test.** The rule "one engine up to D dimensions, another above" closest to each set's fastest exact
   engine on the test clips (geometric mean of the ratios of medians, batched, 1 thread), beside the library's
   rule, which the validation phase chose.
3. **Approximate.** HNSW and IVF at several search breadths (``efSearch``, ``nprobe``): recall@16 against
   the exact neighbours (a returned frame counts when it lies within the exact 16th distance, so ties cannot
   cost recall) and batched time over ``auto``'s, timed back to back.
4. **Scale.** ``--scale-frames`` (default 5 M) frames as copies of the ``train`` + ``val`` takes
   (``scripts/bench_search.py``'s ``copies_of``: copy 1 mirrored, copies ≥ 2 with every joint displaced by
   N(0, ``--jitter``²)); per engine, one at a time: features, build time, memory, query time, recall.

``--quick`` is a smoke run (a few hundred takes, a few clips, 50k scale frames): its figures are no
measurement, and the render says so.
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import time
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager, nullcontext
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, md_table, provenance_line, quantiles, take_split_record

from stylemotion.search.index import FLOAT64_ENGINES

DESCRIPTION = ("k-NN engines per feature set on Bandai: build, memory, 16-NN ms per query (1 thread / all cores), "
               "approximate recall, ≥ 5 M-frame scale run (run alone)")
DEFAULT_SEEDS = (0,)
#: Engines measured (``auto`` is one of the exact ones, marked in the tables).
MEASURED_ENGINES = ("ckdtree", "ckdtree-pca", "pykdtree", "faiss", "faiss-hnsw", "faiss-ivf")
#: Engines that take their thread count at construction (scipy's ``workers``): built twice, once per count.
SCIPY_ENGINES = ("ckdtree", "ckdtree-pca")
#: The exact engines among :data:`MEASURED_ENGINES`.
EXACT_ENGINES_MEASURED = ("ckdtree", "ckdtree-pca", "pykdtree", "faiss")
#: Aims of issue 29: every set's 16-NN with the default engine, and the approximate engines' recall.
AIM_MS = 0.5
AIM_RECALL = 0.99
THREADS = ("1", "all")
#: ``(first, growth, last)`` rounds of ``ckdtree-pca``'s multi-step search the validation phase compares
#: (:data:`stylemotion.search.index.FILTER_FETCH`); ``(1, 2, 1)`` is one round and then the ball query, the
#: engine as it was before the rounds.
FETCH_CANDIDATES = ((1, 2, 1), (4, 4, 256), (8, 2, 128), (8, 4, 128), (16, 4, 64))


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--data", choices=("bandai", "synthetic"), default="bandai")
    parser.add_argument("--features", nargs="+", default=None, help="feature sets (default: all)")
    parser.add_argument("--engines", nargs="+", default=list(MEASURED_ENGINES), choices=MEASURED_ENGINES)
    parser.add_argument("--k", type=int, default=16, help="neighbours per query frame")
    parser.add_argument("--clips", type=int, default=16, help="query clips per seed")
    parser.add_argument("--clip-frames", type=int, default=64, help="consecutive frames per query clip")
    parser.add_argument("--single-per-clip", type=int, default=16, help="frames of each clip also queried alone")
    parser.add_argument("--hnsw-breadths", type=int, nargs="+", default=[16, 32, 64, 128, 256], help="efSearch")
    parser.add_argument("--ivf-breadths", type=int, nargs="+", default=[8, 16, 32, 64, 128], help="nprobe")
    parser.add_argument("--scale-frames", type=int, default=5_000_000, help="scale run's frames (0: skip it)")
    parser.add_argument("--scale-features", nargs="+", default=["E15", "E15x5"])
    parser.add_argument("--scale-engines", nargs="+", default=["ckdtree", "ckdtree-pca", "pykdtree", "faiss",
                                                                "faiss-ivf"],
                        choices=MEASURED_ENGINES, help="(faiss-hnsw: its graph over 5 M frames takes long)")
    parser.add_argument("--scale-clips", type=int, default=4, help="query clips per seed of the scale run")
    parser.add_argument("--scale-single", type=int, default=32, help="frames queried alone in the scale run")
    parser.add_argument("--jitter", type=float, default=0.01, help="σ of the scale copies' joint noise, m")
    parser.add_argument("--validation-clips", type=int, default=32,
                        help="query clips per seed of the validation phase (val takes against the train takes)")
    parser.add_argument("--quick", action="store_true", help="smoke run: small database, few clips (no measurement)")


def _quick(args: argparse.Namespace) -> None:
    """Shrink every count for a smoke run (the render labels its figures as no measurement)."""
    args.features = args.features or ["E15", "E15x5", "pca8"]
    args.clips, args.clip_frames, args.single_per_clip, args.validation_clips = 2, 32, 4, 2
    args.hnsw_breadths, args.ivf_breadths = [16, 64], [4, 32]
    args.scale_frames = min(args.scale_frames, 50_000)
    args.scale_features, args.scale_clips, args.scale_single = ["E15"], 1, 4
    args.scale_engines = [e for e in args.scale_engines if e != "pykdtree"]


# ---------------------------------------------------------------------------------------------
# Helpers (tested on their own)


def recall_at(returned_d: np.ndarray, exact_kth: np.ndarray, rtol: float = 1e-5) -> float:
    """Recall@k of approximate results: the share of returned frames whose true distance ``returned_d`` ``(m, k)``
    (float64, feature units; ``inf`` for a missing one) is within the exact k-th distance ``exact_kth`` ``(m,)``
    (up to ``rtol``). A frame tied with the true k-th counts, so ties cannot cost recall."""
    return float(np.mean(returned_d <= exact_kth[:, None] * (1.0 + rtol) + 1e-12))


def true_distances(features: np.ndarray, queries: np.ndarray, indices: np.ndarray) -> np.ndarray:
    """Float64 distances ``(m, k)`` from each query ``(m, d)`` to the frames ``indices`` ``(m, k)`` (−1: inf)."""
    rows = np.clip(indices, 0, len(features) - 1)
    d = np.linalg.norm(features[rows].astype(np.float64) - queries[:, None, :].astype(np.float64), axis=-1)
    return np.where(indices < 0, np.inf, d)


def implied_rule(dims: Sequence[int], ms: Sequence[dict[str, float]],
                 candidates: Sequence[str] = FLOAT64_ENGINES) -> dict[str, Any]:
    """The ``auto`` rule "engine ``low`` up to ``limit`` dimensions, ``high`` above" (``low``, ``high`` among
    ``candidates``, by default the float64 exact engines ``auto`` may pick) closest to the fastest exact engine of
    every set: per candidate rule (``limit`` ∈ {0} ∪ dims ∪ {∞}) the geometric mean over sets of its engine's time
    over the set's fastest measured exact engine; the smallest wins (ties: the larger limit, then the earlier
    candidates). ``ms[i]``: exact engine → ms per query of set ``i`` (dimension ``dims[i]``).

    Returns ``{"limit": int | None, "low": str, "high": str, "geomean": float, "per_set": [engine…]}``; a rule
    naming one engine for every set has ``limit`` None and ``low == high``.
    """
    def score(chosen: list[str]) -> float:
        if any(e not in times for e, times in zip(chosen, ms)):
            return math.inf
        logs = [math.log(times[e] / min(times.values())) for e, times in zip(chosen, ms)]
        return math.exp(sum(logs) / len(logs))

    ranked = []
    for li, low in enumerate(candidates):
        for hi, high in enumerate(candidates):
            for limit in sorted({0, *dims, math.inf}, reverse=True):
                chosen = [low if d <= limit else high for d in dims]
                ranked.append((score(chosen), -limit, li, hi, limit, low, high, chosen))
    value, _, _, _, limit, low, high, chosen = min(ranked, key=lambda c: c[:4])
    if len(set(chosen)) == 1:
        limit, low = math.inf, chosen[0]
        high = low
    return {"limit": None if math.isinf(limit) else int(limit), "low": low, "high": high, "geomean": value,
            "per_set": chosen}


def fetch_label(fetch: Sequence[int]) -> str:
    """``"first/growth/last"`` of one set of multi-step rounds."""
    return "/".join(str(int(v)) for v in fetch)


def choose_fetch(dims: Sequence[int], kd: Sequence[float],
                 pca: Sequence[dict[str, float]]) -> tuple[str, dict[str, Any]]:
    """The rounds and ``auto`` rule chosen together: per rounds label, the rule :func:`implied_rule` reads off
    cKDTree's times ``kd[i]`` and ``ckdtree-pca``'s under those rounds ``pca[i][label]`` (ms per query of set ``i``);
    the label whose rule has the least geometric mean of the chosen engines' times wins (ties: the earlier label).
    Returns ``(label, rule)``."""
    best: tuple[float, int, str, dict[str, Any]] | None = None
    for i, label in enumerate(pca[0]):
        times = [{"ckdtree": t, "ckdtree-pca": p[label]} for t, p in zip(kd, pca)]
        rule = implied_rule(dims, times, candidates=("ckdtree", "ckdtree-pca"))
        cost = math.fsum(math.log(t[e]) for t, e in zip(times, rule["per_set"])) / len(times)
        if best is None or (cost, i) < best[:2]:
            best = (cost, i, label, rule)
    assert best is not None
    return best[2], best[3]


def library_rule_engines(dims: Sequence[int]) -> list[str]:
    """The engine the library's :data:`AUTO_ENGINES` names for each dimension (installed or not)."""
    from stylemotion.search.index import AUTO_ENGINES

    return [next(engine for limit, engine in AUTO_ENGINES if d <= limit) for d in dims]


def rss_mb(trim: bool = False) -> float:
    """This process' resident set, MB; ``trim``: first collect garbage and hand freed heap memory back to the OS
    (glibc's ``malloc_trim``, where there is one), so that a later difference counts what was added since."""
    import psutil

    if trim:
        gc.collect()
        try:
            import ctypes

            ctypes.CDLL("libc.so.6").malloc_trim(0)
        except (OSError, AttributeError):  # not glibc: the difference may then miss reused memory
            pass
    return psutil.Process().memory_info().rss / 2**20


def thread_limit(threads: str) -> AbstractContextManager:
    """``"1"``: OpenMP and BLAS held to one thread (faiss, pykdtree, numpy); ``"all"``: their defaults."""
    if threads == "all":
        return nullcontext()
    from threadpoolctl import threadpool_limits

    return threadpool_limits(limits=1)


def timed_ms(fn: Callable[[], Any]) -> float:
    """Milliseconds one call of ``fn`` takes."""
    t0 = time.perf_counter()
    fn()
    return 1000.0 * (time.perf_counter() - t0)


def rotated(items: Sequence[Any], shift: int) -> list[Any]:
    """``items`` started at ``shift`` (mod its length): who runs first changes from call to call."""
    n = len(items)
    return [items[(shift + i) % n] for i in range(n)]


def _stats(values: Sequence[float]) -> dict[str, float | None]:
    q = quantiles(values, (50, 95))
    return {"p50": q["p50"], "p95": q["p95"], "mean": float(np.mean(values)) if len(values) else None,
            "n": len(values)}


# ---------------------------------------------------------------------------------------------
# Data


def _load(args: argparse.Namespace) -> Any:
    from stylemotion.datasets import load_dataset

    if args.data == "synthetic":
        return load_dataset("synthetic", takes_per_pair=3 if args.quick else 6)
    return load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"), workers=2)


def _split(takeset: Any, args: argparse.Namespace) -> tuple[dict[str, Any], dict[str, Any]]:
    from suites.common import bandai_split_settings

    settings = bandai_split_settings() if args.data == "bandai" else {"seed": 0, "val_fraction": 0.1,
                                                                      "test_fraction": 0.1}
    split = takeset.split(**settings)
    if args.quick and args.data == "bandai":  # a smoke run's database: every 8th train/val take, 4th test take
        split = {"train": split["train"][::8], "val": split["val"][::8], "test": split["test"][::4]}
    return split, settings


def choose_clips(test_takes: Sequence[Any], clips: int, frames: int, seeds: Sequence[int]) -> list[tuple[int, int]]:
    """``(take, start)`` of ``clips`` random clips of ``frames`` consecutive frames per seed, every start frame of
    every long enough test take equally likely."""
    starts = [(t, s) for t, take in enumerate(test_takes) for s in range(take.num_frames - frames + 1)]
    if not starts:
        raise ValueError(f"no test take has {frames} frames for a query clip")
    out = []
    for seed in seeds:
        picks = np.random.default_rng(seed).choice(len(starts), size=clips, replace=len(starts) < clips)
        out += [starts[p] for p in picks]
    return out


def clip_features(index: Any, test_takes: Sequence[Any], clips: Sequence[tuple[int, int]],
                  frames: int) -> list[np.ndarray]:
    """``(frames, d)`` float32 features of every clip, each computed within its whole take (as the database's)."""
    per_take: dict[int, np.ndarray] = {}
    out = []
    for t, start in clips:
        if t not in per_take:
            per_take[t] = index.features_of(np.asarray(test_takes[t].positions, dtype=np.float64))
        out.append(np.ascontiguousarray(per_take[t][start:start + frames], dtype=np.float32))
    return out


# ---------------------------------------------------------------------------------------------
# Measurements


def _build(database: Any, feature_set: str, features: np.ndarray, fitted: Any, engine: str,
           workers: int) -> tuple[Any, float, dict[str, float | None]]:
    """An index, its build seconds and its memory: ``rss_mb`` the resident set the build added (MB; temporaries it
    freed but the allocator kept count too), ``index_mb`` a faiss index's serialized size (its vectors, lists and
    links; None for the kd-trees)."""
    from stylemotion.search import FrameIndex

    before = rss_mb(trim=True)
    t0 = time.perf_counter()
    index = FrameIndex(database, feature_set, features, fitted, engine=engine, workers=workers)
    seconds = time.perf_counter() - t0
    added = rss_mb() - before
    state = index.engine_state()
    return index, seconds, {"rss_mb": added, "index_mb": None if state is None else state.nbytes / 2**20}


def time_queries(indexes: dict[str, Any], clips: Sequence[np.ndarray], k: int, single_per_clip: int,
                 threads: str) -> dict[str, dict[str, list[float]]]:
    """Back-to-back ms per query frame of every engine: ``{engine: {"batched": [per clip], "single": [per frame]}}``
    (engine order rotated per clip and per frame; one untimed warm-up query each)."""
    names = list(indexes)
    out: dict[str, dict[str, list[float]]] = {e: {"batched": [], "single": []} for e in names}
    with thread_limit(threads):
        for e in names:
            indexes[e].query(clips[0], k)
        for c, clip in enumerate(clips):
            for e in rotated(names, c):
                out[e]["batched"].append(timed_ms(lambda: indexes[e].query(clip, k)) / len(clip))  # noqa: B023
            for j, row in enumerate(clip[:single_per_clip]):
                for e in rotated(names, c + j):
                    out[e]["single"].append(timed_ms(lambda: indexes[e].query(row, k)))  # noqa: B023
    return out


def _exactness(index: Any, queries: np.ndarray, k: int, ref_d: np.ndarray) -> dict[str, Any]:
    """How an engine's answers compare with the reference: recall@k and the largest distance error."""
    dist, idx = index.query(queries, k)
    own = true_distances(index.features, queries, idx)
    finite = np.isfinite(dist) & np.isfinite(ref_d)
    return {"recall": recall_at(own, ref_d[:, -1]),
            "max_distance_error": float(np.max(np.abs(dist - ref_d), where=finite, initial=0.0))}


def measure_validation(train_takes: Sequence[Any], val_takes: Sequence[Any], fps: float, features: Sequence[str],
                       args: argparse.Namespace, seeds: Sequence[int], use_cache: bool) -> dict[str, Any]:
    """Phase 0: cKDTree and ``ckdtree-pca`` under every :data:`FETCH_CANDIDATES` on a train-take database with
    val-take query clips (batched, 1 thread, back to back); the rounds and the ``auto`` rule they choose."""
    from stylemotion.datasets import TakeSet
    from stylemotion.search import FrameIndex, MotionDatabase

    database = MotionDatabase.from_takeset(TakeSet("train", list(train_takes), fps))
    clips = choose_clips(val_takes, args.validation_clips, args.clip_frames, seeds)
    labels = [fetch_label(f) for f in FETCH_CANDIDATES]
    sets = []
    for feature_set in features:
        print(f"[engines] validation: {feature_set}", flush=True)
        first = FrameIndex.build(database, feature_set, engine="ckdtree", use_cache=use_cache)
        kd = FrameIndex(database, feature_set, first.features, first.fitted, engine="ckdtree", workers=1)
        pca = FrameIndex(database, feature_set, first.features, first.fitted, engine="ckdtree-pca", workers=1)
        queries = clip_features(first, val_takes, clips, args.clip_frames)
        del first
        flat = np.concatenate(queries)
        ref_d, _ = kd.query(flat, args.k)
        errors = {}
        for label, fetch in zip(labels, FETCH_CANDIDATES):
            pca._engine.fetch = tuple(fetch)  # the engine's rounds (FILTER_FETCH by default)
            errors[label] = float(np.max(np.abs(pca.query(flat, args.k)[0] - ref_d)))
        names = ["ckdtree", *labels]
        times: dict[str, list[float]] = {name: [] for name in names}
        with thread_limit("1"):
            kd.query(queries[0], args.k)  # untimed warm-up
            pca.query(queries[0], args.k)
            for c, clip in enumerate(queries):
                for name in rotated(names, c):
                    index = kd if name == "ckdtree" else pca
                    if name != "ckdtree":
                        pca._engine.fetch = FETCH_CANDIDATES[labels.index(name)]
                    times[name].append(timed_ms(lambda: index.query(clip, args.k)) / len(clip))  # noqa: B023
        sets.append({"features": feature_set, "dim": kd.dim, "ckdtree": _stats(times["ckdtree"]),
                     "ckdtree-pca": {label: _stats(times[label]) for label in labels},
                     "max_distance_error": errors})
        del kd, pca
        gc.collect()
    chosen, rule = choose_fetch([row["dim"] for row in sets], [row["ckdtree"]["mean"] for row in sets],
                                [{label: row["ckdtree-pca"][label]["mean"] for label in labels} for row in sets])
    return {"frames": database.num_frames, "takes": database.num_takes, "clips": len(clips),
            "candidates": labels, "fetch": chosen, "rule": rule, "sets": sets}


def measure_set(database: Any, feature_set: str, test_takes: Sequence[Any], clips: Sequence[tuple[int, int]],
                args: argparse.Namespace, use_cache: bool) -> dict[str, Any]:
    """Every engine on one feature set: build, memory, query times at both thread counts, exactness, breadths."""
    from stylemotion.search import FrameIndex
    from stylemotion.search.index import APPROXIMATE_ENGINES, HNSW_EF_SEARCH, IVF_NPROBE, auto_engine

    t0 = time.perf_counter()
    first = FrameIndex.build(database, feature_set, engine="ckdtree", use_cache=use_cache)
    features, fitted = first.features, first.fitted
    features_s = time.perf_counter() - t0
    queries = clip_features(first, test_takes, clips, args.clip_frames)
    flat_queries = np.concatenate(queries)
    ref_d, _ = first.query(flat_queries, args.k)  # cKDTree, float64: the exact reference
    del first
    row: dict[str, Any] = {"features": feature_set, "dim": int(features.shape[1]), "features_s": features_s,
                           "auto": auto_engine(int(features.shape[1])), "engines": {}, "breadths": {}}
    indexes: dict[str, Any] = {}
    for engine in args.engines:
        index, seconds, memory = _build(database, feature_set, features, fitted, engine,
                                        1 if engine in SCIPY_ENGINES else -1)
        indexes[engine] = index
        row["engines"][engine] = {"build_s": seconds, **memory, **_exactness(index, flat_queries, args.k, ref_d)}
    all_cores = dict(indexes)
    for engine in SCIPY_ENGINES:  # scipy takes its thread count at construction; these builds are not measured
        if engine in indexes:
            all_cores[engine] = FrameIndex(database, feature_set, features, fitted, engine=engine, workers=-1)
    for threads, group in (("1", indexes), ("all", all_cores)):
        times = time_queries(group, queries, args.k, args.single_per_clip, threads)
        for engine, t in times.items():
            row["engines"][engine][threads] = {"batched": _stats(t["batched"]), "single": _stats(t["single"])}
    del all_cores
    baseline = row["auto"] if row["auto"] in indexes else None
    for engine, breadths, default in (("faiss-hnsw", args.hnsw_breadths, HNSW_EF_SEARCH),
                                      ("faiss-ivf", args.ivf_breadths, IVF_NPROBE)):
        if engine in indexes and engine in APPROXIMATE_ENGINES:
            row["breadths"][engine] = _breadths(indexes[engine], indexes.get(baseline), breadths, default, queries,
                                                flat_queries, ref_d, args.k)
    return row


def _breadths(index: Any, baseline: Any, breadths: Sequence[int], default: int, clips: Sequence[np.ndarray],
              flat_queries: np.ndarray, ref_d: np.ndarray, k: int) -> list[dict[str, Any]]:
    """Recall and batched time (1 thread, back to back with ``auto``'s engine) of an approximate engine per
    breadth; the index is left at ``default``."""
    values = sorted({*breadths, default})
    out = []
    for b in values:
        index.set_breadth(b)
        out.append({"breadth": b, "default": b == default,
                    "recall": _exactness(index, flat_queries, k, ref_d)["recall"], "ms": []})
    base_ms: list[float] = []
    with thread_limit("1"):
        for c, clip in enumerate(clips):
            for j in rotated(list(range(len(values) + 1)), c):
                if j == len(values):
                    if baseline is not None:
                        base_ms.append(timed_ms(lambda: baseline.query(clip, k)) / len(clip))  # noqa: B023
                    continue
                index.set_breadth(values[j])
                out[j]["ms"].append(timed_ms(lambda: index.query(clip, k)) / len(clip))  # noqa: B023
    index.set_breadth(default)
    base = quantiles(base_ms, (50,))["p50"]
    for r in out:
        r["batched"] = _stats(r.pop("ms"))
        r["over_auto"] = r["batched"]["p50"] / base if base else None
    return out


def measure_scale(base: Any, test_takes: Sequence[Any], clips: Sequence[tuple[int, int]],
                  args: argparse.Namespace, seed: int) -> dict[str, Any]:
    """Engines one at a time over ``--scale-frames`` frames of jittered copies of ``base``."""
    import bench_search

    from stylemotion.search import MotionDatabase
    from stylemotion.search.index import database_features

    copies = max(1, math.ceil(args.scale_frames / base.num_frames))
    t0 = time.perf_counter()
    database = MotionDatabase.from_takeset(bench_search.copies_of(base, copies, args.jitter, seed))
    out: dict[str, Any] = {"copies": copies, "frames": database.num_frames, "jitter_m": args.jitter,
                           "copies_s": time.perf_counter() - t0, "sets": []}
    gc.collect()
    for feature_set in args.scale_features:
        t0 = time.perf_counter()
        features, fitted = database_features(database, feature_set)
        row: dict[str, Any] = {"features": feature_set, "dim": int(features.shape[1]),
                               "features_s": time.perf_counter() - t0, "engines": {}}
        ref: dict[str, np.ndarray] = {}
        for engine in args.scale_engines:
            row["engines"][engine] = _scale_engine(database, feature_set, features, fitted, engine, test_takes, clips,
                                                   args, ref)
            gc.collect()
        out["sets"].append(row)
        del features
        gc.collect()
    out["peak_rss_mb"] = _peak_rss_mb()
    return out


def _scale_engine(database: Any, feature_set: str, features: np.ndarray, fitted: Any, engine: str,
                  test_takes: Sequence[Any], clips: Sequence[tuple[int, int]], args: argparse.Namespace,
                  ref: dict[str, np.ndarray]) -> dict[str, Any]:
    """One engine of the scale run: build, memory, query times at both thread counts, exactness against
    ``ref["d"]`` (set here by the first exact engine; ``ref["queries"]`` holds the clips' features)."""
    from stylemotion.search import FrameIndex
    from stylemotion.search.index import APPROXIMATE_ENGINES

    index, seconds, memory = _build(database, feature_set, features, fitted, engine,
                                    1 if engine in SCIPY_ENGINES else -1)
    if "queries" not in ref:
        ref["queries"] = np.stack(clip_features(index, test_takes, clips, args.clip_frames))
    queries = ref["queries"]
    flat_queries = queries.reshape(-1, queries.shape[-1])
    if "d" not in ref and engine not in APPROXIMATE_ENGINES:
        ref["d"] = index.query(flat_queries, args.k)[0]
    entry: dict[str, Any] = {"build_s": seconds, **memory}
    if "d" in ref:
        entry.update(_exactness(index, flat_queries, args.k, ref["d"]))
    for threads in THREADS:
        if engine in SCIPY_ENGINES and threads == "all":  # scipy takes its thread count at construction
            index = None  # free the 1-thread tree first
            gc.collect()
            index = FrameIndex(database, feature_set, features, fitted, engine=engine, workers=-1)
        with thread_limit(threads):
            index.query(queries[0], args.k)
            batched = [timed_ms(lambda: index.query(c, args.k)) / len(c) for c in queries]  # noqa: B023
            single = [timed_ms(lambda: index.query(r, args.k)) for r in flat_queries[:args.scale_single]]  # noqa: B023
        entry[threads] = {"batched": _stats(batched), "single": _stats(single)}
    return entry


def _peak_rss_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.datasets import TakeSet
    from stylemotion.search import MotionDatabase, feature_names
    from stylemotion.search.index import AUTO_ENGINES, FILTER_FETCH

    if args.quick:
        _quick(args)
    features = args.features or feature_names()
    takeset = _load(args)
    split, settings = _split(takeset, args)
    base = TakeSet(f"{takeset.name}-train+val", split["train"] + split["val"], takeset.fps)
    test = split["test"]
    clips = choose_clips(test, args.clips, args.clip_frames, seeds)
    cached = args.data == "bandai" and not args.quick  # a smoke run's subset is not worth a cache file
    validation = measure_validation(split["train"], split["val"], takeset.fps, features, args, seeds, cached)
    gc.collect()
    database = MotionDatabase.from_takeset(base)
    results: dict[str, Any] = {
        "quick": bool(args.quick), "data": args.data, "k": args.k, "frames": database.num_frames,
        "takes": database.num_takes, "clip_frames": args.clip_frames, "clips": len(clips),
        "single_per_clip": args.single_per_clip, "cores": os.cpu_count(),
        "auto_rule": [[None if math.isinf(limit) else limit, engine] for limit, engine in AUTO_ENGINES],
        "splits": {**take_split_record(split, settings["seed"], settings["val_fraction"],
                                       settings["test_fraction"]),
                   "database": "train + val takes", "queries": "clips of the test takes",
                   "choice": "train-take database, val-take query clips (phase 0)"},
        "library_fetch": fetch_label(FILTER_FETCH), "validation": validation, "sets": [], "scale": None,
    }
    for feature_set in features:
        print(f"[engines] {feature_set}", flush=True)
        results["sets"].append(measure_set(database, feature_set, test, clips, args, use_cache=cached))
    del database
    gc.collect()
    if args.scale_frames > 0:
        print(f"[engines] scale: {args.scale_frames:,} frames", flush=True)
        scale_clips = choose_clips(test, args.scale_clips, args.clip_frames, seeds)
        results["scale"] = measure_scale(base, test, scale_clips, args, seeds[0])
    return results


# ---------------------------------------------------------------------------------------------
# Render


def _ms(stats: dict[str, Any] | None, digits: int = 3) -> str:
    if not stats or stats.get("p50") is None:
        return "—"
    return f"{fmt(stats['p50'], digits)} / {fmt(stats['p95'], digits)}"


def _memory(v: dict[str, Any]) -> str:
    return f"{fmt(v['rss_mb'], 0)} / {fmt(v['index_mb'], 0)}"


def _mark(value: float | None, aim: float, below: bool = True) -> str:
    if value is None:
        return ""
    return " ✓" if (value <= aim if below else value >= aim) else " ✗"


def _exact_times(row: dict[str, Any]) -> dict[str, float]:
    """Exact engine → batched p50 ms per query at 1 thread."""
    from stylemotion.search.index import EXACT_ENGINES

    return {e: v["1"]["batched"]["p50"] for e, v in row["engines"].items() if e in EXACT_ENGINES}


def _quick_note(r: dict[str, Any]) -> str:
    return ("**Quick smoke run (`--quick`): small database, few clips — these figures are no measurement.**\n\n"
            if r.get("quick") else "")


def _table(r: dict[str, Any]) -> str:
    rows = []
    for row in r["sets"]:
        times = _exact_times(row)
        fastest = min(times.values()) if times else None
        for engine, v in row["engines"].items():
            quality = (f"{v['max_distance_error']:.1e}" + ("" if v["recall"] >= 1.0 else " ✗ not exact")
                       if engine in times else f"{v['recall']:.4f}")
            rows.append([f"{row['features']} ({row['dim']})", engine + (" ← auto" if engine == row["auto"] else ""),
                         fmt(v["build_s"], 2), _memory(v), _ms(v["1"]["batched"]),
                         _ms(v["all"]["batched"]), _ms(v["1"]["single"]), _ms(v["all"]["single"]),
                         fmt(v["1"]["batched"]["p50"] / fastest, 2) if fastest else "—",
                         quality])
    header = ["set (dims)", "engine", "build s", "memory MB: RSS added / faiss index",
              "batched ms/query p50 / p95, 1 thread", f"batched, {r['cores']} cores", "single ms p50 / p95, 1 thread",
              f"single, {r['cores']} cores",
              "batched 1 thread × fastest exact", "exact: max distance error / approx.: recall@16"]
    return (_quick_note(r) + md_table(header, rows) +
            f"\n\n{r['k']}-NN of {r['clips']} clips × {r['clip_frames']} consecutive frames of the held-out test takes "
            f"against the {r['frames']:,} frames of the train + val takes ({r['takes']:,} takes); batched: one call "
            f"per clip (ms per frame), single: one call per frame ({r['single_per_clip']} frames per clip). Engines "
            "timed back to back (rotated order); memory: resident set the build added (freed memory handed back to the "
            "OS first) and a faiss index's serialized size; builds at the default "
            "thread count (faiss' are parallel, the kd-trees' are not). Approximate engines at their default "
            "breadth. Compare timings as ratios.")


def _choice(r: dict[str, Any]) -> str:
    sets = [row for row in r["sets"] if _exact_times(row)]
    dims, times = [row["dim"] for row in sets], [_exact_times(row) for row in sets]
    implied = implied_rule(dims, times)
    library = library_rule_engines(dims)
    rows = []
    for row, t, want, have in zip(sets, times, implied["per_set"], library):
        fastest = min(t, key=t.get)
        rows.append([f"{row['features']} ({row['dim']})", f"{fastest} ({fmt(t[fastest], 3)} ms)",
                     f"{want} (× {fmt(t[want] / t[fastest], 2)})" if want in t else f"{want} (not measured)",
                     f"{have} (× {fmt(t[have] / t[fastest], 2)})" if have in t else f"{have} (not measured)"])
    logs = [math.log(t[e] / min(t.values())) for e, t in zip(library, times) if e in t]
    library_geo = math.exp(sum(logs) / len(logs)) if logs else None
    rule = (f"{implied['low']} for every dimension" if implied["limit"] is None else
            f"{implied['low']} for ≤ {implied['limit']} dimensions, {implied['high']} above")
    same = implied["per_set"] == library
    verdict = ("the library's rule, chosen on validation (block `engines/validation`), picks the same engine for "
               "every set here too" if same else
               "the library's rule, chosen on validation (block `engines/validation`), differs from this test-clip "
               "rule; it is not re-chosen on the reported clips")
    rules = ", ".join(f"≤ {'∞' if lim is None else lim}: {e}" for lim, e in r["auto_rule"])
    return (_quick_note(r) + md_table(["set (dims)", "fastest exact (batched, 1 thread)", "measured rule's engine",
                                       "library rule's engine"], rows) +
            f"\n\nMeasured rule (one engine up to D dimensions, another above, both among the float64 exact engines "
            f"`auto` may pick: {', '.join(FLOAT64_ENGINES)}; the D and engines whose times are on geometric mean "
            f"closest to each set's fastest exact engine of any kind): **{rule}** (× {fmt(implied['geomean'], 2)} "
            f"the fastest). Library (`AUTO_ENGINES`: {rules}): × {fmt(library_geo, 2)}; {verdict}.")


def _validation(r: dict[str, Any]) -> str:
    from stylemotion.search.index import AUTO_ENGINES

    v = r.get("validation")
    if not v:
        return _quick_note(r) + "Not run (a results file from before the validation phase)."
    chosen, labels, rule = v["fetch"], v["candidates"], v["rule"]
    rows = []
    for row in v["sets"]:
        cells = [f"{row['features']} ({row['dim']})", _mean_p50(row["ckdtree"])]
        for label in labels:
            text = _mean_p50(row["ckdtree-pca"][label])
            cells.append(f"**{text}**" if label == chosen else text)
        cells.append(f"{max(row['max_distance_error'].values()):.1e}")
        rows.append(cells)
    library_rule = [[None if math.isinf(lim) else lim, e] for lim, e in AUTO_ENGINES]
    rule_text = (f"{rule['low']} for every dimension" if rule["limit"] is None else
                 f"{rule['low']} for ≤ {rule['limit']} dimensions, {rule['high']} above")
    measured_rule = ([[None, rule["low"]]] if rule["limit"] is None else
                     [[rule["limit"], rule["low"]], [None, rule["high"]]])
    library_engines = library_rule_engines([row["dim"] for row in v["sets"]])
    same_rule = library_engines == rule["per_set"]
    same_fetch = r.get("library_fetch") == chosen
    verdicts = [
        "The library's `FILTER_FETCH` is the chosen rounds" if same_fetch else
        f"**The library's `FILTER_FETCH` ({r.get('library_fetch')}) differs from the chosen rounds: set it and rerun**",
        "the library's `AUTO_ENGINES` picks the chosen rule's engine for every set" if same_rule else
        f"**the library's `AUTO_ENGINES` ({library_rule}) differs from the chosen rule ({measured_rule}): set it and "
        "rerun**"]
    header = ["set (dims)", "cKDTree", *[f"ckdtree-pca {label}" for label in labels], "max distance error"]
    return (_quick_note(r) + md_table(header, rows) +
            f"\n\nms per query frame, mean / median over {v['clips']} clips × {r['clip_frames']} frames of the **val** "
            f"takes against the {v['frames']:,} frames of the **train** takes ({v['takes']:,} takes; the test takes "
            f"and the reported queries play no part), {r['k']}-NN, batched, 1 thread, back to back (rotated). "
            "`ckdtree-pca first/growth/last`: its multi-step rounds (fetch first·k nearest in the embedding, growth× "
            "more per round up to last·k, then the ball query); every candidate's answers equal cKDTree's (last "
            "column). Chosen together on the means: per candidate rounds, the rule \"one engine up to D dimensions, "
            "the other above\" closest to each set's faster engine; then the rounds whose rule has the least geometric "
            f"mean time over the sets: **{chosen}**, with **{rule_text}** (× {fmt(rule['geomean'], 2)} the faster). "
            + "; ".join(verdicts) + ".")


def _mean_p50(stats: dict[str, Any]) -> str:
    return f"{fmt(stats['mean'], 3)} / {fmt(stats['p50'], 3)}"


def _approximate(r: dict[str, Any]) -> str:
    rows = []
    for row in r["sets"]:
        for engine, sweep in row["breadths"].items():
            for b in sweep:
                rows.append([f"{row['features']} ({row['dim']})", engine, f"{b['breadth']}" + (" (default)" if
                             b["default"] else ""), f"{b['recall']:.4f}{_mark(b['recall'], AIM_RECALL, below=False)}",
                             _ms(b["batched"]), fmt(b["over_auto"], 2)])
    return (_quick_note(r) + md_table(["set (dims)", "engine", "breadth (efSearch / nprobe)",
                                       f"recall@{r['k']} (aim ≥ {AIM_RECALL})", "batched ms/query p50 / p95, 1 thread",
                                       "× auto's engine"], rows) +
            "\n\nRecall: returned frames within the exact k-th distance (ties count), over every query frame. Time: "
            "one call per clip, each breadth and auto's exact engine back to back.")


def _scale(r: dict[str, Any]) -> str:
    s = r.get("scale")
    if not s:
        return _quick_note(r) + "Not run (`--scale-frames 0`)."
    rows = []
    for row in s["sets"]:
        for engine, v in row["engines"].items():
            rows.append([f"{row['features']} ({row['dim']})", engine, fmt(v["build_s"], 1), _memory(v),
                         _ms(v["1"]["batched"]), _ms(v["all"]["batched"]), _ms(v["1"]["single"]),
                         f"{v['recall']:.4f}" if "recall" in v else "—"])
    return (_quick_note(r) + md_table(["set (dims)", "engine", "build s", "memory MB: RSS added / faiss index",
                                       "batched ms/query p50 / p95, 1 thread", f"batched, {r['cores']} cores",
                                       "single ms p50 / p95, 1 thread", f"recall@{r['k']}"], rows) +
            f"\n\n{s['frames']:,} frames: {s['copies']} copies of the train + val takes (copy 1 mirrored, copies ≥ 2 "
            f"with every joint displaced by N(0, {s['jitter_m']} m)); engines built and timed one at a time; "
            f"features {', '.join(fmt(x['features_s'], 1) + ' s' for x in s['sets'])}; peak resident set of the "
            f"process {fmt(s['peak_rss_mb'] / 1024, 1)} GB. Recall against the first exact engine.")


def _headline(r: dict[str, Any]) -> str:
    rows = []
    for row in r["sets"]:
        v = row["engines"].get(row["auto"])
        if v is None:
            continue
        p50, mean = v["1"]["batched"]["p50"], v["1"]["batched"].get("mean")
        approx = [b for sweep in row["breadths"].values() for b in sweep if b["default"]]
        rows.append([f"{row['features']} ({row['dim']})", row["auto"], f"{fmt(p50, 3)}{_mark(p50, AIM_MS)}",
                     "—" if mean is None else f"{fmt(mean, 3)}{_mark(mean, AIM_MS)}",
                     fmt(v["all"]["batched"]["p50"], 3), fmt(v["1"]["single"]["p50"], 3),
                     ", ".join(f"{b['recall']:.3f}{_mark(b['recall'], AIM_RECALL, below=False)}" for b in approx)
                     or "—"])
    return (_quick_note(r) + md_table(["set (dims)", "auto's engine", f"16-NN ms/query, batched, 1 thread, median "
                                       f"over clips (aim ≤ {AIM_MS})", "mean over clips",
                                       f"batched, {r['cores']} cores", "single, 1 thread",
                                       "HNSW, IVF recall@16 at default breadth (aim ≥ 0.99)"], rows))


def _summary(r: dict[str, Any]) -> str:
    """One paragraph for BENCHMARKS.md: the aims with ``auto``'s engine, the approximate recall, the scale run."""
    rows = [row for row in r["sets"] if row["auto"] in row["engines"]]
    p50 = {row["features"]: row["engines"][row["auto"]]["1"]["batched"]["p50"] for row in rows}
    mean = {row["features"]: row["engines"][row["auto"]]["1"]["batched"].get("mean") for row in rows}
    over_mean = [f"{name} {fmt(v, 3)} ms" for name, v in mean.items() if v is not None and v > AIM_MS]
    recalls = [b["recall"] for row in r["sets"] for sweep in row["breadths"].values() for b in sweep if b["default"]]
    gains = []
    for row in rows:
        e = row["engines"]
        if row["auto"] == "ckdtree-pca" and "ckdtree" in e and e["ckdtree"]["1"]["batched"].get("mean"):
            gains.append(e["ckdtree"]["1"]["batched"]["mean"] / e["ckdtree-pca"]["1"]["batched"]["mean"])
    text = (f"16-NN per query frame with `engine=auto` against all {r['frames']:,} train + val frames of Bandai "
            f"(batched, 1 thread): median over clips {fmt(min(p50.values()), 3)}–{fmt(max(p50.values()), 3)} ms, "
            f"{sum(v <= AIM_MS for v in p50.values())} of {len(p50)} sets within the {AIM_MS} ms aim on the median, "
            f"{sum(v is not None and v <= AIM_MS for v in mean.values())} of {len(mean)} on the mean over clips"
            + (f" ({', '.join(over_mean)})" if over_mean else "") + ".")
    if gains:
        text += (f" On the windowed sets the projected kd-tree `ckdtree-pca` is × {fmt(min(gains), 1)}–"
                 f"{fmt(max(gains), 1)} faster than cKDTree on the mean over clips.")
    if recalls:
        text += f" HNSW and IVF at their default breadth: recall@16 ≥ {min(recalls):.3f}."
    scale = r.get("scale")
    if scale:
        parts = []
        for row in scale["sets"]:
            e = row["engines"]
            exact = min((v["1"]["batched"]["p50"], name) for name, v in e.items() if name in EXACT_ENGINES_MEASURED)
            part = f"{row['features']} fastest exact {exact[1]} {fmt(exact[0], 2)} ms"
            if "faiss-ivf" in e:
                v = e["faiss-ivf"]
                part += f", IVF {fmt(v['1']['batched']['p50'], 2)} ms at recall {v.get('recall', float('nan')):.4f}"
            parts.append(part)
        text += (f" At {scale['frames']:,} frames (jittered copies; median, 1 thread): {'; '.join(parts)}; peak "
                 f"resident set {fmt(scale['peak_rss_mb'] / 1024, 1)} GB.")
    return _quick_note(r) + text + " ([benchmarks/engines.md](benchmarks/engines.md))"


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    line = provenance_line(record)
    return {"summary": f"{_summary(r)} {line}", "headline": f"{_headline(r)}\n\n{line}",
            "table": f"{_table(r)}\n\n{line}",
            "choice": f"{_choice(r)}\n\n{line}", "validation": f"{_validation(r)}\n\n{line}",
            "approximate": f"{_approximate(r)}\n\n{line}",
            "scale": f"{_scale(r)}\n\n{line}"}
