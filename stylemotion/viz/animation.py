"""Stick-figure GIFs and last-frame contact sheets of sampled motions (like thesis Fig. 5.4–5.6).

Samples are lined up as in the thesis: every sample starts at the origin facing +Z, so each is
shifted sideways (along its left, +X) by ``spacing`` metres; 16 samples are shown as two rows of 8,
each row in its own panel. The panels use an oblique view (the scene turned by ``yaw_deg`` about
the vertical and tilted by ``pitch_deg`` towards the viewer, then seen from the front), drawn with
:class:`stylemotion.viz.stick.StickFigure` (left limbs blue, right limbs red). Root paths on the
ground are drawn faintly, so the spread of step lengths and turning shows.

* :func:`save_gif`: the samples moving together in real time (shown at 25 fps), a sample that
  has finished holds its last pose; written with matplotlib's ``PillowWriter``.
* :func:`save_last_frames`: a PNG of the same line-up at each sample's last frame, plus a small
  side view of every last pose labelled with its duration.
* :func:`save_samples_npz`: the samples' positions, which ``stylemotion-view`` shows in the browser.
* :class:`SampleAnimation`: a Lightning callback that writes all three for a trained VAE/CVAE and shows the
  contact sheet and frames of the GIF in TensorBoard (when the run logs there).

Files are written atomically (temporary name, then rename). No pyplot: a notebook's backend is left alone.
"""

from __future__ import annotations

import io
import logging
from pathlib import Path

import lightning.pytorch as pl
import numpy as np
from lightning.pytorch.loggers import TensorBoardLogger
from lightning.pytorch.utilities import rank_zero_only
from matplotlib.animation import PillowWriter
from matplotlib.figure import Figure

from stylemotion.geometry import rotate_yaw
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.models.sampling import MotionSamples
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX
from stylemotion.viz.stick import TRUNK_COLOR, StickFigure, draw_pose, project
from stylemotion.viz.tensorboard import log_sample_images

log = logging.getLogger(__name__)


def line_up(positions: np.ndarray, spacing: float = 1.0) -> np.ndarray:
    """Shift sample ``i`` by ``i · spacing`` metres along +X; ``(n, frames, 21, 3)`` → same shape."""
    offsets = np.zeros((positions.shape[0], 1, 1, 3), dtype=positions.dtype)
    offsets[:, 0, 0, 0] = np.arange(positions.shape[0]) * spacing
    return positions + offsets


def oblique(points: np.ndarray, yaw_deg: float = 20.0, pitch_deg: float = 12.0) -> np.ndarray:
    """Turn ``(..., 3)`` points (metres, Y up) about +Y by ``yaw_deg``, then tilt them by
    ``pitch_deg`` so that the ``front`` view of :func:`stylemotion.viz.stick.project` (looking at
    the body from +Z) sees them from the front, a little to the side and from above: forward (+Z)
    points towards the viewer and down the page."""
    turned = rotate_yaw(points, np.radians(yaw_deg))
    x, y, z = turned[..., 0], turned[..., 1], turned[..., 2]
    pitch = np.radians(pitch_deg)
    cp, sp = np.cos(pitch), np.sin(pitch)
    y, z = cp * y - sp * z, sp * y + cp * z  # nearer points (larger z) drop: seen from above
    return np.stack([x, y, z], axis=-1)


def _scene(samples: MotionSamples, count: int, spacing: float, per_row: int):
    """``[(first index, lined-up world positions (k, frames, 21, 3), valid frames (k,))]`` per row."""
    count = min(count, len(samples))
    pos = samples.positions[:count].numpy()
    frames = samples.num_frames[:count].numpy()
    return [(start, line_up(pos[start:start + per_row], spacing), frames[start:start + per_row])
            for start in range(0, count, per_row)]


def _layout(count: int, per_row: int, width: float = 12.0, row_height: float = 2.9):
    nrows = max(1, -(-count // per_row))
    fig = Figure(figsize=(width, row_height * nrows + 0.5))
    axes = fig.subplots(nrows, 1, squeeze=False)[:, 0]
    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.01, top=1 - 0.5 / (row_height * nrows + 0.5), hspace=0.12)
    return fig, axes


def _frame_axes(ax, scene: np.ndarray) -> None:
    xy = project(scene, "front").reshape(-1, 2)
    lo, hi = xy.min(0), xy.max(0)
    pad = 0.15
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal", adjustable="box")
    ax.set_axis_off()


def _paths(ax, world: np.ndarray, frames: np.ndarray) -> None:
    """Faint root paths on the ground (y = 0) of lined-up world positions."""
    for sample, n in zip(world, frames):
        root = sample[:n, JOINT_INDEX["Hips"]].copy()
        root[:, 1] = 0.0
        ground = project(oblique(root), "front")
        ax.plot(ground[:, 0], ground[:, 1], color=TRUNK_COLOR, lw=0.7, alpha=0.5)


def _save(fig: Figure, path: Path, **kwargs) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    fig.savefig(tmp, **kwargs)
    tmp.replace(path)
    return path


def pose_at(sample: np.ndarray, frames: int, index: float) -> np.ndarray:
    """Pose ``(21, 3)`` at fractional frame ``index`` (linear interpolation; held after the end)."""
    index = min(max(index, 0.0), frames - 1.0)
    lo = int(np.floor(index))
    hi = min(lo + 1, frames - 1)
    w = index - lo
    return sample[lo] * (1.0 - w) + sample[hi] * w


def save_gif(samples: MotionSamples, path: str | Path, count: int = 16, per_row: int = 8, spacing: float = 1.0,
             title: str = "", hold_s: float = 0.4, display_fps: int = 25, dpi: int = 70) -> Path:
    """Animated GIF of the first ``count`` samples lined up (see module doc), in real time.

    GIF frame delays are whole hundredths of a second, so 30 fps cannot play at its speed: the
    motions are shown at ``display_fps`` (25 fps = 40 ms per frame, exact), their poses linearly
    interpolated in time.

    Args:
        samples: decoded samples (positions in metres, at ``samples.fps``).
        path: output ``.gif``.
        count, per_row, spacing: how many samples, per panel row, and their sideways spacing (m).
        title: figure title (state data, seed, sample count and checkpoint).
        hold_s: seconds the last poses stay on screen at the end.
        display_fps: frame rate of the GIF (a divisor of 100 plays exactly).
        dpi: resolution (pixels per inch of a 13-inch-wide figure).
    """
    path = Path(path)
    rows = _scene(samples, count, spacing, per_row)
    fig, axes = _layout(min(count, len(samples)), per_row)
    figures = []
    for ax, (start, world, frames) in zip(axes, rows):
        scene = oblique(world)
        _paths(ax, world, frames)
        figures.append((scene, [StickFigure(ax, s[0], "front", linewidth=1.6) for s in scene]))
        _frame_axes(ax, scene)
        ax.set_title(f"samples {start}–{start + len(scene) - 1}", fontsize=8)
    fig.suptitle(title, fontsize=8)
    longest_s = (int(samples.num_frames[:count].max()) - 1) / samples.fps
    total = int(np.ceil(longest_s * display_fps)) + 1 + int(round(hold_s * display_fps))
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    writer = PillowWriter(fps=display_fps)
    with writer.saving(fig, str(tmp), dpi):
        for k in range(total):
            index = k * samples.fps / display_fps
            for (_, _, frames), (scene, sticks) in zip(rows, figures):
                for stick, sample, n in zip(sticks, scene, frames):
                    stick.set_pose(pose_at(sample, int(n), index))
            writer.grab_frame()
    tmp.replace(path)
    return path


def save_last_frames(samples: MotionSamples, path: str | Path, count: int = 16, per_row: int = 8,
                     spacing: float = 1.0, title: str = "") -> Path:
    """PNG contact sheet: the line-up at each sample's last frame (with its root path and a faint
    first pose), and a side view of every last pose labelled with the sample's duration."""
    path = Path(path)
    count = min(count, len(samples))
    rows = _scene(samples, count, spacing, per_row)
    nrows = len(rows)
    fig = Figure(figsize=(13.0, 3.4 * nrows + 1.7 * nrows + 0.8))
    grid = fig.add_gridspec(2 * nrows, per_row, height_ratios=[2.0, 1.0] * nrows)
    positions = samples.positions.numpy()
    for r, (start, world, frames) in enumerate(rows):
        scene = oblique(world)
        ax = fig.add_subplot(grid[2 * r, :])
        _paths(ax, world, frames)
        for sample, n in zip(scene, frames):
            draw_pose(ax, sample[0], "front", alpha=0.2, linewidth=1.0)
            draw_pose(ax, sample[n - 1], "front", linewidth=1.3)
        _frame_axes(ax, scene)
        ax.set_title(f"samples {start}–{start + len(scene) - 1}: last frames (faint: first frames)", fontsize=8)
        for c in range(len(scene)):
            i = start + c
            side = fig.add_subplot(grid[2 * r + 1, c])
            pose = positions[i, int(samples.num_frames[i]) - 1]
            draw_pose(side, pose, "side", linewidth=1.2)
            xy = project(pose, "side")
            mid = xy.mean(0)
            side.set_xlim(mid[0] - 0.6, mid[0] + 0.6)
            side.set_ylim(-0.05, max(1.9, float(xy[:, 1].max()) + 0.05))
            side.set_aspect("equal", adjustable="box")
            side.set_xticks([])
            side.set_yticks([])
            side.set_title(f"#{i} {float(samples.duration_s[i]):.2f} s", fontsize=7)
    fig.suptitle(title + "\nside views: forward →, up ↑; blue = left, red = right", fontsize=8)
    fig.tight_layout()
    return _save(fig, path, dpi=90)


def save_samples_npz(samples: MotionSamples, path: str | Path, count: int = 16) -> Path:
    """The first ``count`` samples as an NPZ that ``stylemotion-view`` shows: ``positions`` ``(n, frames, 21, 3)``
    float32 metres (zero after each sample's end), ``num_frames`` ``(n,)``, ``fps``, ``joint_names``."""
    path = Path(path)
    count = min(count, len(samples))
    buffer = io.BytesIO()
    np.savez(buffer, positions=samples.positions[:count].numpy().astype(np.float32),
             num_frames=samples.num_frames[:count].numpy().astype(np.int64), fps=np.float64(samples.fps),
             joint_names=np.array(CANONICAL_JOINTS))
    atomic_write_bytes(path, buffer.getvalue())
    return path


def render_samples(samples: MotionSamples, folder: str | Path, stem: str = "samples", title: str = "",
                   count: int = 16) -> tuple[Path, Path]:
    """Write ``<stem>.gif``, ``<stem>_last_frames.png`` and ``<stem>.npz`` (for ``stylemotion-view``) into
    ``folder``; returns the GIF's and the PNG's paths."""
    folder = Path(folder)
    gif = save_gif(samples, folder / f"{stem}.gif", count=count, title=title)
    png = save_last_frames(samples, folder / f"{stem}_last_frames.png", count=count, title=title)
    save_samples_npz(samples, folder / f"{stem}.npz", count=count)
    return gif, png


class SampleAnimation(pl.Callback):
    """After fitting, sample the best checkpoint (else the final weights) and write a GIF and a PNG.

    Args:
        dirpath: output folder (``${output_dir}/samples``).
        num_samples: samples shown (16).
        seed: sampling seed.
        data_name: dataset named in the figure title.
    """

    def __init__(self, dirpath: str, num_samples: int = 16, seed: int = 0, data_name: str = ""):
        self.dirpath, self.num_samples, self.seed, self.data_name = Path(dirpath), num_samples, seed, data_name
        self.paths: tuple[Path, Path] | None = None

    @rank_zero_only
    def on_fit_end(self, trainer: pl.Trainer, pl_module: pl.LightningModule) -> None:
        best = next((cb.best_model_path for cb in trainer.checkpoint_callbacks
                     if getattr(cb, "monitor", None) and getattr(cb, "best_model_path", "")), "")
        model = pl_module
        if best:
            from stylemotion.models.loading import load_generative  # viz does not need the models otherwise

            model = load_generative(best, autoencoder=pl_module.autoencoder.cpu())
        model.eval()
        samples = model.sample(self.num_samples, seed=self.seed)
        style = model.spec.get("style")
        title = (f"{type(model).__name__} {model.primitive}" + (f" style={style}" if style else "")
                 + f" · data={self.data_name or model.spec.get('dataset')} · {self.num_samples} samples, "
                 f"seed {self.seed} · checkpoint {best or 'final weights (no best checkpoint)'}")
        self.paths = render_samples(samples, self.dirpath, title=title, count=self.num_samples)
        for logger in trainer.loggers:
            if isinstance(logger, TensorBoardLogger):
                log_sample_images(logger.experiment, *self.paths, step=trainer.global_step)
        log.info("samples written to %s", self.dirpath)
