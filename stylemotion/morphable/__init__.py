"""The Morphable Graph of Du's thesis, chapters 3–4 (docs/morphable.md): functional motion data, time
warping, FPCA/SFPCA, GMM motion primitives, a space-partitioning tree and constrained synthesis."""

from stylemotion.morphable.model import FitSettings, MorphableModel, fit_primitive

__all__ = ["FitSettings", "MorphableModel", "fit_primitive"]
