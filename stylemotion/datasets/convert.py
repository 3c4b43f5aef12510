"""One BVH file to canonical positions in an ``.npz`` (what ``stylemotion-convert`` runs).

Writes ``positions`` (frames, 21, 3) float32 global positions in metres, Y up; ``joint_names``
(the 21 canonical names in order) and ``fps``. Uses the same code path as the datasets.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from stylemotion.datasets.loading import ConversionSettings, load_canonical_positions
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.sources import FileSource
from stylemotion.skeleton import CANONICAL_JOINTS


def convert_file(src: str | Path, dst: str | Path, settings: ConversionSettings) -> np.ndarray:
    """Convert ``src`` (a BVH file, or ``archive.zip::member``) and write ``dst`` atomically."""
    src = str(src)
    source = FileSource(*src.split("::", 1)) if "::" in src else FileSource(src)
    positions = load_canonical_positions(source, settings)
    buf = io.BytesIO()
    np.savez(buf, positions=positions, joint_names=np.array(CANONICAL_JOINTS), fps=np.float64(settings.fps))
    atomic_write_bytes(Path(dst), buf.getvalue())
    return positions
