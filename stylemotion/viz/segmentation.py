"""Plot of one take's segmentation: foot heights, detected contacts, keyframes and clips."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from stylemotion.datasets.base import Take
from stylemotion.primitives.contacts import ContactSettings, foot_signals
from stylemotion.primitives.segmentation import TakeSegmentation
from stylemotion.viz.stick import LEFT_COLOR, RIGHT_COLOR

_SHORT = {"leftStance": "L", "rightStance": "R", "beginLeftStance": "bL", "beginRightStance": "bR",
          "endLeftStance": "eL", "endRightStance": "eR"}


def plot_take_segmentation(take: Take, seg: TakeSegmentation, path: str | Path,
                           settings: ContactSettings | None = None) -> Path:
    """Write a PNG of heel and ball heights of both feet over time, the detected contacts (bars),
    the keyframes (vertical lines), the clips (labelled spans) and rejected or border steps.

    Args:
        take: the take (positions in metres, ``fps``).
        seg: its segmentation (:func:`stylemotion.primitives.segmentation.segment_take`).
        path: output PNG path.
        settings: the contact settings used (for the resting heights' percentile).

    Returns:
        ``path``.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = Figure(figsize=(max(8.0, take.num_frames / 25), 4.2))
    ax = fig.subplots()
    sig = foot_signals(take.positions, take.fps, settings) if take.num_frames >= 2 else None
    t = np.arange(take.num_frames)
    top = 0.3
    if sig is not None:
        for foot, color, name in ((0, LEFT_COLOR, "left"), (1, RIGHT_COLOR, "right")):
            ax.plot(t, sig.heights[:, foot, 0] * 100, color=color, lw=1.2, label=f"{name} heel (ankle)")
            ax.plot(t, sig.heights[:, foot, 1] * 100, color=color, lw=1.0, ls="--", label=f"{name} ball (toes)")
        top = max(float(np.percentile(sig.heights, 99)) * 100, 5.0)
    for foot, color in ((0, LEFT_COLOR), (1, RIGHT_COLOR)):
        on = seg.contacts[:, foot] if len(seg.contacts) else np.zeros(0, bool)
        y = -0.08 * top * (foot + 1)
        ax.fill_between(t[: len(on)], y - 0.03 * top, y + 0.03 * top, where=on, color=color, alpha=0.6, lw=0,
                        step="mid")
    for k in seg.keyframes:
        ax.axvline(k, color="k", lw=0.8, alpha=0.7)
    for clip in seg.clips:
        ax.axvspan(clip.start, clip.stop - 1, ymin=0.93, ymax=0.99, color="0.75")
        ax.text((clip.start + clip.stop - 1) / 2, 1.02 * top, _SHORT[clip.primitive], ha="center", fontsize=7)
    for rej in seg.rejections:
        if rej.start is not None:
            ax.axvspan(rej.start, rej.stop - 1, color="orange" if rej.kind == "border" else "red", alpha=0.12)
    ax.set_xlim(0, max(take.num_frames - 1, 1))
    ax.set_ylim(-0.3 * top, 1.12 * top)
    ax.set_xlabel(f"frame ({take.fps:g} fps)")
    ax.set_ylabel("height above rest (cm)")
    problems = [r.reason for r in seg.rejections if r.kind != "border"]
    ax.set_title(f"{take.name} ({take.content}, {take.style}): {len(seg.clips)} clips\nbars: contacts "
                 f"(blue left, red right); lines: keyframes; shaded: border (orange), rejected (red)"
                 + (f"\n{problems[0]}" if problems else ""), fontsize=8)
    ax.legend(fontsize=6, loc="upper right", ncol=2)
    fig.tight_layout()
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=100)
    tmp.replace(path)
    return path
