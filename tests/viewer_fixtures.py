"""Fixtures of the viewer tests: motion NPZ files from the synthetic generator and a headless Chromium.

The browser is Debian's ``chromium`` driven by Playwright (``.ci/run`` installs it; Playwright's own browser
download is never used). When it is missing the browser tests are skipped on a workstation but FAIL under
``CI=true``.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import running_in_ci

from stylemotion.datasets.synthetic import generate_take
from stylemotion.models.sampling import MotionSamples
from stylemotion.viewer.browser import CHROMIUM_ARGS, chromium_path


def synthetic_samples(styles: tuple[str, ...] = ("normal", "elderly"), seconds: float = 1.0,
                      lengths: list[int] | None = None) -> MotionSamples:
    """MotionSamples of synthetic walks (one per style), as a sampler returns them (padded to one length)."""
    import torch

    pos = np.stack([generate_take("walk", s, 0, duration_s=seconds).positions for s in styles])
    n, frames = pos.shape[:2]
    lengths = torch.tensor(lengths or [frames] * n)
    return MotionSamples(torch.from_numpy(pos), torch.zeros(n, frames, 66), lengths, (lengths - 1) / 30.0,
                         torch.zeros(n, 1, 1), torch.zeros(n, 1, 66), 30.0)


def tiny_results(columns_on_diagonal: tuple[str, ...] = ("neutral", "elderly")) -> dict:
    """Evaluation results with one 2 × 2 Table 5.1 (rows neutral, elderly), as ``evaluate_models`` + meta."""
    styles = ["neutral", "elderly"]
    return {
        "meta": {"data_name": "synthetic", "seed": 3, "samples": {"table_5_1": 4}},
        "table_5_1": {"walk_leftStance": {
            "models": styles, "examples": styles, "distance": [[0.1, 0.7], [0.9, 0.2]], "samples": 4,
            "diagonal": {"rows": styles, "columns": list(columns_on_diagonal), "row_argmin": {},
                         "all_rows": True, "all_columns": len(columns_on_diagonal) == 2},
            "example_clips": {"neutral": "mean motion", "elderly": "take 3"}}},
    }


def write_take_npz(path: Path, style: str, seconds: float = 3.0, walk: bool = False) -> Path:
    """A synthetic walk of ``style`` as a motion NPZ (with a path and junctions when ``walk``)."""
    take = generate_take("walk", style, 0, duration_s=seconds)
    extra = {}
    if walk:
        extra = {"path": take.positions[::10, 0][:, [0, 2]], "junctions": np.array([0, 30, 60])}
    np.savez(path, positions=take.positions, fps=np.float64(take.fps), **extra)
    return path


@pytest.fixture
def motion_files(tmp_path: Path) -> list[Path]:
    """Three motion NPZ files of three styles; the first is a walk with a path and targets."""
    return [write_take_npz(tmp_path / f"{s}.npz", s, walk=(i == 0))
            for i, s in enumerate(("normal", "elderly", "active"))]


def chromium_executable() -> str:
    """The system Chromium; skip (fail under CI=true) when it or Playwright is missing."""
    missing = []
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        missing.append("the Python package playwright (pip install -e '.[dev]')")
    chromium = chromium_path()
    if not (Path(chromium).is_file() or shutil.which(chromium)):
        missing.append(f"{chromium} (apt-get install chromium; or set STYLEMOTION_CHROMIUM)")
    if missing:
        message = "browser test needs " + " and ".join(missing)
        if running_in_ci():
            pytest.fail(message + " (CI=true: not skipped)")
        pytest.skip(message)
    return chromium


@pytest.fixture(scope="module")
def browser():
    """A headless Chromium (one per test module)."""
    executable = chromium_executable()
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=executable, args=list(CHROMIUM_ARGS))
        yield b
        b.close()
