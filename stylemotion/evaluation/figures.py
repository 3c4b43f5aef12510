"""PNG figures of an evaluation report: Table 5.1 heatmaps, classifier confusion matrices and the
variance ratios. Every figure states the data, the seed, the sample count and the checkpoints in a
footer. Written through :class:`matplotlib.figure.Figure` (no pyplot: a notebook's backend is left alone).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from stylemotion.evaluation.tables import VARIANCE_KEYS
from stylemotion.io.outputs import inside


def _footer(results: dict[str, Any], samples: Any, primitive: str | None = None) -> str:
    meta = results.get("meta", {})
    ckpts = [c for c in meta.get("checkpoints", []) if primitive is None or c.get("primitive") == primitive]
    folders = sorted({str(Path(c["path"]).parent.parent) for c in ckpts if c.get("path")})
    where = (folders[0] if len(folders) == 1 else os.path.commonpath(folders)) if folders else "in-memory models"
    ae = meta.get("autoencoder") or {}
    return (f"data={meta.get('data_name', '?')}  seed={meta.get('seed', '?')}  N={samples}  "
            f"git {str(meta.get('git_commit', '?'))[:12]}\n"
            f"autoencoder {ae.get('path') or '?'} (weights {ae.get('fingerprint') or '?'})\n"
            f"{len(ckpts)} model checkpoint(s) under {where}")


def _heatmap(matrix: np.ndarray, rows: list[str], cols: list[str], title: str, footer: str, path: Path,
             integer: bool = False, xlabel: str = "", ylabel: str = "") -> None:
    """A matrix as a coloured grid with its values; the row minimum (counts: maximum) in bold, the
    diagonal boxed; ``footer`` (data, seed, samples, checkpoints) printed under it."""
    width = max(6.5, 0.8 * len(cols) + 3.0)
    fig = Figure(figsize=(width, width * 0.8 + 0.8))
    ax = fig.add_subplot(1, 1, 1)
    cmap = "Blues" if integer else "viridis_r"
    image = ax.imshow(matrix, cmap=cmap)
    fig.colorbar(image, ax=ax, fraction=0.046, pad=0.04)
    ax.set_xticks(range(len(cols)), cols, rotation=45, ha="right")
    ax.set_yticks(range(len(rows)), rows)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    best = matrix.argmax(1) if integer else matrix.argmin(1)
    lo, hi = float(matrix.min()), float(matrix.max())
    for i in range(len(rows)):
        for j in range(len(cols)):
            dark = (matrix[i, j] - lo) > 0.55 * (hi - lo) if hi > lo else False
            ax.text(j, i, f"{int(matrix[i, j])}" if integer else f"{matrix[i, j]:.3g}", ha="center", va="center",
                    fontsize=8, weight="bold" if j == best[i] else "normal", color="white" if dark else "black",
                    bbox={"boxstyle": "square,pad=0.15", "fill": False, "ec": "red", "lw": 1.2} if i == j else None)
    ax.set_title(title, fontsize=9)
    fig.text(0.01, 0.005, footer, fontsize=6, va="bottom")
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=110)


def _variance_plot(results: dict[str, Any], path: Path) -> None:
    prims = list(results["variance_ratio"])
    fig = Figure(figsize=(4.5 * len(prims) + 1, 4.2))
    for k, p in enumerate(prims):
        ax = fig.add_subplot(1, len(prims), k + 1)
        rows = [r for r in results["variance_ratio"][p] if r != "training_data"]
        x = np.arange(len(rows))
        for j, key in enumerate(VARIANCE_KEYS):
            ax.bar(x + (j - 1) * 0.27, [results["variance_ratio"][p][r][key] for r in rows], 0.27, label=key)
        ax.axhline(1.0, color="0.3", lw=0.8, ls="--")
        ax.set_xticks(x, rows, rotation=45, ha="right")
        ax.set_ylabel("SD / training data SD")
        ax.set_title(f"{p}: variance relative to training data", fontsize=9)
        ax.legend(fontsize=7)
    samples = results.get("meta", {}).get("samples", {}).get("variance", "?")
    fig.text(0.01, 0.005, _footer(results, samples), fontsize=6, va="bottom")
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(path, dpi=110)


def write_figures(results: dict[str, Any], folder: Path) -> list[str]:
    written = []
    for p, t in results.get("table_5_1", {}).items():
        name = f"table_5_1_{p}.png"
        _heatmap(np.asarray(t["distance"]), t["models"], t["examples"],
                 f"Table 5.1, {p}: D(model, example)\nbold = row minimum, red box = diagonal",
                 _footer(results, t["samples"], p), inside(folder, name), xlabel="style example", ylabel="model")
        written.append(name)
    for p, c in results.get("style_recognition", {}).get("per_primitive", {}).items():
        name = f"classifier_confusion_{p}.png"
        _heatmap(np.asarray(c["confusion"], dtype=float), c["styles"], c["styles"],
                 f"style classifier, real held-out {p} clips\naccuracy {c['heldout_accuracy']:.1%}",
                 _footer(results, f"{c['heldout_clips']} real clips", p), inside(folder, name), integer=True,
                 xlabel="predicted", ylabel="true style")
        written.append(name)
    if results.get("variance_ratio"):
        _variance_plot(results, folder / "variance.png")
        written.append("variance.png")
    return written
