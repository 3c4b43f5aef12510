"""k-nearest-neighbour search over every frame of a dataset (Krüger §2.3.3, Table 2.1).

:class:`FrameIndex` holds one feature set's features of every frame of a :class:`MotionDatabase` and an
engine that answers k-NN queries on them (Euclidean distance in feature space):

* ``"auto"`` (default, exact): the exact engine :func:`auto_engine` picks for the features' dimension from
  :data:`AUTO_ENGINES` (a kd-tree for few dimensions, the projected kd-tree for many), a rule read off the table
  ``python scripts/benchmarks.py run engines`` measures;
* ``"ckdtree"`` (exact): :class:`scipy.spatial.cKDTree`;
* ``"ckdtree-pca"`` (exact): filter and refine — a cKDTree over a low-dimensional embedding whose distances never
  exceed the true ones (the principal-axis coordinates keeping :data:`PROJECTION_VARIANCE` of the variance, plus the
  norm of the rest), then exact float64 distances of the frames nearest in the embedding, fetched in growing rounds
  until no other frame can be nearer;
* ``"pykdtree"`` (exact): the ``pykdtree`` package, float32, OpenMP-parallel over queries;
* ``"faiss"`` (exact): ``faiss.IndexFlatL2`` brute force (optional extra ``search``);
* ``"faiss-hnsw"`` (approximate, no ε guarantee): ``faiss.IndexHNSWFlat`` graph (:data:`HNSW_M` links per node,
  ``efSearch`` = :data:`HNSW_EF_SEARCH`);
* ``"faiss-ivf"`` (approximate, no ε guarantee): ``faiss.IndexIVFFlat``, :func:`ivf_lists` k-means cells of which
  :data:`IVF_NPROBE` nearest are scanned — the index type whose cells shard across machines (docs/search.md,
  "Engines and scale").

The approximate engines' search breadth (HNSW's ``efSearch``, IVF's ``nprobe``) trades recall for time:
:meth:`FrameIndex.set_breadth`.

Queries: exact k nearest, the up-to-k nearest within a fixed radius (missing ones padded with distance
``inf`` and index ``-1``), and approximate ε search as in cKDTree (the i-th result is within ``1 + ε``
of the true i-th nearest distance; the kd-tree engines honour it, ``"faiss"`` is exact anyway).

Persisting: :meth:`FrameIndex.build` keeps the features and a fitted PCA in
``<dataset cache>/search/`` as an ``.npz`` of plain arrays (read with ``allow_pickle=False``), keyed on
the database's content digest (:attr:`MotionDatabase.digest` — so it is invalidated with the dataset:
any changed frame, take or label gives a new key), the feature set, the normalization and
:data:`SEARCH_FORMAT`. kd-trees, flat and IVF indexes are rebuilt on load (a cKDTree over 400k frames takes
~0.2 s; pickled trees would be arbitrary objects); an HNSW graph (~1 min for 400k frames) is stored beside the features
as faiss' own serialized bytes with a CRC.
"""

from __future__ import annotations

import hashlib
import importlib.util
import io
import json
import math
import os
import warnings
import zlib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.datasets.base import TakeSet
from stylemotion.datasets.loading import CacheWarning, default_cache_dir
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.outputs import safe_name
from stylemotion.search.database import FrameLocation, MotionDatabase
from stylemotion.search.features import (
    FEATURE_SETS,
    FittedPCA,
    compute_features,
    feature_spec,
    fit_features,
)

#: Bump when the features or the cache layout change, to invalidate cached indexes.
SEARCH_FORMAT = 2  # 2: physics terms scaled by a 0.3 s interval and a 73 kg body
#: Engines by name: ``auto``, the exact ones, the approximate ones.
ENGINES = ("auto", "ckdtree", "ckdtree-pca", "pykdtree", "faiss", "faiss-hnsw", "faiss-ivf")
EXACT_ENGINES = ("ckdtree", "ckdtree-pca", "pykdtree", "faiss")
#: Exact engines whose distances are float64 (the others compute in float32): those ``auto`` may pick.
FLOAT64_ENGINES = ("ckdtree", "ckdtree-pca")
APPROXIMATE_ENGINES = ("faiss-hnsw", "faiss-ivf")
#: Engines whose built index is slow enough to build that :meth:`FrameIndex.build` caches it too.
STORED_ENGINES = ("faiss-hnsw",)
#: Links per node of the HNSW graph (faiss' ``M``).
HNSW_M = 32
#: Default breadth of an HNSW search (faiss' ``efSearch``; raised to k when k is larger).
HNSW_EF_SEARCH = 64
#: Default cells an IVF search scans (faiss' ``nprobe``).
IVF_NPROBE = 32
#: Share of the features' variance the embedding of engine ``ckdtree-pca`` keeps on its principal axes (the rest
#: enters as one coordinate, the residual's norm). Not tuned: any share gives exact answers, only the speed moves.
PROJECTION_VARIANCE = 0.95
#: Frames (a seeded sample) the principal axes of ``ckdtree-pca`` are fitted on; rows embedded per chunk.
PROJECTION_SAMPLE = 50_000
_EMBED_CHUNK = 100_000
#: ``ckdtree-pca``'s multi-step search (Seidl & Kriegel's optimal filter and refine, in rounds): ``(first, growth,
#: last)`` — a query fetches ``first · k`` nearest in the embedding, then ``growth`` times more per round while
#: unsettled, up to ``last · k``; queries still unsettled take every frame embedded within their k-th distance.
#: Any value gives exact answers; it sets the speed only. Chosen on validation (a train-take database, val-take
#: query clips) by ``python scripts/benchmarks.py run engines`` (benchmarks/engines.md, block ``engines/validation``).
FILTER_FETCH: tuple[int, int, int] = (8, 2, 128)
#: Most candidate coordinates (queries × fetched frames × dimensions) one pass of ``ckdtree-pca`` holds in float64
#: (16 M: 128 MB); a large batch of queries (a motion graph's every frame) is answered in slices of that size.
_FETCH_CELLS = 1 << 24
#: Training points per IVF cell (k-means on a seeded sample of the database; faiss wants ≥ 39).
IVF_TRAIN_PER_LIST = 40
#: ``engine="auto"``: ``(largest feature dimension, exact engine)`` rows in ascending order; features of dimension
#: ``d`` use the engine of the first row whose dimension is ≥ ``d``. Only the float64 engines (:data:`FLOAT64_ENGINES`)
#: are candidates: pykdtree's and faiss' float32 distances put an LNG path's cost below exact DTW's on Bandai
#: (tests/search/test_search_bandai_slice.py). Chosen on validation by ``python scripts/benchmarks.py run engines``
#: (alone, Bandai: 16-NN of val-take clips against the train takes, batched, one thread, mean over clips;
#: benchmarks/engines.md, block ``engines/validation``, which says whether this rule is the chosen one): cKDTree for
#: the sets of up to 39 dimensions, the projected cKDTree above (E15x3 and the windowed 75–117-dimensional sets,
#: whose frames lie near a ~15-dimensional subspace). faiss' brute force was 24–76× slower than a kd-tree at
#: every dimension measured.
AUTO_ENGINES: tuple[tuple[float, str], ...] = ((39, "ckdtree"), (math.inf, "ckdtree-pca"))
#: The exact engine ``auto`` falls back to when the one its rule names is not installed.
AUTO_FALLBACK = "ckdtree"
_INSTALL_HINT = {"pykdtree": "pip install pykdtree", "faiss": "pip install 'stylemotion[search]' (faiss-cpu)"}


# ---------------------------------------------------------------------------------------------
# Engines: query(x (m, d) float32, k, eps, bound) -> (distances (m, k) float64, indices (m, k) int64),
# with indices ≥ n or < 0 for missing neighbours (cleaned up by FrameIndex).


class _CKDTree:
    def __init__(self, data: np.ndarray, workers: int, leafsize: int = 16):
        from scipy.spatial import cKDTree

        self.tree = cKDTree(data, leafsize=leafsize)
        self.workers = workers

    def query(self, x: np.ndarray, k: int, eps: float, bound: float) -> tuple[np.ndarray, np.ndarray]:
        d, i = self.tree.query(x, k=k, eps=eps, distance_upper_bound=bound, workers=self.workers)
        return np.reshape(d, (len(x), k)), np.reshape(i, (len(x), k))


class _PyKDTree:
    def __init__(self, data: np.ndarray, workers: int, leafsize: int = 16):
        try:
            from pykdtree.kdtree import KDTree
        except ImportError as exc:  # pragma: no cover - depends on the environment
            raise ImportError(f"engine 'pykdtree' needs the pykdtree package: {_INSTALL_HINT['pykdtree']}") from exc
        self.tree = KDTree(np.ascontiguousarray(data, dtype=np.float32), leafsize=leafsize)

    def query(self, x: np.ndarray, k: int, eps: float, bound: float) -> tuple[np.ndarray, np.ndarray]:
        bound_arg = None if np.isinf(bound) else float(bound)
        d, i = self.tree.query(x, k=k, eps=eps, distance_upper_bound=bound_arg)
        return np.reshape(d, (len(x), k)).astype(np.float64), np.reshape(i, (len(x), k)).astype(np.int64)


class _ProjectedKDTree:
    """Exact k-NN by filter and refine (the lower-bounding embedding of Faloutsos et al.'s GEMINI).

    Each frame ``x`` is embedded as ``z(x) = [Vᵀ(x − μ), ‖(I − VVᵀ)(x − μ)‖]`` with ``V`` ``(d, p)`` the principal
    axes keeping :data:`PROJECTION_VARIANCE` of a seeded sample's variance; ``‖z(x) − z(y)‖ ≤ ‖x − y‖`` (Pythagoras
    and the reverse triangle inequality), so a frame farther than r in the embedding is farther than r. A query
    fetches its ``first · k`` nearest in the embedding and ranks them by float64 distances (ties by index); it is
    settled when the last one fetched lies farther in the embedding than the k-th true distance found, as then no
    other frame can be nearer (Seidl & Kriegel's multi-step k-NN, in rounds of ``growth`` times more, up to
    ``last · k``; :attr:`fetch`). A query still unsettled takes every frame embedded within that k-th distance. A
    radius search (a finite ``bound``) runs one round of k and then the ball within ``min(r, bound)``. ε is not
    used: the answer is exact.
    """

    def __init__(self, data: np.ndarray, workers: int):
        from scipy.spatial import cKDTree

        n, d = data.shape
        rows = np.sort(np.random.default_rng(0).choice(n, size=min(n, PROJECTION_SAMPLE), replace=False))
        sample = data[rows].astype(np.float64)
        self.mean = sample.mean(axis=0)
        _, singular, axes = np.linalg.svd(sample - self.mean, full_matrices=False)
        share = np.cumsum(singular**2) / max(float(np.sum(singular**2)), np.finfo(float).tiny)
        p = min(int(np.searchsorted(share, PROJECTION_VARIANCE)) + 1, len(axes))
        self.axes = axes[:p].T  # (d, p), orthonormal columns
        self.data = data
        self.workers = workers
        self.fetch = FILTER_FETCH  # (first, growth, last): the multi-step rounds of :meth:`query`
        self.tree = cKDTree(np.concatenate([self.embed(data[i:i + _EMBED_CHUNK])
                                            for i in range(0, n, _EMBED_CHUNK)]))

    def embed(self, x: np.ndarray) -> np.ndarray:
        """``(m, p + 1)`` float64 embedding of frames ``(m, d)``."""
        centred = x.astype(np.float64) - self.mean
        projected = centred @ self.axes
        residual = np.linalg.norm(centred - projected @ self.axes.T, axis=1)
        return np.column_stack([projected, residual])

    def _distances(self, x: np.ndarray, owner: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Float64 distances from queries ``x[owner]`` (float64) to frames ``rows``."""
        return np.sqrt(np.sum((self.data[rows].astype(np.float64) - x[owner]) ** 2, axis=1))

    def query(self, x: np.ndarray, k: int, eps: float, bound: float) -> tuple[np.ndarray, np.ndarray]:
        m, n = len(x), len(self.data)
        x = x.astype(np.float64)  # once, for the embedding and every distance pass
        z = self.embed(x)
        distances, indices = np.full((m, k), np.inf), np.full((m, k), n, dtype=np.int64)
        pending, limit = np.arange(m), np.full(m, bound)
        # a radius caps the ball query already: one round of k, then the ball (the rounds pay off without a radius)
        first, growth, last = self.fetch if math.isinf(bound) else (1, 2, 1)
        fetch = min(n, k * first)
        while pending.size and fetch <= k * last:
            step = max(1, _FETCH_CELLS // (fetch * x.shape[1]))  # queries per slice: bounded memory
            parts = [self._fetched(x, z, pending[i:i + step], k, fetch, bound, distances, indices)
                     for i in range(0, len(pending), step)]
            pending, limit = np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])
            fetch = min(n, max(fetch + 1, fetch * growth))
        step = max(1, _FETCH_CELLS // (k * last * x.shape[1]))  # the ball holds about as many frames as the last round
        for i in range(0, len(pending), step):
            self._ball(x, z, pending[i:i + step], k, limit[i:i + step], bound, distances, indices)
        return distances, indices

    def _fetched(self, x: np.ndarray, z: np.ndarray, rows: np.ndarray, k: int, fetch: int, bound: float,
                 distances: np.ndarray, indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Answer the queries ``rows`` whose ``fetch`` nearest in the embedding settle them; return the rest with
        their radius (``(r,)`` each: the k-th smallest true distance among the fetched frames, at most ``bound``).

        A query is settled when its ``fetch``-th embedded distance exceeds its k-th smallest true distance among
        the fetched frames (or ``bound``): every other frame is at least that far in the embedding, hence in truth.
        """
        n = len(self.data)
        embedded, near = self.tree.query(z[rows], k=fetch, workers=self.workers)
        embedded, near = np.reshape(embedded, (len(rows), fetch)), np.reshape(near, (len(rows), fetch))
        exact = self._distances(x, np.repeat(rows, fetch), near.ravel()).reshape(len(rows), fetch)
        order = np.lexsort((near, exact))[:, :k]  # along each row: by distance, then frame index
        top_d, top_i = np.take_along_axis(exact, order, axis=1), np.take_along_axis(near, order, axis=1)
        limit = np.minimum(top_d[:, -1], bound)
        settled = (fetch == n) | (embedded[:, -1] > limit * (1.0 + 1e-9) + 1e-9)
        beyond = top_d > bound
        top_d[beyond], top_i[beyond] = np.inf, n
        distances[rows[settled]], indices[rows[settled]] = top_d[settled], top_i[settled]
        return rows[~settled], limit[~settled]

    def _ball(self, x: np.ndarray, z: np.ndarray, rows: np.ndarray, k: int, radius: np.ndarray, bound: float,
              distances: np.ndarray, indices: np.ndarray) -> None:
        """Answer the queries ``rows`` from every frame embedded within ``radius`` ``(r,)`` (each ≥ its query's true
        k-th distance, or ``bound``)."""
        m = len(rows)
        # a hair wider than r, so that rounding in the embedding cannot drop a frame at exactly r
        found = self.tree.query_ball_point(z[rows], radius * (1.0 + 1e-9) + 1e-9, workers=self.workers)
        counts = np.fromiter((len(f) for f in found), dtype=np.int64, count=m)
        frames = np.fromiter((i for f in found for i in f), dtype=np.int64, count=int(counts.sum()))
        owner = np.repeat(np.arange(m), counts)
        dist = self._distances(x, rows[owner], frames)
        keep = dist <= bound
        owner, frames, dist = owner[keep], frames[keep], dist[keep]
        order = np.lexsort((frames, dist, owner))  # by query, then distance, then frame index
        owner, frames, dist = owner[order], frames[order], dist[order]
        starts = np.searchsorted(owner, np.arange(m))
        rank = np.arange(len(owner)) - starts[owner]
        first = rank < k
        distances[rows[owner[first]], rank[first]] = dist[first]
        indices[rows[owner[first]], rank[first]] = frames[first]


def _import_faiss() -> Any:
    try:
        import faiss
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(f"the faiss engines need faiss-cpu: {_INSTALL_HINT['faiss']}") from exc
    return faiss


def ivf_lists(frames: int) -> int:
    """Cells of an IVF index over ``frames`` vectors: ``round(4·√frames)``, at most ``frames //``
    :data:`IVF_TRAIN_PER_LIST` (so every cell has its training points), at least 1."""
    return max(1, min(int(round(4.0 * math.sqrt(frames))), frames // IVF_TRAIN_PER_LIST))


class _Faiss:
    """A faiss index over ``data`` ``(n, d)``: ``kind`` ``"flat"`` (``IndexFlatL2``, exact), ``"hnsw"``
    (``IndexHNSWFlat``, ``hnsw_m`` links per node) or ``"ivf"`` (``IndexIVFFlat`` over :func:`ivf_lists` cells,
    k-means trained on a seeded sample of :data:`IVF_TRAIN_PER_LIST` points per cell)."""

    def __init__(self, data: np.ndarray, workers: int, kind: str = "flat", state: np.ndarray | None = None,
                 hnsw_m: int = HNSW_M, ef_construction: int = 80):
        faiss = _import_faiss()
        if workers > 0:
            faiss.omp_set_num_threads(workers)
        n, d = data.shape
        data = np.ascontiguousarray(data, dtype=np.float32)
        if state is not None:  # faiss' own binary format (faiss.serialize_index), not a pickle
            self.index = faiss.deserialize_index(np.ascontiguousarray(state, dtype=np.uint8))
            if self.index.ntotal != n or self.index.d != d:
                raise ValueError(f"stored faiss index holds {self.index.ntotal}×{self.index.d}, expected {data.shape}")
        elif kind == "hnsw":
            self.index = faiss.IndexHNSWFlat(d, hnsw_m)
            self.index.hnsw.efConstruction = ef_construction
            self.index.add(data)
        elif kind == "ivf":
            lists = ivf_lists(n)
            self.quantizer = faiss.IndexFlatL2(d)  # the IVF index keeps a pointer to it, not a reference
            self.index = faiss.IndexIVFFlat(self.quantizer, d, lists)
            self.index.cp.niter, self.index.cp.seed = 10, 0
            sample = min(n, IVF_TRAIN_PER_LIST * lists)
            rows = np.sort(np.random.default_rng(0).choice(n, size=sample, replace=False))
            self.index.train(data[rows])
            self.index.add(data)
        else:
            self.index = faiss.IndexFlatL2(d)
            self.index.add(data)
        self.kind = kind
        self.breadth = {"hnsw": HNSW_EF_SEARCH, "ivf": IVF_NPROBE}.get(kind, 0)

    def state(self) -> np.ndarray:
        """The index as faiss' serialized bytes ``(bytes,)`` uint8."""
        return _import_faiss().serialize_index(self.index)

    def query(self, x: np.ndarray, k: int, eps: float, bound: float) -> tuple[np.ndarray, np.ndarray]:
        if self.kind == "hnsw":
            self.index.hnsw.efSearch = max(self.breadth, k)
        elif self.kind == "ivf":
            self.index.nprobe = min(self.breadth, self.index.nlist)
        sq, i = self.index.search(np.ascontiguousarray(x, dtype=np.float32), k)
        d = np.sqrt(np.maximum(sq.astype(np.float64), 0.0))
        d[i < 0] = np.inf
        return d, i.astype(np.int64)


def faiss_available() -> bool:
    """Whether faiss (the optional extra ``search``) is installed."""
    return importlib.util.find_spec("faiss") is not None


def auto_engine(dim: int) -> str:
    """The exact engine ``engine="auto"`` uses for ``dim``-dimensional features: the first row of
    :data:`AUTO_ENGINES` whose dimension is ≥ ``dim``; :data:`AUTO_FALLBACK` when that engine is not installed."""
    if isinstance(dim, bool) or not isinstance(dim, (int, np.integer)) or dim < 1:
        raise ValueError(f"a feature dimension must be a whole number ≥ 1, got {dim!r}")
    engine = next(name for limit, name in AUTO_ENGINES if dim <= limit)
    installed = {"faiss": faiss_available(), "pykdtree": importlib.util.find_spec("pykdtree") is not None}
    return engine if installed.get(engine, True) else AUTO_FALLBACK


def _make_engine(engine: str, data: np.ndarray, workers: int, state: np.ndarray | None = None) -> Any:
    if engine == "ckdtree":
        return _CKDTree(data, workers)
    if engine == "ckdtree-pca":
        return _ProjectedKDTree(data, workers)
    if engine == "pykdtree":
        return _PyKDTree(data, workers)
    kinds = {"faiss": "flat", "faiss-hnsw": "hnsw", "faiss-ivf": "ivf"}
    if engine in kinds:
        return _Faiss(data, workers, kind=kinds[engine], state=state)
    raise ValueError(f"unknown search engine {engine!r}; valid: {list(ENGINES)}")


# ---------------------------------------------------------------------------------------------
# Features of a whole database


def database_features(database: MotionDatabase, feature_set: str, normalization: str = "3d",
                      fitted: FittedPCA | None = None) -> tuple[np.ndarray, FittedPCA | None]:
    """``(frames, d)`` float32 features of every frame (each take on its own), and the PCA fitted on all
    takes when the set needs one and ``fitted`` is None."""
    takes = [database.take_positions(i) for i in range(database.num_takes)]
    if fitted is None:
        fitted = fit_features(feature_set, takes, database.fps, normalization)
    parts = [compute_features(feature_set, p, database.fps, fitted, normalization, allow_short=True) for p in takes]
    return np.concatenate(parts), fitted


def index_cache_key(database: MotionDatabase, feature_set: str, normalization: str) -> str:
    """Hex key of an index's cached features: format, database digest, feature set and normalization."""
    text = json.dumps({"format": SEARCH_FORMAT, "database": database.digest, "features": feature_set,
                       "normalization": normalization}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def _cache_path(cache_dir: Path, database: MotionDatabase, feature_set: str, normalization: str) -> Path:
    key = index_cache_key(database, feature_set, normalization)
    return cache_dir / "search" / f"{safe_name(database.name)}-{feature_set}-{normalization}-{key}.npz"


def _write_features(path: Path, features: np.ndarray, fitted: FittedPCA | None, meta: dict[str, Any]) -> None:
    arrays: dict[str, np.ndarray] = {"features": features, "meta": np.array(json.dumps(meta))}
    if fitted is not None:
        arrays.update(fitted.to_arrays())
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    atomic_write_bytes(path, buffer.getvalue())


def _read_features(path: Path, expect_frames: int, expect_dim: int) -> tuple[np.ndarray, FittedPCA | None]:
    """Features and PCA of a cache file; ValueError when it does not hold what the key promised."""
    with np.load(path, allow_pickle=False) as npz:
        meta = json.loads(str(npz["meta"]))
        features = np.asarray(npz["features"])
        fitted = FittedPCA.from_arrays(npz) if "pca_mean" in npz.files else None
    if meta.get("format") != SEARCH_FORMAT:
        raise ValueError(f"format {meta.get('format')!r}, expected {SEARCH_FORMAT}")
    if features.dtype != np.float32 or features.shape != (expect_frames, expect_dim):
        raise ValueError(f"features are {features.dtype} {features.shape}, expected float32 "
                         f"({expect_frames}, {expect_dim})")
    return features, fitted


def _as_database(data: TakeSet | MotionDatabase | Mapping[str, Any]) -> MotionDatabase:
    if isinstance(data, MotionDatabase):
        return data
    if isinstance(data, TakeSet):
        return MotionDatabase.from_takeset(data)
    if isinstance(data, Mapping):
        from stylemotion.datasets.registry import build_dataset

        return MotionDatabase.from_takeset(build_dataset(data))
    raise TypeError(f"data must be a TakeSet, a MotionDatabase or a data config mapping, got {type(data).__name__}")


# ---------------------------------------------------------------------------------------------
# The index


def _check_count(value: Any, key: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{key} must be a whole number ≥ 1, got {value!r}")
    return int(value)


class FrameIndex:
    """k-NN index over one feature set of every frame of a :class:`MotionDatabase`.

    Attributes:
        database: the frames and their takes.  feature_set, normalization: how features are made.
        features: ``(frames, d)`` float32.  fitted: the database's PCA for ``pca*`` sets, else None.
        engine: the engine that answers (:data:`ENGINES` but never ``"auto"``: what it resolved to).
        requested_engine: the engine asked for (``"auto"`` by default).
        cache_path: where :meth:`build` keeps the features (None if built directly).
        from_cache: whether :meth:`build` read them from there.
    """

    def __init__(self, database: MotionDatabase, feature_set: str, features: np.ndarray | None = None,
                 fitted: FittedPCA | None = None, *, normalization: str = "3d", engine: str = "auto",
                 workers: int = 1, engine_state: np.ndarray | None = None):
        """Index ``features`` (computed, and a PCA fitted, when None). With ``features`` given, a
        ``feature_set`` that is none of :data:`FEATURE_SETS` names custom features of any width (``features_of``
        cannot compute those for a query: pass the query's own features to :meth:`query`).

        ``workers``: threads (cKDTree's ``workers``, -1 = all cores; faiss' OpenMP threads, set process-wide;
        pykdtree follows ``OMP_NUM_THREADS``). ``engine_state``: a faiss index serialized by
        :meth:`engine_state` for these features (skips the HNSW build). ``engine="auto"``: the exact engine
        :func:`auto_engine` picks for the features' dimension.
        """
        if features is None or feature_set in FEATURE_SETS:
            dim = feature_spec(feature_set).dim
        else:  # custom features under a name of the caller's (e.g. marker-only ones): any (frames, d)
            dim = int(np.shape(features)[1]) if np.ndim(features) == 2 else -1
        if engine not in ENGINES:
            raise ValueError(f"unknown search engine {engine!r}; valid: {list(ENGINES)}")
        if features is None:
            features, fitted = database_features(database, feature_set, normalization, fitted)
        features = np.ascontiguousarray(features, dtype=np.float32)
        if features.shape != (database.num_frames, dim):
            raise ValueError(f"features must be ({database.num_frames}, {dim}) for {feature_set}, "
                             f"got {features.shape}")
        self.database, self.feature_set, self.normalization = database, feature_set, normalization
        self.requested_engine = engine
        self.engine = auto_engine(dim) if engine == "auto" else engine
        self.features, self.fitted = features, fitted
        self.cache_path: Path | None = None
        self.from_cache = False
        self._engine = _make_engine(self.engine, features, workers, engine_state)

    def engine_state(self) -> np.ndarray | None:
        """The built faiss index as plain bytes ``(bytes,)`` uint8 (None for the kd-tree engines, which are
        rebuilt faster than they would load)."""
        return self._engine.state() if isinstance(self._engine, _Faiss) else None

    @classmethod
    def build(cls, data: TakeSet | MotionDatabase | Mapping[str, Any], feature_set: str = "E15", *,
              normalization: str = "3d", engine: str = "auto", workers: int = 1,
              cache_dir: str | os.PathLike | None = None, use_cache: bool = True) -> FrameIndex:
        """Index a dataset (a TakeSet, a MotionDatabase, or a ``data`` config as everywhere), reading the
        features (and PCA) from the cache when they are there and writing them there otherwise.

        A damaged cache file is rebuilt with a :class:`~stylemotion.datasets.loading.CacheWarning`.
        """
        database = _as_database(data)
        spec = feature_spec(feature_set)
        if engine not in ENGINES:
            raise ValueError(f"unknown search engine {engine!r}; valid: {list(ENGINES)}")
        requested, engine = engine, auto_engine(spec.dim) if engine == "auto" else engine
        path = _cache_path(Path(cache_dir) if cache_dir is not None else default_cache_dir(), database,
                           feature_set, normalization)
        cached = _read_or_discard(path, database.num_frames, spec.dim) if use_cache and path.exists() else None
        if cached is not None:
            state_path = _state_path(path, engine)
            state = _read_state(state_path) if engine in STORED_ENGINES and state_path.exists() else None
            index = _with_state(cls, database, feature_set, cached, normalization, engine, workers, state, state_path)
        else:
            features, fitted = database_features(database, feature_set, normalization)
            index = cls(database, feature_set, features, fitted, normalization=normalization, engine=engine,
                        workers=workers)
            if use_cache:
                meta = {"format": SEARCH_FORMAT, "dataset": database.name, "digest": database.digest,
                        "features": feature_set, "normalization": normalization}
                _write_or_warn(path, features, fitted, meta)
        if use_cache and engine in STORED_ENGINES and not _state_path(path, engine).exists():
            _write_state(_state_path(path, engine), index.engine_state())
        index.cache_path, index.from_cache = (path if use_cache else None), cached is not None
        index.requested_engine = requested
        return index

    def set_breadth(self, breadth: int) -> None:
        """How widely an approximate engine searches from now on: HNSW's ``efSearch`` (raised to k when k is
        larger; default :data:`HNSW_EF_SEARCH`) or IVF's ``nprobe`` (cells scanned, capped at the cells there are;
        default :data:`IVF_NPROBE`). More breadth, more recall and more time. ValueError for an exact engine."""
        if self.engine not in APPROXIMATE_ENGINES:
            raise ValueError(f"engine {self.engine!r} is exact: it has no search breadth")
        self._engine.breadth = _check_count(breadth, "breadth")

    @property
    def dim(self) -> int:
        return int(self.features.shape[1])

    @property
    def size(self) -> int:
        return int(self.features.shape[0])

    def query(self, queries: np.ndarray, k: int = 1, *, eps: float = 0.0,
              radius: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The ``k`` nearest frames of each query.

        Args:
            queries: ``(d,)`` one feature vector or ``(m, d)`` a batch.
            k: neighbours per query, 1 ≤ k ≤ database size.
            eps: approximation (ε ≥ 0): each returned distance is within ``(1 + ε)`` of the true one.
            radius: if given, only neighbours at distance ≤ radius (at most k of them); missing ones are
                padded with distance ``inf`` and index ``-1``.

        Returns:
            distances ``(m, k)`` float64 (or ``(k,)``), ascending, and global frame indices ``(m, k)``
            int64 (or ``(k,)``) into :attr:`database`.
        """
        x, single = self._check_queries(queries)
        k = _check_count(k, "k")
        if k > self.size:
            raise ValueError(f"k={k} exceeds the database size of {self.size} frames")
        if not np.isfinite(eps) or eps < 0:
            raise ValueError(f"eps must be a finite number ≥ 0, got {eps!r}")
        if radius is not None and not (np.isfinite(radius) and radius > 0):
            raise ValueError(f"radius must be a positive finite number or None, got {radius!r}")
        bound = np.inf if radius is None else float(np.nextafter(radius, np.inf))
        distances, indices = self._engine.query(x, k, float(eps), bound)
        missing = (indices < 0) | (indices >= self.size) | ~np.isfinite(distances)
        if radius is not None:
            missing |= distances > radius
        distances, indices = np.where(missing, np.inf, distances), np.where(missing, -1, indices)
        return (distances[0], indices[0]) if single else (distances, indices)

    def _check_queries(self, queries: np.ndarray) -> tuple[np.ndarray, bool]:
        x = np.asarray(queries, dtype=np.float32)
        single = x.ndim == 1
        x = x[None, :] if single else x
        if x.ndim != 2 or x.shape[1] != self.dim:
            raise ValueError(f"queries must be ({self.dim},) or (m, {self.dim}) for {self.feature_set}, "
                             f"got {np.shape(queries)}")
        if not np.all(np.isfinite(x)):
            raise ValueError("queries contain NaN or infinite values")
        return np.ascontiguousarray(x), single

    def features_of(self, positions: np.ndarray) -> np.ndarray:
        """``(frames, d)`` features of a query motion ``(frames, 21, 3)`` at the database's fps, made like the
        database's (same normalization and PCA); ValueError if it is shorter than the set's window."""
        return compute_features(self.feature_set, positions, self.database.fps, self.fitted, self.normalization)

    def query_positions(self, positions: np.ndarray, k: int = 1, **options: Any) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`query` for every frame of a query motion ``(frames, 21, 3)`` → ``(frames, k)`` each."""
        return self.query(self.features_of(positions), k, **options)

    def locate(self, global_index: int) -> FrameLocation:
        """``(take, frame, content, style)`` of a hit (see :meth:`MotionDatabase.locate`)."""
        return self.database.locate(global_index)


def _read_or_discard(path: Path, frames: int, dim: int) -> tuple[np.ndarray, FittedPCA | None] | None:
    try:
        return _read_features(path, frames, dim)
    except Exception as exc:  # noqa: BLE001 - any damage to the file means: rebuild it
        warnings.warn(f"{path}: corrupt search index cache ({type(exc).__name__}: {exc}); rebuilding it",
                      CacheWarning, stacklevel=3)
        path.unlink(missing_ok=True)
        return None


def _state_path(path: Path, engine: str) -> Path:
    return path.with_name(f"{path.stem}-{engine}-m{HNSW_M}.npz")


def _read_state(path: Path) -> np.ndarray | None:
    """A stored engine index, or None (with a CacheWarning, the file removed) when it is damaged."""
    try:
        with np.load(path, allow_pickle=False) as npz:
            state, crc = np.asarray(npz["state"]), int(npz["crc32"])
        if state.dtype != np.uint8 or state.ndim != 1 or zlib.crc32(state) != crc:
            raise ValueError("the stored bytes do not match their CRC")
        return state
    except Exception as exc:  # noqa: BLE001 - any damage means: rebuild it
        warnings.warn(f"{path}: corrupt stored search engine ({type(exc).__name__}: {exc}); rebuilding it",
                      CacheWarning, stacklevel=3)
        path.unlink(missing_ok=True)
        return None


def _write_state(path: Path, state: np.ndarray | None) -> None:
    if state is None:
        return
    buffer = io.BytesIO()
    np.savez(buffer, state=state, crc32=np.array(zlib.crc32(state), dtype=np.int64))
    try:
        atomic_write_bytes(path, buffer.getvalue())
    except OSError as exc:
        warnings.warn(f"{path}: cannot store the search engine ({exc}); it is rebuilt next time",
                      CacheWarning, stacklevel=3)


def _with_state(cls: type[FrameIndex], database: MotionDatabase, feature_set: str,
                cached: tuple[np.ndarray, FittedPCA | None], normalization: str, engine: str, workers: int,
                state: np.ndarray | None, state_path: Path) -> FrameIndex:
    """The index from cached features and, when it loads, the stored engine (else built anew)."""
    if state is not None:
        try:
            return cls(database, feature_set, cached[0], cached[1], normalization=normalization, engine=engine,
                       workers=workers, engine_state=state)
        except (RuntimeError, ValueError) as exc:
            warnings.warn(f"{state_path}: stored search engine does not load ({exc}); rebuilding it",
                          CacheWarning, stacklevel=4)
            state_path.unlink(missing_ok=True)
    return cls(database, feature_set, cached[0], cached[1], normalization=normalization, engine=engine,
               workers=workers)


def _write_or_warn(path: Path, features: np.ndarray, fitted: FittedPCA | None, meta: dict[str, Any]) -> None:
    try:
        _write_features(path, features, fitted, meta)
    except OSError as exc:
        warnings.warn(f"{path}: cannot write the search index cache ({exc}); the index is built but not cached",
                      CacheWarning, stacklevel=3)
