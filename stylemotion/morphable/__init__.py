"""The Morphable Graph of Du's thesis, chapters 3–4 (docs/morphable.md): functional motion data, time
warping, FPCA/SFPCA, GMM motion primitives, a space-partitioning tree and constrained synthesis.

The names below are loaded on first use (PEP 562), so importing a light submodule such as
:mod:`stylemotion.morphable.warping` does not load the model (torch, scikit-learn).
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from stylemotion.morphable.model import FitSettings, MorphableModel, fit_primitive

__all__ = ["FitSettings", "MorphableModel", "fit_primitive"]


def __getattr__(name: str) -> Any:
    """Load an exported name from :mod:`stylemotion.morphable.model` on first use."""
    if name not in __all__:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f"{__name__}.model"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
