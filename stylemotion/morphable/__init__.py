"""The Morphable Graph of Du's thesis, chapters 3–4 (docs/morphable.md): functional motion data, time
warping, FPCA/SFPCA, GMM motion primitives, a space-partitioning tree and constrained synthesis.

The names below load from their submodules on first use (PEP 562, :func:`stylemotion.lazy_exports`), so a light
submodule of the package loads without the heavy ones.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from stylemotion import lazy_exports

if TYPE_CHECKING:
    from stylemotion.morphable.model import FitSettings, MorphableModel, fit_primitive


__all__ = ["FitSettings", "MorphableModel", "fit_primitive"]

__getattr__, __dir__ = lazy_exports(__name__, {
    "FitSettings": "model",
    "MorphableModel": "model",
    "fit_primitive": "model",
})
