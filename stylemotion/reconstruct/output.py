"""The output folder of the reconstruction commands: ``motion.npz``, ``motion.bvh``, ``summary.json`` and
``motion.gif``, atomically."""

from __future__ import annotations

import io
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.io.atomic import atomic_folder, atomic_write_bytes
from stylemotion.io.jsonfile import write_json
from stylemotion.io.outputs import check_new_output, inside
from stylemotion.skeleton import CANONICAL_JOINTS


def write_motion_folder(out: str | os.PathLike, force: bool, positions: np.ndarray, fps: float,
                        summary: dict[str, Any], started: float, *, gif: bool = False,
                        gif_path_xz: np.ndarray | None = None, gif_keys: list[int] | None = None,
                        gif_title: str = "") -> None:
    """Write a motion and its summary into the new folder ``out`` (refused if it holds a result, unless ``force``).

    Args:
        positions: ``(frames, 21, 3)`` metres; ``motion.npz`` holds them as ``stylemotion-convert`` writes
            (``positions`` float32, ``joint_names``, ``fps``), ``motion.bvh`` with rotations fitted.
        summary: written as ``summary.json`` after ``timing_s.command`` (seconds since ``started``, a
            ``time.perf_counter()`` reading) is added to it.
        gif: also ``motion.gif``, the stick figure along its ground track
            (:func:`stylemotion.viz.walk.save_walk_animation`), with ``gif_path_xz`` ``(n, 2)`` metres drawn as
            the path (default: the Hips' track) and ``gif_keys`` frames marked on the track.
    """
    out = Path(out)
    with atomic_folder(out, on_exists=lambda: check_new_output(out, force)) as tmp:
        buffer = io.BytesIO()
        np.savez(buffer, positions=np.asarray(positions, dtype=np.float32), joint_names=np.array(CANONICAL_JOINTS),
                 fps=np.float64(fps))
        atomic_write_bytes(inside(tmp, "motion.npz"), buffer.getvalue())
        from stylemotion.io.export import write_motion_bvh

        write_motion_bvh(positions, inside(tmp, "motion.bvh"), fps)
        if gif:
            from stylemotion.skeleton import JOINT_INDEX
            from stylemotion.viz.walk import save_walk_animation

            track = np.asarray(positions, dtype=np.float64)[:, JOINT_INDEX["Hips"]][:, [0, 2]]
            save_walk_animation(positions, fps, track if gif_path_xz is None else np.asarray(gif_path_xz),
                                inside(tmp, "motion.gif"), keyframes=gif_keys, title=gif_title)
        summary.setdefault("timing_s", {})["command"] = round(time.perf_counter() - started, 3)
        write_json(inside(tmp, "summary.json"), summary)
