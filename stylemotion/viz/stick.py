"""Stick figures of canonical 21-joint positions with matplotlib.

Views project positions (metres, Y up) onto the page:

* ``side``: forward (+Z) to the right, up (+Y) up — seen from the body's right side when it faces +Z;
* ``front``: the body's left (+X) on the page's right, up (+Y) up — seen from in front;
* ``top``: the body's left (+X) on the page's left, forward (+Z) up — seen from above, so a
  walker facing +Z keeps its left foot on the left of the page.

Left limbs are drawn in blue, right limbs in red, the trunk in grey. :class:`StickFigure` keeps its
line artists so that an animation (GIF) can update them frame by frame. Files are written through
:class:`matplotlib.figure.Figure` (no pyplot, so the active backend of a notebook is left alone).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from stylemotion.skeleton import CANONICAL_JOINTS, CANONICAL_PARENTS, JOINT_INDEX

#: ``(parent, child)`` joint index pairs of the canonical skeleton.
BONES: tuple[tuple[int, int], ...] = tuple((p, j) for j, p in enumerate(CANONICAL_PARENTS) if p >= 0)
LEFT_COLOR, RIGHT_COLOR, TRUNK_COLOR = "tab:blue", "tab:red", "0.35"
VIEWS = ("side", "front", "top")


def _side_color(joint: int) -> str:
    name = CANONICAL_JOINTS[joint]
    return LEFT_COLOR if name.endswith("_L") else RIGHT_COLOR if name.endswith("_R") else TRUNK_COLOR


def project(points: np.ndarray, view: str) -> np.ndarray:
    """Page coordinates ``(..., 2)`` of ``(..., 3)`` points (metres) in ``view``."""
    points = np.asarray(points)
    if view == "side":
        return points[..., [2, 1]]
    if view == "front":
        return points[..., [0, 1]]
    if view == "top":
        return np.stack([-points[..., 0], points[..., 2]], axis=-1)
    raise ValueError(f"unknown view {view!r}; one of {VIEWS}")


class StickFigure:
    """The bones of one pose as line artists on ``ax`` (update them with :meth:`set_pose`)."""

    def __init__(self, ax: Axes, pose: np.ndarray, view: str = "side", alpha: float = 1.0,
                 linewidth: float = 1.6):
        self.ax, self.view = ax, view
        self.lines = [ax.plot([], [], color=_side_color(j), alpha=alpha, lw=linewidth,
                              solid_capstyle="round")[0] for _, j in BONES]
        self.set_pose(pose)

    def set_pose(self, pose: np.ndarray) -> None:
        """Move the figure to ``pose`` ``(21, 3)``, metres."""
        xy = project(np.asarray(pose), self.view)
        for line, (p, j) in zip(self.lines, BONES):
            line.set_data([xy[p, 0], xy[j, 0]], [xy[p, 1], xy[j, 1]])


def draw_pose(ax: Axes, pose: np.ndarray, view: str = "side", alpha: float = 1.0,
              linewidth: float = 1.6) -> StickFigure:
    """Draw one ``(21, 3)`` pose."""
    return StickFigure(ax, pose, view, alpha, linewidth)


def draw_clip(ax: Axes, positions: np.ndarray, view: str = "side", poses: int = 4,
              contacts: np.ndarray | None = None, title: str | None = None) -> None:
    """Draw a clip: overlaid poses (``side``/``front``) or the feet's ground paths (``top``).

    In ``side`` and ``front`` views, ``poses`` evenly spaced poses are drawn from the first (faint)
    to the last (solid) frame, with the paths of the balls of both feet. The ``top`` view draws the
    paths of heels and balls of both feet, the root's path, and the hip and shoulder lines of the
    first (faint) and last frame; it shows which foot stays put and where the body turns.

    Args:
        ax: axes to draw into (limits and equal aspect are set).
        positions: ``(frames, 21, 3)`` metres.
        view: one of :data:`VIEWS`.
        poses: number of poses drawn in ``side``/``front`` views.
        contacts: ``(frames, 2)`` bool; frames where a foot is in contact get a dot on its path.
        title: axes title.
    """
    positions = np.asarray(positions)
    n = positions.shape[0]
    feet = ((JOINT_INDEX["Foot_L"], JOINT_INDEX["Toes_L"], LEFT_COLOR),
            (JOINT_INDEX["Foot_R"], JOINT_INDEX["Toes_R"], RIGHT_COLOR))
    if view == "top":
        root = project(positions[:, JOINT_INDEX["Hips"]], view)
        ax.plot(root[:, 0], root[:, 1], color=TRUNK_COLOR, lw=0.8)
        for f, alpha in ((0, 0.35), (n - 1, 1.0)):
            for a, b in (("UpperLeg_L", "UpperLeg_R"), ("UpperArm_L", "UpperArm_R")):
                seg = project(positions[f, [JOINT_INDEX[a], JOINT_INDEX[b]]], view)
                ax.plot(seg[:, 0], seg[:, 1], color=TRUNK_COLOR, lw=1.2, alpha=alpha)
        trunk = [JOINT_INDEX["Hips"], JOINT_INDEX["UpperArm_L"], JOINT_INDEX["UpperArm_R"]]
        shown = positions[:, trunk + [j for f in feet for j in f[:2]]]
    else:
        for k, f in enumerate(np.linspace(0, n - 1, max(poses, 1)).round().astype(int)):
            draw_pose(ax, positions[f], view, alpha=0.25 + 0.75 * (k + 1) / max(poses, 1), linewidth=1.2)
        shown = positions
    for foot, (heel, toes, color) in enumerate(feet):
        for joint, style in ((toes, ":"), (heel, "-")) if view == "top" else ((toes, ":"),):
            path = project(positions[:, joint], view)
            ax.plot(path[:, 0], path[:, 1], color=color, lw=0.8, ls=style)
            if contacts is not None:
                on = np.asarray(contacts)[:, foot]
                ax.plot(path[on, 0], path[on, 1], "o", color=color, ms=2.5)
    xy = project(shown, view).reshape(-1, 2)
    lo, hi = xy.min(0), xy.max(0)
    pad = 0.08 * max(float((hi - lo).max()), 0.2)
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal", adjustable="box")
    ax.tick_params(labelsize=6)
    if title:
        ax.set_title(title, fontsize=7)


def render_contact_sheet(rows: Mapping[str, Sequence[tuple[str, np.ndarray, np.ndarray | None]]],
                         path: str | Path, views: Sequence[str] = ("side", "top"), title: str = "",
                         cell_size: float = 2.2) -> Path:
    """A PNG grid: one row per key of ``rows``, one column pair (``views``) per clip.

    Args:
        rows: row label → ``[(clip label, positions (frames, 21, 3), contacts (frames, 2) or None)]``.
        path: output PNG path (its folder is created).
        views: views drawn side by side for each clip.
        title: figure title.
        cell_size: inches per view cell.

    Returns:
        ``path``.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    ncols = max((len(v) for v in rows.values()), default=1) * len(views)
    nrows = max(len(rows), 1)
    fig = Figure(figsize=(cell_size * ncols, cell_size * nrows + 0.6))
    axes = fig.subplots(nrows, ncols, squeeze=False)
    for ax in axes.flat:
        ax.set_axis_off()
    for r, (row_label, clips) in enumerate(rows.items()):
        for c, (label, positions, contacts) in enumerate(clips):
            for v, view in enumerate(views):
                ax = axes[r, c * len(views) + v]
                ax.set_axis_on()
                draw_clip(ax, positions, view, contacts=contacts, title=f"{label}\n{view}")
        axes[r, 0].set_ylabel(row_label, fontsize=9)
        axes[r, 0].yaxis.label.set_visible(True)
    fig.suptitle(title + "\nblue = left, red = right, dots = foot in contact. side: forward →, up ↑. "
                 "top: forward ↑, body's left on the left; heels solid, balls dotted, grey = root path, "
                 "hip and shoulder lines at the first (faint) and last frame", fontsize=9)
    fig.tight_layout()
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=110)
    tmp.replace(path)
    return path
