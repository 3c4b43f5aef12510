"""Fixtures of the viewer tests: motion NPZ files from the synthetic generator and a headless Chromium.

The browser is Debian's ``chromium`` driven by Playwright (``.ci/run`` installs it; Playwright's own browser
download is never used). When it is missing the browser tests are skipped on a workstation but FAIL under
``CI=true``.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from stylemotion.datasets.synthetic import generate_take
from stylemotion.viewer.browser import CHROMIUM_ARGS, chromium_path


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


def running_in_ci() -> bool:
    """As tests/conftest.py decides it (not imported: tests/viewer/conftest.py shadows that module name here)."""
    return os.environ.get("CI", "").strip().lower() in ("1", "true", "yes", "on")


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
