"""The dataset summary lists what was skipped and what loaded but looks wrong."""

from __future__ import annotations

import json

import numpy as np

from stylemotion.datasets import load_dataset
from stylemotion.datasets.base import Take, TakeSet
from stylemotion.datasets.retarget import retarget_takeset
from stylemotion.datasets.summary import dataset_summary, format_summary, write_dataset_summary


def _takeset() -> TakeSet:
    takes = [Take(f"walk_normal_{i}", np.zeros((10 + i, 21, 3), np.float32), 30.0,
                  {"content": "walk", "style": "normal"}) for i in range(2)]
    return TakeSet("tiny", takes, 30.0, skipped=[("bad.bvh", "bad.bvh:3: no HIERARCHY")],
                   warnings=["odd.bvh: the body's height runs along Z but up_axis is y"])


def test_summary_counts_and_lists_skipped_and_warnings():
    summary = dataset_summary(_takeset())
    assert summary["takes"] == 2 and summary["frames"] == 21
    assert summary["per_content_style"] == [{"content": "walk", "style": "normal", "takes": 2, "frames": 21}]
    assert summary["skipped"] == [{"source": "bad.bvh", "reason": "bad.bvh:3: no HIERARCHY"}]
    assert summary["warnings"] == ["odd.bvh: the body's height runs along Z but up_axis is y"]
    text = format_summary(summary)
    assert "skipped 1 broken input(s)" in text and "bad.bvh:3: no HIERARCHY" in text
    assert "1 input(s) loaded but look wrong" in text and "odd.bvh" in text
    assert summary["retarget"] is None and "retargeted" not in text


def test_summary_records_the_skeleton_the_takes_were_retargeted_to():
    retargeted = retarget_takeset(load_dataset("synthetic", takes_per_pair=1, duration_s=1.0, contents=["walk"]),
                                  "elderly")
    summary = dataset_summary(retargeted)
    assert summary["retarget"] == retargeted.retarget and summary["retarget"]["style"] == "elderly"
    assert summary["retarget"]["takes"] == 1 and len(summary["retarget"]["bone_lengths_m"]) == 20
    thigh = summary["retarget"]["bone_lengths_m"]["LowerLeg_L"]
    assert f"retargeted: every take on the median bones of the 1 'elderly' takes (left thigh {thigh:.3f} m" \
        in format_summary(summary)


def test_write_dataset_summary_of_the_synthetic_data(tmp_path, monkeypatch):
    monkeypatch.setenv("STYLEMOTION_CACHE", str(tmp_path / "cache"))
    summary = write_dataset_summary({"name": "synthetic", "split": {"seed": 0}}, tmp_path / "out")
    written = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert written == summary
    assert written["provenance"]["stylemotion_version"] and written["provenance"]["git_commit"]
    assert written["dataset"] == "synthetic" and written["takes"] > 0
    assert sum(part["takes"] for part in written["split"].values()) == written["takes"]
