"""Writing C3D test files with ezc3d's writer in a fresh Python process.

ezc3d and faiss are both SWIG modules; once faiss is imported, ezc3d's ``Parameter.set`` no longer accepts the
vectors its writer passes (``TypeError: Wrong number or type of arguments``), so a test that writes a C3D after
any search test had failed depending on test order. Reading is not affected (the library only reads). The writer
runs in a child process that imports ezc3d alone.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

_WRITER = """
import sys
import ezc3d
import numpy as np
with np.load(sys.argv[1], allow_pickle=False) as npz:
    labels, points, rate = [str(x) for x in npz["labels"]], npz["points"], float(npz["rate"])
    residuals = npz["residuals"] if "residuals" in npz.files else None
c3d = ezc3d.c3d()
c3d["parameters"]["POINT"]["RATE"]["value"] = [rate]
c3d["parameters"]["POINT"]["LABELS"]["value"] = labels
c3d["data"]["points"] = points
if residuals is not None:
    c3d["data"]["meta_points"]["residuals"] = residuals
c3d.add_parameter("POINT", "UNITS", "mm")
c3d.write(sys.argv[2])
"""


def write_c3d(path: str | Path, labels: list[str], xyz_mm: np.ndarray, rate: float,
              residual: np.ndarray | None = None) -> Path:
    """A C3D of points ``xyz_mm`` ``(frames, points, 3)`` in millimetres, Z up, at ``rate`` (ezc3d's writer);
    ``residual`` ``(frames, points)`` optional."""
    path = Path(path)
    xyz = np.asarray(xyz_mm, np.float64)
    points = np.ones((4, len(labels), len(xyz)))
    points[:3] = np.moveaxis(xyz, -1, 0).swapaxes(1, 2)
    arrays = {"labels": np.array(list(labels)), "points": points, "rate": np.array(float(rate))}
    if residual is not None:
        arrays["residuals"] = np.asarray(residual, np.float64).T[None]
    staging = path.with_name(path.name + ".arrays.npz")
    np.savez(staging, **arrays)
    try:
        subprocess.run([sys.executable, "-c", _WRITER, str(staging), str(path)], check=True, capture_output=True)
    finally:
        staging.unlink(missing_ok=True)
    return path
