"""Regression on a fixed slice of real data: Bandai's normal walks, split as the data config splits them; 1 s
queries cut from the validation takes against the train takes. At the default k the LNG must answer every
query and return exact DTW's best segment for at least the share the default was chosen to reach on validation
queries (SAME_SEGMENT_AIM of scripts/suites/search.py, 95 %), and never cost less than DTW."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import BANDAI_ZIP, shared_data_dir

from stylemotion.datasets.base import TakeSet
from stylemotion.datasets.registry import load_dataset
from stylemotion.search import DEFAULT_K, FrameIndex
from stylemotion.search.evaluation import compare_lng_dtw, random_segments, summarize_lng

AIM = 0.95  # the validation aim behind DEFAULT_K (benchmarks/search.md, "Choosing k")


@pytest.mark.realdata
def test_lng_answers_and_agrees_with_dtw_on_validation_walks(tmp_path):
    root = shared_data_dir(BANDAI_ZIP) / BANDAI_ZIP
    walks = load_dataset("bandai", root=root, contents=["walk"], styles=["normal"], cache_dir=tmp_path / "data",
                         workers=1)
    split = walks.split(seed=0, val_fraction=0.1, test_fraction=0.1)
    assert split["val"] and not {t.name for t in split["val"]} & {t.name for t in split["train"]}
    index = FrameIndex.build(TakeSet("train", split["train"], walks.fps), "E15", use_cache=False)
    k = min(DEFAULT_K, index.size)
    m = int(walks.fps)
    records = []
    for t, start in random_segments([take.num_frames for take in split["val"]], m, 8, np.random.default_rng(0)):
        features = index.features_of(split["val"][t].positions[start:start + m])
        records.append(compare_lng_dtw(features, index, index.database.take_bounds, [k]).record(k))
    summary = summarize_lng(records)
    assert summary["no_path"] == 0, summary
    assert summary["same_segment"] >= math.ceil(AIM * len(records)) / len(records), summary
    assert summary["lng_never_below_dtw"], summary
