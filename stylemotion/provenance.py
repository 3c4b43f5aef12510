"""What produced a result: package version, git commit, command, machine load.

Every command records :func:`provenance` in its run folder, so a number can be traced to the code
that computed it.
"""

from __future__ import annotations

import os
import platform
import subprocess
import sys
from pathlib import Path
from typing import Any

import stylemotion

#: The source tree the package was imported from (a clone, or site-packages for a wheel).
SOURCE_ROOT = Path(stylemotion.__file__).resolve().parents[1]


def git_commit(root: str | os.PathLike = SOURCE_ROOT) -> str:
    """``HEAD``'s commit of the repository at ``root`` (``+dirty`` with uncommitted changes), or
    ``unknown`` (an installed wheel, no git)."""
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True, text=True, timeout=10,
                              check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
        return head + ("+dirty" if dirty else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def load_average() -> list[float] | None:
    """The 1/5/15-minute load averages, or None where the OS has none."""
    try:
        return [round(v, 2) for v in os.getloadavg()]
    except OSError:
        return None


def provenance(command: str | None = None) -> dict[str, Any]:
    """Version, commit, command line, Python/torch versions, host load: JSON-ready."""
    import torch

    return {"stylemotion_version": stylemotion.__version__, "git_commit": git_commit(),
            "command": command if command is not None else " ".join([Path(sys.argv[0]).name, *sys.argv[1:]]),
            "python": platform.python_version(), "torch": torch.__version__,
            "torch_threads": torch.get_num_threads(), "load_average_at_start": load_average()}
