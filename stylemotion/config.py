"""Where the Hydra configs live and small helpers shared by the entry points."""

from __future__ import annotations

from pathlib import Path

#: The repository's ``configs/`` folder (the package is installed editable from the repository).
CONFIG_DIR = Path(__file__).resolve().parents[1] / "configs"


def config_dir() -> str:
    """Absolute path of ``configs/``; a clear error if the package was installed without it."""
    if not CONFIG_DIR.is_dir():
        raise FileNotFoundError(
            f"Hydra configs not found at {CONFIG_DIR}; install stylemotion from a clone with "
            "'pip install -e .' so the configs/ folder stays beside the package"
        )
    return str(CONFIG_DIR)
