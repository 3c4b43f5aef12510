"""report.html beside an evaluation report: the tables with the thesis' values, the figures, the viewer."""

from __future__ import annotations

import json

import numpy as np
import torch
from viewer_fixtures import write_take_npz

from stylemotion.evaluation.report import write_report
from stylemotion.sampling import MotionSamples


def _samples(tmp_path, style: str) -> MotionSamples:
    pos = np.load(write_take_npz(tmp_path / f"{style}.npz", style, seconds=1.5))["positions"]
    pos = np.repeat(pos[None], 4, axis=0)
    n, frames = pos.shape[:2]
    return MotionSamples(torch.from_numpy(pos), torch.zeros(n, frames, 66), torch.full((n,), frames),
                         torch.full((n,), (frames - 1) / 30), torch.zeros(n, 1, 1), torch.zeros(n, 1, 66), 30.0)


def test_report_html_has_tables_thesis_figures_and_samples(tmp_path):
    styles = ["neutral", "elderly"]
    results = {
        "meta": {"data_name": "synthetic", "seed": 0, "samples": {"table_5_1": 4}},
        "table_5_1": {"walk_leftStance": {
            "models": styles, "examples": styles, "distance": [[0.1, 0.7], [0.9, 0.2]], "samples": 4,
            "diagonal": {"rows": styles, "columns": styles, "row_argmin": {"neutral": "neutral", "elderly": "elderly"},
                         "all_rows": True, "all_columns": True},
            "example_clips": {"neutral": "mean motion", "elderly": "take 3"}}},
    }
    samples = {"walk_leftStance neutral": _samples(tmp_path, "normal"),
               "walk_leftStance elderly": _samples(tmp_path, "elderly")}
    out = write_report(results, tmp_path / "report", samples=samples)
    page = (out / "report.html").read_text()
    assert "<table>" in page and "Table 5.1" in page and "<td><strong>0.1</strong></td>" in page
    assert "7 / 7" in page  # the thesis' Table 5.1 result beside ours
    assert "52.8613" in page and "45.5661" in page  # the thesis' Tables 5.2/5.3
    assert '<img alt="Table 5.1 walk_leftStance" src="table_5_1_walk_leftStance.png"' in page
    assert (out / "table_5_1_walk_leftStance.png").is_file()
    assert '<iframe src="viewer/index.html"' in page
    data = (out / "viewer" / "data.js").read_text()
    motions = json.loads(data[data.index("{"):data.rindex(";")])["motions"]
    assert len(motions) == 2 * 3 and {m["group"] for m in motions} == set(samples)
    assert "report.html" not in json.loads((out / "report.json").read_text())  # the JSON is unchanged


def test_report_html_escapes_labels(tmp_path):
    results = {"meta": {"data_name": "<script>alert(1)</script>", "seed": 0}}
    out = write_report(results, tmp_path / "report")
    page = (out / "report.html").read_text()
    assert "<script>" not in page and not (out / "viewer").exists()
