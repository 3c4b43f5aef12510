"""The motion database and its k-NN frame index against numpy brute force (random features, and takes the
database does not hold), radius, ε, cache, bad input."""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path

import numpy as np
import pytest
from conftest import BANDAI_ZIP, shared_data_dir

from stylemotion.datasets.base import Take, TakeSet
from stylemotion.datasets.loading import CacheWarning
from stylemotion.datasets.registry import load_dataset
from stylemotion.representation import facing_yaw
from stylemotion.search import FrameIndex, MotionDatabase, compute_features
from stylemotion.search.index import (
    AUTO_ENGINES,
    AUTO_FALLBACK,
    EXACT_ENGINES,
    FLOAT64_ENGINES,
    SEARCH_FORMAT,
    auto_engine,
    faiss_available,
    index_cache_key,
    ivf_lists,
)

ENGINES_HERE = ["ckdtree", "ckdtree-pca"] + [e for e, module in (("pykdtree", "pykdtree"), ("faiss", "faiss"))
                              if importlib.util.find_spec(module) is not None]


@pytest.fixture(scope="module")
def takeset() -> TakeSet:
    return load_dataset("synthetic", takes_per_pair=1)


@pytest.fixture(scope="module")
def database(takeset) -> MotionDatabase:
    return MotionDatabase.from_takeset(takeset)


def brute_force(data: np.ndarray, queries: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Exact k-NN in float64 numpy: distances and indices ``(m, k)``, ties broken by index."""
    d = np.linalg.norm(queries[:, None, :].astype(np.float64) - data[None].astype(np.float64), axis=-1)
    order = np.argsort(d, axis=1, kind="stable")[:, :k]
    return np.take_along_axis(d, order, axis=1), order


def _check_exact(index: FrameIndex, queries: np.ndarray, k: int, engine: str) -> None:
    dist, idx = index.query(queries, k)
    true_d, true_i = brute_force(index.features, queries, k + 1)  # one more, to see ties at the k-th place
    after, true_d, true_i = true_d[:, k:], true_d[:, :k], true_i[:, :k]
    assert dist.shape == idx.shape == (len(queries), k)
    tol = 1e-12 if engine in FLOAT64_ENGINES else 1e-5  # float32 arithmetic in pykdtree / faiss
    np.testing.assert_allclose(dist, true_d, rtol=tol, atol=tol)
    # Every returned frame really lies at the returned distance (indices agree up to exact ties).
    own = np.linalg.norm(index.features[idx].astype(np.float64) - queries[:, None, :], axis=-1)
    np.testing.assert_allclose(own, dist, rtol=tol, atol=tol)
    # The same frames, except where several lie at the same distance (within the engine's arithmetic).
    band = tol * (1.0 + true_d)
    tied = np.zeros_like(true_d, dtype=bool)
    tied[:, 1:] |= true_d[:, 1:] - true_d[:, :-1] <= band[:, 1:]
    tied[:, :-1] |= true_d[:, 1:] - true_d[:, :-1] <= band[:, :-1]
    tied[:, -1] |= after[:, 0] - true_d[:, -1] <= band[:, -1]
    np.testing.assert_array_equal(idx[~tied], true_i[~tied])
    assert all(len(set(row)) == k for row in idx)  # no frame twice


@pytest.mark.parametrize("engine", ENGINES_HERE)
def test_exact_search_equals_brute_force_on_random_data(database, engine):
    rng = np.random.default_rng(0)
    features = rng.normal(size=(database.num_frames, 15)).astype(np.float32)
    index = FrameIndex(database, "E15", features, engine=engine)
    queries = rng.normal(size=(40, 15)).astype(np.float32)
    for k in (1, 5, 16):
        _check_exact(index, queries, k, engine)
    d1, i1 = index.query(queries[3], 5)  # a single query gives (k,) arrays, as row 3 of the batch
    d_batch, i_batch = index.query(queries, 5)
    assert d1.shape == i1.shape == (5,)
    np.testing.assert_array_equal(i1, i_batch[3])
    np.testing.assert_allclose(d1, d_batch[3])


def test_projected_engine_is_exact_where_the_projection_drops_dimensions(database):
    """``ckdtree-pca`` on features of low intrinsic dimension (its embedding drops most axes, so the filter
    matters) with duplicated rows: the same answers as numpy brute force; its embedding never lengthens a
    distance."""
    rng = np.random.default_rng(7)
    latent = rng.normal(size=(database.num_frames, 6)) * np.array([3.0, 2.0, 1.0, 0.5, 0.2, 0.1])
    features = (latent @ rng.normal(size=(6, 75)) + rng.normal(0, 0.01, (database.num_frames, 75))).astype(np.float32)
    features[1::5] = features[::5][:len(features[1::5])]
    index = FrameIndex(database, "E15x5", features, engine="ckdtree-pca")
    engine = index._engine
    assert engine.axes.shape[1] < 75  # the projection drops axes
    queries = np.concatenate([features[::53][:20] + rng.normal(0, 0.05, (20, 75)), features[::91][:10]])
    queries = queries.astype(np.float32)
    for k in (1, 16):
        _check_exact(index, queries, k, "ckdtree-pca")
    pairs = rng.choice(len(features), size=(500, 2))
    a, b = features[pairs[:, 0]], features[pairs[:, 1]]
    true = np.linalg.norm(a.astype(np.float64) - b, axis=1)
    embedded = np.linalg.norm(engine.embed(a) - engine.embed(b), axis=1)
    assert np.all(embedded <= true * (1 + 1e-12) + 1e-12) and np.mean(embedded / np.maximum(true, 1e-9)) > 0.5


@pytest.mark.parametrize("fetch", [(1, 2, 1), (8, 2, 128), (1, 2, 1 << 30)],
                         ids=["ball after one round", "default rounds", "rounds up to every frame"])
def test_projected_engine_is_exact_in_every_stage_of_its_multi_step_search(database, fetch):
    """``ckdtree-pca``'s multi-step k-NN settles a query in a fetch round or leaves it to the ball query; each path
    (forced by its ``fetch``) gives numpy brute force's answers, also within a radius and among duplicated rows."""
    rng = np.random.default_rng(11)
    latent = rng.normal(size=(database.num_frames, 4)) * np.array([2.0, 1.0, 0.5, 0.1])
    features = (latent @ rng.normal(size=(4, 75)) + rng.normal(0, 0.02, (database.num_frames, 75))).astype(np.float32)
    features[2::7] = features[::7][:len(features[2::7])]
    index = FrameIndex(database, "E15x5", features, engine="ckdtree-pca")
    index._engine.fetch = fetch
    far = rng.normal(0, 3.0, (5, 75))  # far from every frame: the embedding's bound is loose there
    queries = np.concatenate([features[::61][:15] + rng.normal(0, 0.05, (15, 75)), features[::97][:5], far])
    queries = queries.astype(np.float32)
    for k in (1, 16, 40):
        _check_exact(index, queries, k, "ckdtree-pca")
    true_d, true_i = brute_force(index.features, queries, 16)
    radius = float(np.median(true_d[:, 6]))
    dist, idx = index.query(queries, 16, radius=radius)
    inside = true_d <= radius
    np.testing.assert_allclose(dist[inside], true_d[inside], rtol=1e-12)
    assert np.all(np.isinf(dist[~inside])) and np.all(idx[~inside] == -1)


def test_projected_engine_answers_large_batches_in_slices_of_bounded_memory(database, monkeypatch):
    """A batch of queries larger than one pass may hold (a motion graph queries every frame) is answered in slices,
    with brute force's answers: the cap that kept suite fat_graph's 300k-frame batches from 24 GB."""
    import stylemotion.search.index as index_module

    rng = np.random.default_rng(3)
    features = (rng.normal(size=(database.num_frames, 3)) @ rng.normal(size=(3, 75))).astype(np.float32)
    features += rng.normal(0, 0.01, features.shape).astype(np.float32)
    index = FrameIndex(database, "E15x5", features, engine="ckdtree-pca")
    monkeypatch.setattr(index_module, "_FETCH_CELLS", 75 * 8 * 16 * 3)  # three queries per slice at the first fetch
    queries = features[::97][:40] + rng.normal(0, 0.02, (40, 75)).astype(np.float32)
    _check_exact(index, queries, 16, "ckdtree-pca")


@pytest.mark.parametrize("feature_set", ["E15", "E15x3", "pca8", "EP19"])
def test_exact_search_on_the_synthetic_dataset(takeset, feature_set):
    """A take the database does not hold, queried frame by frame: the same neighbours as numpy brute force."""
    held_out = takeset.takes[5]
    rest = TakeSet(takeset.name, [t for t in takeset.takes if t.name != held_out.name], takeset.fps)
    index = FrameIndex.build(rest, feature_set, use_cache=False)
    assert held_out.name not in index.database.take_names
    queries = index.features_of(held_out.positions.astype(np.float64))
    _check_exact(index, queries[::3].astype(np.float32), 16, "ckdtree")
    rng = np.random.default_rng(1)
    jittered = index.features[rng.choice(index.size, 50, replace=False)] + rng.normal(0, 0.01, (50, index.dim))
    _check_exact(index, jittered.astype(np.float32), 16, "ckdtree")


def test_radius_search_is_capped_at_k(database):
    rng = np.random.default_rng(2)
    features = rng.normal(size=(database.num_frames, 4)).astype(np.float32)
    index = FrameIndex(database, "pca8", np.concatenate([features, features], axis=1))
    queries = index.features[:30] + 0.05
    true_d, true_i = brute_force(index.features, queries, 16)
    radius = float(np.median(true_d[:, 8]))
    for engine in ENGINES_HERE:
        index = FrameIndex(database, "pca8", index.features, engine=engine)
        dist, idx = index.query(queries, 16, radius=radius)
        inside = true_d <= radius
        assert np.all((idx >= 0) == inside), engine
        assert np.all(np.isinf(dist[~inside])) and np.all(idx[~inside] == -1), engine
        np.testing.assert_allclose(dist[inside], true_d[inside], rtol=1e-5)
    assert 0 < inside.sum() < inside.size  # some queries capped at k, some padded


@pytest.mark.parametrize("engine", [e for e in ENGINES_HERE if e != "faiss"])
def test_eps_search_is_within_one_plus_eps(database, engine):
    rng = np.random.default_rng(3)
    features = rng.normal(size=(database.num_frames, 15)).astype(np.float32)
    index = FrameIndex(database, "E15", features, engine=engine)
    queries = rng.normal(size=(60, 15)).astype(np.float32)
    true_d, _ = brute_force(features, queries, 8)
    for eps in (0.1, 0.5, 2.0):
        dist, idx = index.query(queries, 8, eps=eps)
        assert np.all(idx >= 0)
        assert np.all(dist <= (1 + eps) * true_d * (1 + 1e-6)), eps
        own = np.linalg.norm(features[idx].astype(np.float64) - queries[:, None, :], axis=-1)
        np.testing.assert_allclose(own, dist, rtol=1e-5)


@pytest.mark.skipif(importlib.util.find_spec("faiss") is None, reason="faiss-cpu not installed (extra 'search')")
def test_hnsw_finds_most_true_neighbours(takeset):
    exact = FrameIndex.build(takeset, "E15", use_cache=False)
    approx = FrameIndex(exact.database, "E15", exact.features, engine="faiss-hnsw")
    queries = exact.features[::37] + 0.005
    _, true_i = exact.query(queries, 16)
    _, got = approx.query(queries, 16)
    recall = np.mean([len(set(a) & set(b)) / 16 for a, b in zip(got, true_i)])
    assert recall > 0.9


@pytest.mark.parametrize("dim", [8, 15, 45, 46, 75, 117])
def test_auto_equals_brute_force_with_ties(database, dim):
    """``engine="auto"`` answers exactly (numpy float64 brute force), on both sides of its dimension rule, with
    exact ties in the data: duplicated database rows and queries on database rows."""
    rng = np.random.default_rng(dim)
    features = rng.normal(size=(database.num_frames, dim)).astype(np.float32)
    features[1::7] = features[::7][:len(features[1::7])]  # every 7th row twice: ties at distance > 0 and 0
    index = FrameIndex(database, "custom", features)
    assert index.requested_engine == "auto"
    rule = next(engine for limit, engine in AUTO_ENGINES if dim <= limit)
    assert index.engine == (rule if importlib.util.find_spec("faiss") or rule != "faiss" else AUTO_FALLBACK)
    queries = np.concatenate([rng.normal(size=(30, dim)), features[::97][:20] + 0.0]).astype(np.float32)
    for k in (1, 16):
        _check_exact(index, queries, k, index.engine)


@pytest.mark.parametrize("feature_set", ["E15", "E15x5"])
def test_build_resolves_auto_per_feature_set(takeset, feature_set, tmp_path):
    index = FrameIndex.build(takeset, feature_set, cache_dir=tmp_path)
    again = FrameIndex.build(takeset, feature_set, cache_dir=tmp_path)  # from the cache: the same engine
    dim = {"E15": 15, "E15x5": 75}[feature_set]
    assert again.from_cache and index.requested_engine == again.requested_engine == "auto"
    assert index.engine == again.engine == auto_engine(dim) and index.dim == dim


def test_auto_rule_and_fallback(monkeypatch):
    limits = [limit for limit, _ in AUTO_ENGINES]
    assert limits == sorted(limits) and limits[-1] == np.inf  # every dimension has an engine
    assert all(engine in EXACT_ENGINES for _, engine in AUTO_ENGINES) and AUTO_FALLBACK in EXACT_ENGINES
    if faiss_available():
        for (limit, engine), (_, above) in zip(AUTO_ENGINES[:-1], AUTO_ENGINES[1:]):  # the rule's edges
            assert (auto_engine(int(limit)), auto_engine(int(limit) + 1)) == (engine, above)
    monkeypatch.setattr("stylemotion.search.index.faiss_available", lambda: False)
    assert "faiss" not in {auto_engine(d) for d in (1, 8, 15, 45, 75, 117, 10_000)}
    for bad in (0, -3, 2.5, True):
        with pytest.raises(ValueError, match="feature dimension"):
            auto_engine(bad)


def test_ivf_cells():
    assert [ivf_lists(n) for n in (1, 39, 40, 1_000, 384_931, 5_000_000)] == [1, 1, 1, 25, 2482, 8944]


@pytest.mark.skipif(importlib.util.find_spec("faiss") is None, reason="faiss-cpu not installed (extra 'search')")
def test_approximate_engines_breadth_and_recall(database):
    """IVF scanning every cell is exact; HNSW and IVF recall grows with the breadth; exact engines have none."""
    rng = np.random.default_rng(5)
    centres = rng.normal(size=(40, 12))
    features = (centres[rng.integers(0, 40, database.num_frames)]
                + 0.3 * rng.normal(size=(database.num_frames, 12))).astype(np.float32)
    queries = (features[rng.choice(len(features), 60, replace=False)] + 0.05 * rng.normal(size=(60, 12))
               ).astype(np.float32)
    true_d, _ = brute_force(features, queries, 16)

    def recall(index: FrameIndex) -> float:  # returned frames within the true 16th distance (tie-proof)
        _, idx = index.query(queries, 16)
        own = np.linalg.norm(features[idx].astype(np.float64) - queries[:, None, :], axis=-1)
        return float(np.mean(own <= true_d[:, -1:] * (1 + 1e-5)))

    ivf = FrameIndex(database, "custom", features, engine="faiss-ivf")
    assert ivf.engine == "faiss-ivf" and ivf._engine.index.nlist == ivf_lists(database.num_frames)
    ivf.set_breadth(1)
    narrow = recall(ivf)
    ivf.set_breadth(10**6)  # capped at the cells there are: every cell scanned, exact
    assert recall(ivf) == 1.0 > narrow
    _check_exact(ivf, queries, 16, "faiss-ivf")
    hnsw = FrameIndex(database, "custom", features, engine="faiss-hnsw")
    hnsw.set_breadth(1)  # raised to k
    assert recall(hnsw) > 0.5
    hnsw.set_breadth(400)
    assert recall(hnsw) >= 0.99
    for engine in ENGINES_HERE:
        with pytest.raises(ValueError, match="is exact: it has no search breadth"):
            FrameIndex(database, "custom", features, engine=engine).set_breadth(4)
    with pytest.raises(ValueError, match="breadth must be a whole number"):
        hnsw.set_breadth(0)


@pytest.mark.skipif(importlib.util.find_spec("faiss") is None, reason="faiss-cpu not installed (extra 'search')")
def test_hnsw_graph_is_stored_with_the_features(takeset, tmp_path):
    first = FrameIndex.build(takeset, "E15", engine="faiss-hnsw", cache_dir=tmp_path)
    stored = list((tmp_path / "search").glob("*-faiss-hnsw-*.npz"))
    assert len(stored) == 1
    second = FrameIndex.build(takeset, "E15", engine="faiss-hnsw", cache_dir=tmp_path)
    assert second.from_cache
    np.testing.assert_array_equal(second.engine_state(), first.engine_state())
    queries = first.features[::50] + 0.01
    np.testing.assert_array_equal(second.query(queries, 8)[1], first.query(queries, 8)[1])
    state = np.load(stored[0])["state"]
    np.savez(stored[0], state=state[::-1].copy(), crc32=np.array(0))
    with pytest.warns(CacheWarning, match="corrupt stored search engine"):
        third = FrameIndex.build(takeset, "E15", engine="faiss-hnsw", cache_dir=tmp_path)
    assert third.query(queries, 8)[1].shape == (len(queries), 8) and stored[0].exists()
    assert FrameIndex.build(takeset, "E15", cache_dir=tmp_path).engine_state() is None  # kd-trees: rebuilt


def test_database_locates_frames(takeset, database):
    assert database.num_frames == takeset.num_frames and database.num_takes == len(takeset)
    rng = np.random.default_rng(4)
    for g in rng.choice(database.num_frames, 50, replace=False):
        loc = database.locate(g)
        take = takeset.takes[database.take_names.index(loc.take)]
        assert (loc.content, loc.style) == (take.content, take.style)
        assert database.global_index(loc.take, loc.frame) == g
        np.testing.assert_array_equal(database.positions[g], take.positions[loc.frame])
    ends = database.take_start[1:] - 1
    assert not np.any(database.has_next(ends)) and database.has_next(0) is True
    assert database.has_next(int(database.take_start[1])) is True  # first frame of the second take
    assert database.next_in_take.sum() == database.num_frames - database.num_takes
    takes, frames = database.locate_many(np.array([[0, int(database.take_start[2]) + 3]]))
    assert takes.tolist() == [[0, 2]] and frames.tolist() == [[0, 3]]


def test_cache_is_reused_and_follows_the_data(takeset, tmp_path):
    first = FrameIndex.build(takeset, "pca8", cache_dir=tmp_path)
    assert not first.from_cache and first.cache_path.is_file() and first.cache_path.parent == tmp_path / "search"
    second = FrameIndex.build(takeset, "pca8", cache_dir=tmp_path)
    assert second.from_cache and second.cache_path == first.cache_path
    np.testing.assert_array_equal(second.features, first.features)
    np.testing.assert_array_equal(second.fitted.components, first.fitted.components)
    assert second.fitted.normalization == "3d"
    np.testing.assert_array_equal(second.query(first.features[:5], 3)[1], first.query(first.features[:5], 3)[1])
    # Another feature set, normalization or dataset content: another entry.
    assert not FrameIndex.build(takeset, "pca8", normalization="2d", cache_dir=tmp_path).from_cache
    changed = TakeSet(takeset.name, [Take(t.name, t.positions.copy(), t.fps, dict(t.labels)) for t in takeset.takes],
                      takeset.fps)
    changed.takes[3].positions[10, 4, 1] += 0.01
    third = FrameIndex.build(changed, "pca8", cache_dir=tmp_path)
    assert not third.from_cache and third.cache_path != first.cache_path
    relabelled = TakeSet(takeset.name, [Take(t.name, t.positions, t.fps, {**t.labels, "style": "other"})
                                        for t in takeset.takes], takeset.fps)
    assert index_cache_key(MotionDatabase.from_takeset(relabelled), "pca8", "3d") != \
        index_cache_key(first.database, "pca8", "3d")
    assert len(list((tmp_path / "search").glob("*.npz"))) == 3


def test_cache_key_changes_with_the_search_format(takeset, monkeypatch):
    database = MotionDatabase.from_takeset(takeset)
    key = index_cache_key(database, "EP17", "3d")
    monkeypatch.setattr("stylemotion.search.index.SEARCH_FORMAT", SEARCH_FORMAT + 1)
    assert index_cache_key(database, "EP17", "3d") != key


def test_damaged_cache_is_rebuilt(takeset, tmp_path):
    first = FrameIndex.build(takeset, "E15", cache_dir=tmp_path)
    first.cache_path.write_bytes(b"not an npz")
    with pytest.warns(CacheWarning, match="corrupt search index cache"):
        again = FrameIndex.build(takeset, "E15", cache_dir=tmp_path)
    assert not again.from_cache
    np.testing.assert_array_equal(again.features, first.features)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert FrameIndex.build(takeset, "E15", cache_dir=tmp_path).from_cache


def test_build_from_a_data_config(tmp_path):
    index = FrameIndex.build({"name": "synthetic", "takes_per_pair": 1, "contents": ["walk"]}, "E30",
                             cache_dir=tmp_path)
    assert index.database.name == "synthetic" and set(index.database.contents) == {"walk"}
    assert index.features.shape == (index.database.num_frames, 30)


def test_bad_input_is_named(takeset, database):
    index = FrameIndex(database, "E15", np.zeros((database.num_frames, 15), np.float32))
    q = np.zeros(15, np.float32)
    with pytest.raises(ValueError, match=f"k=99999 exceeds the database size of {database.num_frames} frames"):
        index.query(q, 99999)
    with pytest.raises(ValueError, match="k must be a whole number ≥ 1, got 0"):
        index.query(q, 0)
    with pytest.raises(ValueError, match="eps must be .* got -0.5"):
        index.query(q, 1, eps=-0.5)
    with pytest.raises(ValueError, match="radius must be .* got -1"):
        index.query(q, 1, radius=-1.0)
    with pytest.raises(ValueError, match=r"queries must be \(15,\) or \(m, 15\) for E15, got \(14,\)"):
        index.query(np.zeros(14), 1)
    with pytest.raises(ValueError, match="NaN"):
        index.query(np.full(15, np.nan), 1)
    with pytest.raises(ValueError, match="unknown search engine 'annoy'"):
        FrameIndex(database, "E15", index.features, engine="annoy")
    with pytest.raises(ValueError, match=r"features must be \(\d+, 30\) for E30"):
        FrameIndex(database, "E30", index.features)
    with pytest.raises(ValueError, match="unknown feature set 'E14'"):
        FrameIndex.build(takeset, "E14", use_cache=False)
    with pytest.raises(ValueError, match="'empty' has no takes"):
        MotionDatabase.from_takeset(TakeSet("empty", [], 30.0))
    with pytest.raises(IndexError, match=r"global frame index -1 out of range \[0, \d+\)"):
        database.locate(-1)
    with pytest.raises(IndexError, match="frame 9999 out of range for take"):
        database.global_index(0, 9999)
    with pytest.raises(KeyError, match="no take 'nope'"):
        database.take_index("nope")
    short = FrameIndex.build(takeset, "E15x5", use_cache=False)
    with pytest.raises(ValueError, match="needs at least 10 frames .* the query has 4"):
        short.query_positions(takeset.takes[0].positions[:4], 1)


@pytest.mark.realdata
def test_bandai_turns(tmp_path):
    """Real data: exact search on a few Bandai takes, and the angular momentum tells left from right turns."""
    root = shared_data_dir(BANDAI_ZIP) / BANDAI_ZIP
    ts = load_dataset("bandai", root=root, contents=["walk-turn-left", "walk-turn-right"], styles=["normal"],
                      cache_dir=tmp_path / "data", workers=1)
    assert {t.content for t in ts.takes} == {"walk-turn-left", "walk-turn-right"}
    index = FrameIndex.build(ts, "EP17", cache_dir=tmp_path)
    rng = np.random.default_rng(5)
    queries = index.features[rng.choice(index.size, 64, replace=False)] + rng.normal(0, 0.01, (64, 17))
    _check_exact(index, queries.astype(np.float32), 16, "ckdtree")
    assert FrameIndex.build(ts, "EP17", cache_dir=tmp_path).from_cache
    # A take's mean vertical angular momentum turns the way the take turns (positive: +Z towards +X, left):
    # compare with the net change of its facing, and with the labels.
    momentum = np.array([compute_features("EP17", t.positions, ts.fps)[:, 16].mean() for t in ts.takes])
    turned = np.array([np.diff(np.unwrap(facing_yaw(t.positions, ts.fps))).sum() for t in ts.takes])
    clear = np.abs(turned) > 0.5
    assert clear.mean() > 0.9 and np.mean(np.sign(momentum[clear]) == np.sign(turned[clear])) >= 0.95
    left = np.array([t.content == "walk-turn-left" for t in ts.takes])
    assert np.mean(momentum[left] > 0) >= 0.9 and np.mean(momentum[~left] < 0) >= 0.8


def test_cache_file_has_no_pickles(takeset, tmp_path):
    index = FrameIndex.build(takeset, "pca16", cache_dir=tmp_path)
    with np.load(Path(index.cache_path), allow_pickle=False) as npz:
        assert {"features", "meta", "pca_mean", "pca_components"} <= set(npz.files)
        assert all(npz[name].dtype != object for name in npz.files)
