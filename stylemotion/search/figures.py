"""The thesis' Fig. 2.8: the distance matrix the LNG computes implicitly, with the recovered warping paths.

One panel per shown match: query frames across, the frames of the match's take around the match up (a
``margin`` on both sides, clipped to the take). Only frames found by the k-NN search have a distance (shades
of grey, the darker the more similar, on one scale for all panels); the blue background was never computed;
the red line is the warping path. Matplotlib ``Figure`` objects with the Agg canvas (no pyplot, a notebook's
backend is left alone), written atomically.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure

from stylemotion.search.index import FrameIndex
from stylemotion.search.matching import SearchResult, SegmentMatch

#: Colour of the cells the search never computed (the thesis' blue regions).
NOT_COMPUTED = "#9ec5e8"


def match_region(index: FrameIndex, match: SegmentMatch, margin: int) -> tuple[int, int]:
    """Global frames ``(lo, hi)`` of the match's take around it: ``margin`` frames each side, within the take."""
    take = index.database.take_slice(match.take)
    return max(take.start, match.global_start - margin), min(take.stop, match.global_end + margin)


def plot_distance_matrix(result: SearchResult, index: FrameIndex, path: str | os.PathLike, matches: int = 3,
                         margin: int = 30, title: str = "") -> Path:
    """Write the figure for the best ``matches`` matches of ``result`` to ``path`` (a ``.png``).

    Raises:
        ValueError: the result has no match.
    """
    shown = result.matches[:matches]
    if not shown:
        raise ValueError("no match to plot: the search found no path through the k-NN graph")
    regions = [match_region(index, m, margin) for m in shown]
    blocks = [result.implicit_distances(lo, hi) for lo, hi in regions]
    finite = np.concatenate([b[np.isfinite(b)] for b in blocks]) if any(np.isfinite(b).any() for b in blocks) \
        else np.array([0.0, 1.0])
    vmin, vmax = float(finite.min()), float(max(finite.max(), finite.min() + 1e-9))
    greys = ListedColormap(np.linspace([0.05] * 3, [0.92] * 3, 256)).with_extremes(bad=NOT_COMPUTED)
    fig = Figure(figsize=(3.2 * len(shown) + 0.8, 4.2))
    axes = fig.subplots(1, len(shown), squeeze=False)[0]
    image = None
    for ax, match, (lo, hi), block in zip(axes, shown, regions, blocks):
        first = lo - (match.global_start - match.start)  # the region's first frame within the take
        extent = (-0.5, block.shape[0] - 0.5, first - 0.5, first + hi - lo - 0.5)
        image = ax.imshow(np.ma.masked_invalid(block.T), origin="lower", aspect="auto", cmap=greys, vmin=vmin,
                          vmax=vmax, interpolation="nearest", extent=extent)
        ax.plot(match.path[:, 0], match.path[:, 1], color="red", lw=1.4)
        ax.set_title(f"#{match.rank} {match.take}\n{match.content}/{match.style}  cost {match.cost:.3g}", fontsize=7)
        ax.set_xlabel("query frame", fontsize=7)
        ax.set_ylabel("frame of the take", fontsize=7)
        ax.tick_params(labelsize=6)
    if image is not None:
        bar = fig.colorbar(image, ax=list(axes), fraction=0.03, pad=0.02)
        bar.set_label("feature distance (k-NN only)", fontsize=7)
        bar.ax.tick_params(labelsize=6)
    fig.suptitle(title or f"k = {result.k}: distances computed by the k-NN search (grey), not computed (blue), "
                          "warping paths (red)", fontsize=8)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.stem}.tmp{out.suffix}")
    fig.savefig(tmp, dpi=110)
    tmp.replace(out)
    return out
