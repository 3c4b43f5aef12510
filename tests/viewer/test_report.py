"""report.html beside an evaluation report: the tables with the thesis' values, the figures, the viewer."""

from __future__ import annotations

import json

from viewer_fixtures import synthetic_samples, tiny_results

from stylemotion.evaluation.report import write_report


def test_report_html_has_tables_thesis_figures_and_samples(tmp_path):
    results = tiny_results()
    samples = {"walk_leftStance neutral": synthetic_samples(("normal",) * 4, 1.5),
               "walk_leftStance elderly": synthetic_samples(("elderly",) * 4, 1.5)}
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
