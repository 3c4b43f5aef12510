"""``report.html`` of an evaluation: ``report.md`` as HTML, the figures, the thesis' Tables 5.2/5.3 and the viewer.

The tables and the comparison with the thesis are those of ``report.md``
(:func:`stylemotion.evaluation.markdown.format_markdown`), rendered by Python-Markdown, so the two files
never disagree; the figures are the PNGs beside it; the thesis' own Tables 5.2/5.3
(:data:`stylemotion.evaluation.markdown.THESIS`) are printed next to them; and a few samples of every
model play in the viewer (``viewer/``, :func:`stylemotion.viewer.page.build_viewer`) embedded in the page.
"""

from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import markdown

from stylemotion.evaluation.markdown import THESIS
from stylemotion.evaluation.tables import VARIANCE_KEYS
from stylemotion.viewer.motions import ViewerMotion, samples_to_motions
from stylemotion.viewer.page import build_viewer

#: Samples of each model shown in the report's viewer.
SAMPLES_PER_MODEL = 3
VIEWER_FOLDER = "viewer"

_STYLE = """
body { font: 15px/1.45 system-ui, sans-serif; max-width: 1150px; margin: 1.5em auto; padding: 0 1em; color: #222; }
table { border-collapse: collapse; margin: 0.6em 0 1.2em; font-size: 13px; }
th, td { border: 1px solid #ccc; padding: 0.2em 0.5em; text-align: right; }
th:first-child, td:first-child { text-align: left; }
thead th { background: #f0f0f0; }
img { max-width: 100%; }
code { background: #f4f4f4; padding: 0 0.2em; }
pre { background: #f4f4f4; padding: 0.6em; overflow-x: auto; }
iframe { width: 100%; height: 640px; border: 1px solid #ccc; }
nav a { margin-right: 1em; }
"""


def thesis_variance_markdown() -> str:
    """The thesis' Tables 5.2 (left stance) and 5.3 (right stance) as Markdown tables."""
    out = ["## The thesis' Tables 5.2/5.3", "",
           "Du's values (their styles: proud, depressed, angry, female, childlike, old; pose_SD in cm, V_SD, "
           "step_SD in cm), for comparison with the tables above.", ""]
    for primitive, rows in THESIS["variance"].items():
        out += [f"### {primitive}", "", "| row | " + " | ".join(VARIANCE_KEYS) + " |",
                "|---|" + "---|" * len(VARIANCE_KEYS)]
        out += [f"| {name} | " + " | ".join(f"{v:.4f}" for v in values) + " |" for name, values in rows.items()]
        out.append("")
    return "\n".join(out)


def _to_html(text: str) -> str:
    # labels in the report come from data and checkpoints: no raw HTML passes through
    return markdown.markdown(text.replace("<", "&lt;"), extensions=["tables", "fenced_code"])


def viewer_motions(samples: Mapping[str, Any], per_model: int = SAMPLES_PER_MODEL) -> list[ViewerMotion]:
    """The first ``per_model`` samples of each model; ``samples`` maps a label to
    :class:`~stylemotion.models.sampling.MotionSamples`."""
    motions: list[ViewerMotion] = []
    for label, s in samples.items():
        motions += samples_to_motions(s.positions.numpy(), s.num_frames.numpy().tolist(), float(s.fps), label,
                                      per_model)
    return motions


def write_report_html(folder: Path, report_md: str, figures: Sequence[str],
                      samples: Mapping[str, Any] | None = None, per_model: int = SAMPLES_PER_MODEL) -> Path:
    """Write ``report.html`` (and ``viewer/`` when ``samples`` are given) into the report ``folder``.

    Args:
        folder: the report folder being built (its PNG ``figures`` already written).
        report_md: the text of ``report.md``.
        figures: file names of the figures in ``folder``.
        samples: label (``<primitive> <model>``) → that model's samples, or None for no viewer.
    """
    body = _to_html(report_md)
    missing = [f for f in figures if f'src="{html.escape(f)}"' not in body]
    parts = [body, _to_html(thesis_variance_markdown())]
    if missing:
        parts.append("<h2>Figures</h2>" + "".join(f'<p><img src="{html.escape(f)}" alt="{html.escape(f)}"></p>'
                                                  for f in missing))
    nav = ['<a href="#samples">samples in the viewer</a>'] if samples else []
    if samples:
        motions = viewer_motions(samples, per_model)
        build_viewer(motions, folder / VIEWER_FOLDER, title=f"{per_model} samples of each model")
        parts.append(f'<h2 id="samples">Samples in the viewer</h2><p>{per_model} samples of each of the '
                     f'{len(samples)} models (colour = model; drag to orbit). Open '
                     f'<a href="{VIEWER_FOLDER}/index.html">the viewer</a> on its own for a larger view.</p>'
                     f'<iframe src="{VIEWER_FOLDER}/index.html" title="samples"></iframe>')
    page = ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>Evaluation report</title>"
            f"<style>{_STYLE}</style></head><body><nav>{''.join(nav)}<a href=\"report.md\">report.md</a>"
            f"<a href=\"report.json\">report.json</a></nav>\n" + "\n".join(parts) + "\n</body></html>\n")
    path = folder / "report.html"
    path.write_text(page)
    return path
