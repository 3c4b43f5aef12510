"""Suite ``engines`` (scripts/suites/engines.py): its recall and rule helpers against hand-worked cases, and a
``--quick`` run on synthetic data whose results (not timings) and render are checked."""

from __future__ import annotations

import argparse
import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from stylemotion.search import AUTO_ENGINES, EXACT_ENGINES

ROOT = Path(__file__).resolve().parents[2]
HAVE_FAISS = importlib.util.find_spec("faiss") is not None


@pytest.fixture(scope="module")
def suite():
    sys.path.insert(0, str(ROOT / "scripts"))  # the suite imports suites.common and bench_search, as the runner does
    spec = importlib.util.spec_from_file_location("suites.engines", ROOT / "scripts" / "suites" / "engines.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def test_recall_counts_frames_within_the_exact_kth_distance(suite):
    returned = np.array([[0.1, 0.2, 0.3], [0.1, 0.5, np.inf]])
    kth = np.array([0.3, 0.4])  # row 0: the third ties with the true third; row 1: 0.5 is too far, inf is missing
    assert suite.recall_at(returned, kth) == pytest.approx(4 / 6)
    features = np.array([[0.0, 0.0], [3.0, 4.0]], dtype=np.float32)
    d = suite.true_distances(features, np.zeros((1, 2), np.float32), np.array([[1, 0, -1]]))
    np.testing.assert_array_equal(d, [[5.0, 0.0, np.inf]])


@pytest.mark.parametrize("times, candidates, want", [
    # one engine faster up to 45 dimensions, another above: the rule's limit is 45
    ([{"ckdtree": 0.1, "ckdtree-pca": 0.2, "faiss": 1.0}, {"ckdtree": 0.3, "ckdtree-pca": 0.4, "faiss": 1.0},
      {"ckdtree": 2.0, "ckdtree-pca": 0.5, "faiss": 1.0}], ("ckdtree", "ckdtree-pca"),
     {"limit": 45, "low": "ckdtree", "high": "ckdtree-pca", "per_set": ["ckdtree", "ckdtree", "ckdtree-pca"]}),
    # the fastest engine (pykdtree) is no candidate: the closest candidate rule, one engine for all
    ([{"ckdtree": 0.2, "pykdtree": 0.1, "faiss": 1.0}, {"ckdtree": 0.4, "pykdtree": 0.3, "faiss": 1.0},
      {"ckdtree": 0.4, "pykdtree": 0.3, "faiss": 1.0}], ("ckdtree", "faiss"),
     {"limit": None, "low": "ckdtree", "high": "ckdtree", "per_set": ["ckdtree"] * 3}),
    ([{"ckdtree": 2.0, "faiss": 1.0}, {"ckdtree": 2.0, "faiss": 1.0}, {"ckdtree": 2.0, "faiss": 1.0}],
     ("ckdtree", "faiss"), {"limit": None, "low": "faiss", "high": "faiss", "per_set": ["faiss"] * 3}),
    # a candidate not measured on some set is never chosen for it
    ([{"ckdtree": 1.0}, {"ckdtree": 1.0, "ckdtree-pca": 0.5}, {"ckdtree": 1.0, "ckdtree-pca": 0.5}],
     ("ckdtree", "ckdtree-pca"), {"limit": 15, "low": "ckdtree", "high": "ckdtree-pca",
                                  "per_set": ["ckdtree", "ckdtree-pca", "ckdtree-pca"]}),
])
def test_the_implied_rule(suite, times, candidates, want):
    got = suite.implied_rule([15, 45, 75], times, candidates)
    assert {key: got[key] for key in want} == want
    fastest = [min(t.values()) for t in times]
    logs = [math.log(t[e] / f) for t, e, f in zip(times, want["per_set"], fastest)]
    assert got["geomean"] == pytest.approx(math.exp(sum(logs) / len(logs)))


def test_the_rounds_are_chosen_with_the_rule_they_imply(suite):
    # rounds "a" make ckdtree-pca fastest on the two wide sets; "b" is faster on the narrow set, where cKDTree is
    # faster still (so "b"'s gain there does not count), and slower on the wide ones
    kd = [0.1, 1.0, 1.0]
    pca = [{"a": 0.5, "b": 0.2}, {"a": 0.3, "b": 0.4}, {"a": 0.3, "b": 0.4}]
    label, rule = suite.choose_fetch([15, 75, 90], kd, pca)
    assert label == "a" and rule["limit"] == 15 and rule["per_set"] == ["ckdtree", "ckdtree-pca", "ckdtree-pca"]
    label, _ = suite.choose_fetch([15, 75, 90], kd, [{"a": 0.5, "b": 0.5}, {"a": 0.3, "b": 0.3}, {"a": 0.3, "b": 0.3}])
    assert label == "a"  # a tie: the earlier candidate
    assert suite.fetch_label((8, 2, 128)) == "8/2/128"


def test_clips_lie_inside_their_takes_and_follow_the_seed(suite):
    class Take:
        def __init__(self, n):
            self.num_frames = n

    takes = [Take(10), Take(40), Take(5)]
    clips = suite.choose_clips(takes, 20, 8, [0, 1])
    assert len(clips) == 40 and all(takes[t].num_frames >= s + 8 and t != 2 for t, s in clips)
    assert clips == suite.choose_clips(takes, 20, 8, [0, 1]) and clips[:20] != clips[20:]
    with pytest.raises(ValueError, match="no test take has 50 frames"):
        suite.choose_clips(takes, 1, 50, [0])


@pytest.mark.skipif(not HAVE_FAISS, reason="faiss-cpu not installed (extra 'search')")
def test_a_quick_run_on_synthetic_data_and_its_render(suite):
    parser = argparse.ArgumentParser()
    suite.add_arguments(parser)
    args = parser.parse_args(["--data", "synthetic", "--quick", "--features", "E15", "E15x5",
                              "--scale-frames", "20000"])
    r = suite.run(args, [0])
    assert r["quick"] and r["splits"]["takes"]["test"] > 0 and r["frames"] > 0
    assert [row["features"] for row in r["sets"]] == ["E15", "E15x5"]
    for row in r["sets"]:
        assert set(row["engines"]) == set(suite.MEASURED_ENGINES)
        assert row["auto"] == next(e for limit, e in AUTO_ENGINES if row["dim"] <= limit)
        for engine, v in row["engines"].items():
            assert v["1"]["batched"]["n"] == r["clips"] and v["1"]["single"]["n"] == r["clips"] * r["single_per_clip"]
            assert v["build_s"] >= 0 and v["1"]["batched"]["p50"] > 0
            assert v["1"]["batched"]["mean"] > 0
            if engine.startswith("faiss"):  # a faiss index holds every vector as float32 (HNSW and IVF add more)
                assert v["index_mb"] * 2**20 >= r["frames"] * row["dim"] * 4
            else:
                assert v["index_mb"] is None
            if engine in EXACT_ENGINES:  # exact: every frame within the exact 16th distance, the same distances
                assert v["recall"] == 1.0 and v["max_distance_error"] < 1e-4, (row["features"], engine, v)
        ivf = row["breadths"]["faiss-ivf"]  # more cells scanned: a superset of candidates, never less recall
        assert [b["breadth"] for b in ivf] == sorted(b["breadth"] for b in ivf)
        assert all(a["recall"] <= b["recall"] for a, b in zip(ivf, ivf[1:]))
        assert sum(b["default"] for b in ivf) == 1 and sum(b["default"] for b in row["breadths"]["faiss-hnsw"]) == 1
    v = r["validation"]  # the choices: val clips against the train takes, every candidate exact
    assert v["frames"] < r["frames"] and v["clips"] > 0 and v["candidates"] == [suite.fetch_label(f) for f in
                                                                                 suite.FETCH_CANDIDATES]
    assert v["fetch"] in v["candidates"] and [row["features"] for row in v["sets"]] == ["E15", "E15x5"]
    for row in v["sets"]:
        assert max(row["max_distance_error"].values()) < 1e-9
        assert row["ckdtree"]["n"] == v["clips"] and all(x["n"] == v["clips"] for x in row["ckdtree-pca"].values())
    assert r["splits"]["choice"].startswith("train-take database, val-take")
    scale = r["scale"]
    assert scale["frames"] >= 20000 and [s["features"] for s in scale["sets"]] == ["E15"]
    assert all(v["recall"] == 1.0 for e, v in scale["sets"][0]["engines"].items() if e in EXACT_ENGINES)
    record = {"command": "python scripts/benchmarks.py run engines --quick", "commit": "abc",
              "started": "2026-12-04T00:00", "seeds": [0], "results": r}
    blocks = suite.render(record)
    assert set(blocks) == {"summary", "headline", "table", "choice", "validation", "approximate", "scale"}
    assert all("Quick smoke run" in b for b in blocks.values())
    assert all(f"{row['auto']} ← auto" in blocks["table"] for row in r["sets"])
    assert "Measured rule" in blocks["choice"] and "Library (`AUTO_ENGINES`" in blocks["choice"]
    assert f"**{v['fetch']}**" in blocks["validation"] and "**val**" in blocks["validation"]
    assert "Not run" in suite.render({**record, "results": {**r, "scale": None, "quick": False}})["scale"]
    assert "Not run" in suite.render({**record, "results": {**r, "validation": None}})["validation"]
