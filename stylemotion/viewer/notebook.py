"""The viewer page inside a Jupyter notebook (``stylemotion.view``): the same three.js page ``stylemotion-view``
writes, as one self-contained HTML document shown in an ``<iframe srcdoc=…>``.

Everything the page needs is inlined (the vendored three.js, ``viewer.js``, ``viewer.css`` and the motions'
``data.js``), so it plays offline and in any front end that renders HTML outputs (JupyterLab, classic Notebook,
VS Code); nothing is fetched from a CDN. A page with three.js is about 0.8 MB plus ~50 kB per 100 frames of 16
motions; :meth:`ViewerPage.save` writes the folder ``stylemotion-view`` writes instead.
"""

from __future__ import annotations

import html
import json
import os
import re
from collections.abc import Iterable, Mapping
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.io.errors import MotionDataError, UserInputError
from stylemotion.viewer.motions import ViewerMotion, read_inputs, samples_to_motions
from stylemotion.viewer.page import _index_html, page_data, write_viewer

#: Motions of one batch of samples shown at most (the page plays every motion at once).
MAX_SAMPLES = 16


def _as_motions(item: Any, name: str, fps: float, max_samples: int) -> list[ViewerMotion]:
    """Motions of one item: samples (``positions``, ``num_frames``, ``fps``), a walk (``positions``, ``fps``, ``path``),
    an array ``(frames, 21, 3)`` or ``(n, frames, 21, 3)``, or a file or folder ``stylemotion-view`` reads."""
    if isinstance(item, (str, os.PathLike)):
        return read_inputs([item], fps=fps, max_samples=max_samples)
    positions = getattr(item, "positions", item)
    if hasattr(positions, "detach"):
        positions = positions.detach().cpu().numpy()
    positions = np.asarray(positions, dtype=np.float32)
    rate = float(getattr(item, "fps", fps))
    if positions.ndim == 4:
        lengths = getattr(item, "num_frames", None)
        lengths = [positions.shape[1]] * len(positions) if lengths is None else [int(n) for n in lengths]
        return samples_to_motions(positions, lengths, rate, name, max_samples)
    if positions.ndim != 3:
        raise MotionDataError(name, f"positions of shape {positions.shape}: expected (frames, 21, 3) or "
                                    "(n, frames, 21, 3) metres")
    walk = getattr(item, "path", None)
    ground = getattr(walk, "points", None)
    motion = samples_to_motions(positions[None], [positions.shape[0]], rate, name, 1)[0]
    motion.name = name
    if ground is not None:
        motion.path = np.asarray(ground, dtype=np.float64)[:, :2]
    return [motion]


def viewer_motions(motions: Any, fps: float = 30.0, max_samples: int = MAX_SAMPLES) -> list[ViewerMotion]:
    """Every motion of ``motions`` (see :func:`view`) as :class:`~stylemotion.viewer.motions.ViewerMotion`\\ s."""
    if isinstance(motions, Mapping):
        items: Iterable[tuple[str, Any]] = [(str(k), v) for k, v in motions.items()]
    elif isinstance(motions, (list, tuple)):
        items = [(Path(m).name if isinstance(m, (str, os.PathLike)) else f"motion {i}", m)
                 for i, m in enumerate(motions)]
    else:
        items = [("motion", motions)]
    out = [m for name, item in items for m in _as_motions(item, name, fps, max_samples)]
    if not out:
        raise UserInputError("view: no motion given")
    return out


def _inline(template: str, data: dict[str, Any]) -> str:
    """``index.html`` with its stylesheet and scripts inlined (``data.js`` from ``data``)."""
    static = resources.files("stylemotion.viewer").joinpath("static")
    vendor = resources.files("stylemotion.viewer").joinpath("vendor")
    scripts = {"vendor/three.bundle.min.js": vendor.joinpath("three.bundle.min.js").read_text(),
               "data.js": "window.STYLEMOTION_DATA = " + json.dumps(data, separators=(",", ":")) + ";",
               "viewer.js": static.joinpath("viewer.js").read_text()}
    page = template.replace('<link rel="stylesheet" href="viewer.css">',
                            "<style>\n" + static.joinpath("viewer.css").read_text() + "\n</style>")
    for src, code in scripts.items():
        if re.search(r"</script", code, re.IGNORECASE):  # cannot happen for our files; never emit a broken page
            raise RuntimeError(f"{src} holds '</script' and cannot be inlined")
        page = page.replace(f'<script src="{src}"></script>', f"<script data-src=\"{src}\">\n{code}\n</script>")
    return page


class ViewerPage:
    """A viewer page a notebook displays (``_repr_html_``): the motions, and the page as one HTML document.

    Attributes:
        motions: the :class:`~stylemotion.viewer.motions.ViewerMotion`\\ s it shows.
        title: the page's heading.
        height: the frame's height in the notebook, pixels.
    """

    def __init__(self, motions: list[ViewerMotion], title: str = "", layout: str = "side", spacing_m: float = 1.0,
                 height: int = 480):
        self.motions, self.title, self.layout, self.spacing_m, self.height = motions, title, layout, spacing_m, height
        self.document = _inline(_index_html(title, len(motions)), page_data(motions, title, layout, spacing_m))

    def __repr__(self) -> str:
        return f"<ViewerPage {self.title!r}: {len(self.motions)} motions>"

    def _repr_html_(self) -> str:
        return (f'<iframe srcdoc="{html.escape(self.document, quote=True)}" style="width: 100%; height: '
                f'{int(self.height)}px; border: 1px solid #ddd" sandbox="allow-scripts"></iframe>')

    def save(self, out: str | os.PathLike, force: bool = False) -> Path:
        """Write the page's folder (as ``stylemotion-view --out``); returns its ``index.html``."""
        return write_viewer(self.motions, out, force, self.title, self.layout, self.spacing_m)


def view(motions: Any, title: str = "", layout: str = "side", fps: float = 30.0, max_samples: int = MAX_SAMPLES,
         height: int = 480, spacing_m: float = 1.0) -> ViewerPage:
    """The three.js viewer in a notebook: the last expression of a cell displays it (see the module doc).

    Args:
        motions: samples (``stylemotion.load(...).sample(n)``), a walk, an array ``(frames, 21, 3)`` or
            ``(n, frames, 21, 3)`` metres, a BVH/NPZ file or a run folder; a list of them; or a dict
            ``{name: motions}`` (each name a colour in the legend).
        title: the page's heading.
        layout: ``side`` (side by side) or ``overlay``.
        fps: frame rate of arrays and BVH files that carry none.
        max_samples: motions shown of each batch of samples.
        height: the frame's height in the notebook, pixels.
        spacing_m: distance between motions side by side, metres.
    """
    return ViewerPage(viewer_motions(motions, fps, max_samples), title, layout, spacing_m, height)


__all__ = ["MAX_SAMPLES", "ViewerPage", "view", "viewer_motions"]
