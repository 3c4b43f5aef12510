"""Animation of one long motion walking along a ground path (the synthesis of thesis Fig. 5.7).

One oblique view (:func:`stylemotion.viz.animation.oblique`, across the walk and from above)
holds the whole scene: the requested path on the ground (dashed), the root's track so far (grey),
the step keyframes (dots) and the stick figure (left limbs blue, right limbs red). Written as a GIF
with matplotlib's ``PillowWriter``, or as MP4 (H.264) with ``FFMpegWriter`` running the ffmpeg binary that
the ``imageio-ffmpeg`` wheel ships (a dependency), so no system ffmpeg is needed.
Files are written atomically (temporary name, then rename).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib import rc_context
from matplotlib.animation import FFMpegWriter, PillowWriter
from matplotlib.figure import Figure

from stylemotion.skeleton import JOINT_INDEX
from stylemotion.viz.animation import oblique, pose_at
from stylemotion.viz.stick import StickFigure, project


def ffmpeg_executable() -> str:
    """Path of the ffmpeg binary of ``imageio-ffmpeg`` (its wheel's, or ``IMAGEIO_FFMPEG_EXE``).

    Raises:
        RuntimeError: imageio-ffmpeg finds no binary (a platform without a wheel and no system ffmpeg).
    """
    import imageio_ffmpeg

    return imageio_ffmpeg.get_ffmpeg_exe()


def mp4_available() -> bool:
    """Whether an ffmpeg binary is found (needed for ``.mp4``)."""
    try:
        ffmpeg_executable()
    except RuntimeError:
        return False
    return True


def save_walk_animation(positions: np.ndarray, fps: float, path_xz: np.ndarray, out: str | Path,
                        keyframes: list[int] | None = None, title: str = "", display_fps: int = 25,
                        dpi: int = 80, yaw_deg: float = -65.0, pitch_deg: float = 40.0) -> Path:
    """Animate ``positions`` along ``path_xz`` into ``out`` (``.gif`` or ``.mp4``).

    Args:
        positions: ``(frames, 21, 3)`` metres, Y up, at ``fps``.
        fps: frames per second of ``positions``.
        path_xz: ``(n, 2)`` the path's ground points (x, z), metres.
        out: output file; the suffix picks the writer.
        keyframes: frame indices of the step transitions, drawn as dots on the root track.
        title: figure title.
        display_fps: frame rate of the animation (GIF delays are whole hundredths: 25 plays exactly).
        dpi, yaw_deg, pitch_deg: resolution and view (see :func:`~stylemotion.viz.animation.oblique`;
            the default looks across a walk along +Z, from its right and above).

    Raises:
        RuntimeError: ``.mp4`` requested and imageio-ffmpeg finds no ffmpeg binary.
    """
    out = Path(out)
    suffix = out.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ValueError(f"{out}: animation must be .gif or .mp4")
    if suffix == ".mp4" and not mp4_available():
        raise RuntimeError(f"{out}: writing MP4 needs the ffmpeg binary of imageio-ffmpeg (pip install imageio-ffmpeg, "
                           f"or set IMAGEIO_FFMPEG_EXE; or write a .gif)")
    world = np.asarray(positions, dtype=np.float64)
    ground_path = np.stack([path_xz[:, 0], np.zeros(len(path_xz)), path_xz[:, 1]], axis=-1)
    root = world[:, JOINT_INDEX["Hips"]].copy()
    root[:, 1] = 0.0

    def page(points: np.ndarray) -> np.ndarray:
        return project(oblique(points, yaw_deg, pitch_deg), "front")

    scene, path_page, root_page = page(world), page(ground_path), page(root)
    fig = Figure(figsize=(10, 5.5))
    ax = fig.add_axes((0.02, 0.02, 0.96, 0.9))
    ax.plot(path_page[:, 0], path_page[:, 1], ls="--", color="tab:green", lw=1.2, label="path")
    track, = ax.plot([], [], color="0.4", lw=1.0, label="root")
    keys = np.asarray(keyframes or [], dtype=int)
    dots, = ax.plot([], [], "o", color="0.2", ms=2.5)
    stick = StickFigure(ax, scene[0], "front", linewidth=1.8)
    both = np.concatenate([scene.reshape(-1, 2), path_page])
    lo, hi = both.min(0), both.max(0)
    ax.set_xlim(lo[0] - 0.3, hi[0] + 0.3)
    ax.set_ylim(lo[1] - 0.3, hi[1] + 0.3)
    ax.set_aspect("equal", adjustable="box")
    ax.set_axis_off()
    ax.legend(loc="upper right", fontsize=7, frameon=False)
    fig.suptitle(title, fontsize=8)
    frames = len(world)
    total = int(np.ceil((frames - 1) / fps * display_fps)) + 1
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(f".{out.stem}.tmp{out.suffix}")
    writer = PillowWriter(fps=display_fps) if suffix == ".gif" else FFMpegWriter(fps=display_fps, codec="h264")
    ffmpeg = {"animation.ffmpeg_path": ffmpeg_executable()} if suffix == ".mp4" else {}
    try:
        with rc_context(ffmpeg), writer.saving(fig, str(tmp), dpi):
            for k in range(total):
                index = k * fps / display_fps
                stick.set_pose(pose_at(scene, frames, index))
                upto = min(int(index) + 1, frames)
                track.set_data(root_page[:upto, 0], root_page[:upto, 1])
                shown = keys[keys < upto]
                dots.set_data(root_page[shown, 0], root_page[shown, 1])
                writer.grab_frame()
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    tmp.replace(out)
    return out
