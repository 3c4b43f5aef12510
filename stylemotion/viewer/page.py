"""Write the viewer page: a static folder that opens from disk and from any static server.

Layout of the folder::

    index.html            the page (controls, legend, canvas)
    viewer.js, viewer.css the page's code (stylemotion/viewer/static/)
    data.js               the motions: ``window.STYLEMOTION_DATA = {...}`` (a script, not a fetched JSON,
                          so ``file://`` works); positions as base64 little-endian float32
    vendor/               three.js (one classic script defining ``THREE``) and its LICENSE

The page's behaviour and the data format are described in ``docs/viewer.md``.
"""

from __future__ import annotations

import base64
import html
import json
import os
from collections.abc import Sequence
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.io.atomic import atomic_folder
from stylemotion.io.errors import UserInputError
from stylemotion.io.outputs import check_new_output
from stylemotion.skeleton import CANONICAL_JOINTS, CANONICAL_PARENTS, FOOT_POINTS
from stylemotion.viewer.motions import ViewerMotion

#: Colours of the groups (styles), in order of first appearance (matplotlib's tab10).
PALETTE = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
           "#17becf")
LAYOUTS = ("side", "overlay")
STATIC_FILES = ("viewer.js", "viewer.css")
VENDOR_FILES = ("three.bundle.min.js", "LICENSE", "VERSION.json")


def _b64(array: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(array).astype(array.dtype.newbyteorder("<")).tobytes()).decode()


def group_colors(motions: Sequence[ViewerMotion]) -> dict[str, str]:
    """A colour per group, in order of first appearance (cycling through :data:`PALETTE`)."""
    colors: dict[str, str] = {}
    for m in motions:
        colors.setdefault(m.group, PALETTE[len(colors) % len(PALETTE)])
    return colors


def page_data(motions: Sequence[ViewerMotion], title: str = "", layout: str = "side",
              spacing_m: float = 1.0) -> dict[str, Any]:
    """What ``data.js`` holds (see ``docs/viewer.md``)."""
    if layout not in LAYOUTS:
        raise UserInputError(f"layout {layout!r}: expected one of {', '.join(LAYOUTS)}")
    colors = group_colors(motions)
    return {
        "format": 1,
        "title": title,
        "layout": layout,
        "spacing_m": float(spacing_m),
        "joints": list(CANONICAL_JOINTS),
        "parents": list(CANONICAL_PARENTS),
        "foot_points": FOOT_POINTS.tolist(),
        "groups": colors,
        "motions": [{
            "name": m.name, "group": m.group, "color": colors[m.group], "fps": m.fps, "frames": m.frames,
            "source": m.source,
            "positions": _b64(np.asarray(m.positions, dtype=np.float32)),
            "contacts": _b64(np.asarray(m.contacts, dtype=np.uint8)),
            "path": None if m.path is None else np.round(m.path, 4).tolist(),
            "targets": None if m.targets is None else np.round(m.targets, 4).tolist(),
        } for m in motions],
    }


def _index_html(title: str, count: int) -> str:
    template = resources.files("stylemotion.viewer").joinpath("static", "index.html").read_text()
    return (template.replace("{{title}}", html.escape(title or "stylemotion viewer"))
            .replace("{{count}}", str(count)))


def build_viewer(motions: Sequence[ViewerMotion], folder: Path, title: str = "", layout: str = "side",
                 spacing_m: float = 1.0) -> Path:
    """Write the page's files into the existing folder ``folder`` (no atomicity: see :func:`write_viewer`)."""
    if not motions:
        raise UserInputError("a viewer page needs at least one motion")
    data = page_data(motions, title, layout, spacing_m)
    static = resources.files("stylemotion.viewer").joinpath("static")
    vendor = resources.files("stylemotion.viewer").joinpath("vendor")
    (folder / "vendor").mkdir(parents=True, exist_ok=True)
    for name in STATIC_FILES:
        (folder / name).write_bytes(static.joinpath(name).read_bytes())
    for name in VENDOR_FILES:
        (folder / "vendor" / name).write_bytes(vendor.joinpath(name).read_bytes())
    (folder / "data.js").write_text("window.STYLEMOTION_DATA = " + json.dumps(data, separators=(",", ":")) + ";\n")
    (folder / "index.html").write_text(_index_html(title, len(motions)))
    return folder / "index.html"


def write_viewer(motions: Sequence[ViewerMotion], out: str | os.PathLike, force: bool = False, title: str = "",
                 layout: str = "side", spacing_m: float = 1.0) -> Path:
    """Write the viewer folder ``out`` atomically (refused if it exists unless ``force``); returns ``index.html``."""
    out = check_new_output(out, force, key="--out")
    with atomic_folder(out, on_exists=lambda: check_new_output(out, force, key="--out")) as tmp:
        build_viewer(motions, tmp, title, layout, spacing_m)
    return out / "index.html"


def folder_size(folder: str | os.PathLike) -> int:
    """Bytes of the files under ``folder``."""
    return sum(p.stat().st_size for p in Path(folder).rglob("*") if p.is_file())


__all__ = ["LAYOUTS", "build_viewer", "folder_size", "page_data", "write_viewer"]
