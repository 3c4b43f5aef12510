"""The report folder of an evaluation: ``report.md``, ``report.json``, one CSV per table, PNG figures.

``report.html`` is the same report as a web page with the figures and samples in the viewer; ``tensorboard/``
holds the figures, settings and headline numbers as TensorBoard events. The layout of
``report.json`` (Table 5.1 under ``table_5_1.<primitive>``, Tables 5.2/5.3 under
``variance``/``variance_ratio``, the extra metrics, ``meta`` with provenance, ``definitions`` of
every number) is specified in ``docs/report.md``. The folder is built beside its final place and
renamed into it, so a report is never half written; an existing folder is refused unless
``force`` (then replaced as a whole).
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from stylemotion.evaluation.figures import write_figures
from stylemotion.evaluation.markdown import DEFINITIONS, format_markdown
from stylemotion.evaluation.pipeline import VARIATION_KEYS
from stylemotion.evaluation.tables import VARIANCE_KEYS
from stylemotion.io.atomic import atomic_folder
from stylemotion.io.jsonfile import write_json
from stylemotion.io.outputs import check_new_output, inside
from stylemotion.viz.tensorboard import write_report_events


def write_report(results: dict[str, Any], out: str | os.PathLike, force: bool = False,
                 samples: Mapping[str, Any] | None = None) -> Path:
    """Write the report folder of ``results`` (from :func:`stylemotion.evaluation.pipeline.evaluate_models`
    plus ``meta``) atomically; returns its path. ``report.html`` (:mod:`stylemotion.evaluation.html_report`) shows the
    tables, the figures and, when ``samples`` maps ``<primitive> <model>`` to its MotionSamples, a few of
    them in the viewer."""
    out = check_new_output(out, force)
    results = {**results, "definitions": DEFINITIONS}
    # checked again at swap time: the folder may have appeared meanwhile
    with atomic_folder(out, on_exists=lambda: check_new_output(out, force)) as tmp:
        figures = write_figures(results, tmp)
        write_report_events(tmp, results, figures)
        tables = write_csvs(results, tmp)
        write_json(tmp / "report.json", results)
        text = format_markdown(results, figures, tables)
        (tmp / "report.md").write_text(text)
        from stylemotion.evaluation.html_report import write_report_html  # Python-Markdown, only when writing

        write_report_html(tmp, text, figures, samples)
    return out


def _csv_text(header: list[str], rows: list[list[Any]]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([["" if v is None else v for v in r] for r in rows])
    return buf.getvalue()


# -- CSVs


def write_csvs(results: dict[str, Any], folder: Path) -> list[str]:
    written = []

    def put(name: str, header: list[str], rows: list[list[Any]]) -> None:
        inside(folder, name).write_text(_csv_text(header, rows))  # names hold primitive names from checkpoints
        written.append(name)

    for p, t in results.get("table_5_1", {}).items():
        put(f"table_5_1_{p}.csv", ["model \\ example"] + t["examples"],
            [[m] + row for m, row in zip(t["models"], t["distance"])]
            + [[m] + row for m, row in t.get("extra_rows", {}).items()])
    for p, rows in results.get("variance", {}).items():
        ratio = results["variance_ratio"][p]
        body = [["model", r] + [s[k] for k in VARIANCE_KEYS] + [ratio[r][k] for k in VARIANCE_KEYS]
                + [s["speed_mean_mps"], s["step_mean_cm"], s["motions"]] for r, s in rows.items()]
        body += [["real", st] + [s[k] for k in VARIANCE_KEYS] + [""] * 3 + [s["speed_mean_mps"], s["step_mean_cm"],
                                                                            s["motions"]]
                 for st, s in results.get("variance_real", {}).get(p, {}).items()]
        put(f"variance_{p}.csv", ["kind", "row", "pose_sd_cm", "v_sd", "step_sd_cm", "pose_sd_ratio", "v_sd_ratio",
                                  "step_sd_ratio", "speed_mean_mps", "step_mean_cm", "motions"], body)
    body = [[p, m] + [r[k] for k in VARIATION_KEYS] for p, models in results.get("variation_vs_style", {}).items()
            for m, r in models.items()]
    if body:
        put("variation_vs_style.csv", ["primitive", "model"] + [f"{k}_ratio" for k in VARIATION_KEYS], body)
    rec = results.get("style_recognition", {})
    for p, c in rec.get("per_primitive", {}).items():
        put(f"classifier_confusion_{p}.csv", ["true \\ predicted"] + c["styles"],
            [[s] + row for s, row in zip(c["styles"], c["confusion"])])
    rows = []
    for p, models in rec.get("per_model_detail", {}).items():
        for m, d in models.items():
            rows.append([p, m, d["target_style"], d["share"], d["real_share"], d["samples"]]
                        + [d["predicted"][s] for s in rec["per_primitive"][p]["styles"]])
    if rows:
        styles = next(iter(rec["per_primitive"].values()))["styles"]
        put("style_recognition.csv", ["primitive", "model", "target_style", "share", "real_ground_truth_share",
                                      "samples"] + [f"predicted_{s}" for s in styles], rows)
    ref, div = results.get("frechet_reference", {}), results.get("diversity", {})
    rows = [[p, m, fd, ref[p][m].get("neutral_samples"), ref[p][m].get("real_floor"), ref[p][m]["ground_truth_clips"],
             div[p][m]["samples"], div[p][m]["real"]]
            for p, ms in results.get("frechet", {}).items() for m, fd in ms.items()]
    if rows:
        put("frechet_diversity.csv", ["primitive", "model", "frechet", "frechet_neutral_samples", "frechet_real_floor",
                                      "ground_truth_clips", "diversity_samples", "diversity_real"], rows)
    keys = ["ratio", "contact_share", "no_plant_share", "planted_mid_mps", "motions"]
    rows = [[p, m, kind] + [d[kind][k] for k in keys]
            for p, ms in results.get("foot_skating_detail", {}).items() for m, d in ms.items()
            for kind in ("samples", "real")]
    if rows:
        put("foot_skating.csv", ["primitive", "model", "motions_of"] + keys, rows)
    keys = ["travel_ratio", "foot_drift_m", "root_speed_mps", "duration_s", "root_travel_m", "leg_travel_m", "motions"]
    rows = [[p, m, kind] + [d[kind][k] for k in keys]
            for p, ms in results.get("stance_travel", {}).items() for m, d in ms.items()
            for kind in ("samples", "real")]
    if rows:
        put("stance_travel.csv", ["primitive", "model", "motions_of"] + keys, rows)
    keys = ["samples_median_m", "heldout_neutral_median_m", "ground_truth_median_m", "to_example_median_m",
            "ground_truth_to_example_median_m", "training_clips"]
    rows = [[p, m] + [d.get(k) for k in keys] for p, ms in results.get("nearest_training", {}).items()
            for m, d in ms.items()]
    if rows:
        put("nearest_training.csv", ["primitive", "model"] + keys, rows)
    return written
