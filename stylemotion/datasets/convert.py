"""One BVH file to canonical positions in an ``.npz`` (what ``stylemotion-convert`` runs).

Writes ``positions`` (frames, 21, 3) float32 global positions in metres, Y up; ``joint_names``
(the 21 canonical names in order) and ``fps``. Uses the same code path as the datasets. The output
must be a ``.npz`` file name (an existing file is replaced atomically; a folder, or another
extension such as ``.fbx`` or ``.bvh``, is refused: :func:`check_arguments`).
"""

from __future__ import annotations

import io
import math
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.datasets.loading import ConversionSettings, load_canonical_positions
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.errors import UserInputError
from stylemotion.io.sources import FileSource
from stylemotion.skeleton import CANONICAL_JOINTS

#: File types ``stylemotion-convert`` writes.
OUTPUT_SUFFIXES = (".npz",)


class ConvertError(UserInputError, ValueError):
    """A bad argument of ``stylemotion-convert`` (frame rate, output path); the message names it."""


def check_arguments(dst: str | Path, fps: Any) -> Path:
    """``dst`` as a Path after checking it and ``fps``, before any work.

    Raises:
        ConvertError: ``fps`` is not a positive finite number (0, -5, nan, inf), or ``dst`` is an
            existing folder or does not end in ``.npz``.
    """
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not math.isfinite(fps) or fps <= 0:
        raise ConvertError(f"--fps must be a positive finite frame rate (frames per second), got {fps!r}")
    path = Path(dst).expanduser()
    if path.is_dir():
        raise ConvertError(f"output {path} is a folder; give a file name ending in .npz")
    if path.suffix.lower() not in OUTPUT_SUFFIXES:
        raise ConvertError(f"output {path}: unknown extension {path.suffix or '(none)'!r}; stylemotion-convert "
                           f"writes {', '.join(OUTPUT_SUFFIXES)} (canonical positions)")
    return path


def convert_file(src: str | Path, dst: str | Path, settings: ConversionSettings, force: bool = False) -> np.ndarray:
    """Convert ``src`` (a BVH file, or ``archive.zip::member``) and write ``dst`` atomically.

    Returns the positions ``(frames, 21, 3)`` float32, metres. Raises :class:`ConvertError` for a bad
    ``dst`` or ``settings.fps``, an existing ``dst`` without ``force`` or a ``dst`` that is a link (all checked
    before reading), :class:`~stylemotion.io.errors.MotionDataError` for a file that cannot be converted.
    """
    dst = check_arguments(dst, settings.fps)
    if Path(dst).is_symlink():
        raise ConvertError(f"{dst} is a link; nothing is written through a link or over it: give another DST")
    if Path(dst).exists() and not force:
        raise ConvertError(f"{dst} already exists; give another DST or pass --force to replace it")
    src = str(src)
    source = FileSource(*src.split("::", 1)) if "::" in src else FileSource(src)
    positions = load_canonical_positions(source, settings)
    buf = io.BytesIO()
    np.savez(buf, positions=positions, joint_names=np.array(CANONICAL_JOINTS), fps=np.float64(settings.fps))
    atomic_write_bytes(dst, buf.getvalue())
    return positions
