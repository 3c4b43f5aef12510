"""The annotation timeline of a document (Krüger Fig. 3.1): class segments above, sub-class segments below."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np


def plot_timeline(segments: Sequence[dict[str, Any]], classes: Sequence[str], frames: int, fps: float,
                  path: Path, title: str, truth: Sequence[str] | None = None) -> None:
    """Write a PNG: one row per class (annotated segments, and ground truth as thin bars when given), then one
    row per sub-class label that occurs; time in seconds."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from stylemotion.annotate.annotation import segments as runs

    styles = sorted({s["style"] for s in segments if s.get("style")})
    rows = list(classes) + [f"{s}" for s in styles]
    colours = plt.get_cmap("tab10")
    fig, ax = plt.subplots(figsize=(12, 0.35 * len(rows) + 1.4))
    for seg in segments:
        y = len(rows) - 1 - classes.index(seg["label"])
        ax.broken_barh([(seg["start"] / fps, (seg["end"] - seg["start"]) / fps)], (y - 0.35, 0.5),
                       color=colours(classes.index(seg["label"]) % 10))
        if seg.get("style"):
            ys = len(rows) - 1 - (len(classes) + styles.index(seg["style"]))
            ax.broken_barh([(seg["start"] / fps, (seg["end"] - seg["start"]) / fps)], (ys - 0.35, 0.7),
                           color="tab:green")
    if truth is not None:
        for start, end, label in runs(truth):
            if label in classes:
                y = len(rows) - 1 - classes.index(label)
                ax.broken_barh([(start / fps, (end - start) / fps)], (y + 0.2, 0.15), color="black")
    ax.set_yticks(np.arange(len(rows)), list(reversed(rows)), fontsize=8)
    if styles:
        ax.axhline(len(styles) - 0.5, color="grey", lw=0.8)
    ax.set_xlim(0, frames / fps)
    ax.set_xlabel("time (s)")
    ax.set_title(title + ("  (black: ground truth)" if truth is not None else ""), fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
