"""Evaluation of primitive models: the thesis' Tables 5.1–5.3 and the metrics it lacks.

* :mod:`.tables`: style distance D(m, s) (Table 5.1, eq. 5.12) and pose/speed/step SD (Tables
  5.2/5.3, eq. 5.13–5.15);
* :mod:`.classifier`: a style classifier fitted on real clips, whose PCA space hosts the Fréchet
  distance and the diversity;
* :mod:`.metrics`: Fréchet distance, diversity, foot skating, nearest-training-clip distance;
* :mod:`.sources`: what is evaluated (:class:`SampleSource`, :class:`EvalModel`, checkpoints);
* :mod:`.reference`: the real clips a primitive's models are compared with;
* :mod:`.pipeline`: one evaluation → plain results; :mod:`.report`: the report folder.

* :mod:`.run`: checkpoints → loaded models → evaluation → report folder (what ``stylemotion-eval`` calls).

The names below load from their submodules on first use (PEP 562, :func:`stylemotion.lazy_exports`), so the
settings (:mod:`.settings`, what ``stylemotion-eval --help`` composes) load without torch, scikit-learn or
matplotlib.
"""


from __future__ import annotations

from typing import TYPE_CHECKING

from stylemotion import lazy_exports

if TYPE_CHECKING:
    from stylemotion.evaluation.classifier import StyleClassifier
    from stylemotion.evaluation.metrics import diversity, foot_skating, frechet_distance, nearest_distances
    from stylemotion.evaluation.pipeline import evaluate_models
    from stylemotion.evaluation.reference import PrimitiveData, primitive_data
    from stylemotion.evaluation.report import write_report
    from stylemotion.evaluation.settings import EvalSettings
    from stylemotion.evaluation.sources import MissingExampleError, MixedAutoencodersError, RealClipSource
    from stylemotion.evaluation.tables import diagonal_minima, distance_table, variance_stats
    from stylemotion.models.loading import NEUTRAL, EvalModel, SampleSource, load_model

__all__ = ["NEUTRAL", "EvalModel", "EvalSettings", "MissingExampleError", "MixedAutoencodersError", "PrimitiveData",
           "RealClipSource", "SampleSource", "StyleClassifier", "diagonal_minima",
           "distance_table", "diversity", "evaluate_models", "foot_skating", "frechet_distance", "load_model",
           "nearest_distances", "primitive_data", "variance_stats", "write_report"]

#: Each exported name → its submodule, or the module it is re-exported from.
_WHERE = {
    "StyleClassifier": "classifier", "diversity": "metrics", "foot_skating": "metrics", "frechet_distance": "metrics",
    "nearest_distances": "metrics", "evaluate_models": "pipeline", "PrimitiveData": "reference",
    "primitive_data": "reference", "write_report": "report", "EvalSettings": "settings",
    "MissingExampleError": "sources", "MixedAutoencodersError": "sources", "RealClipSource": "sources",
    "diagonal_minima": "tables", "distance_table": "tables", "variance_stats": "tables",
    "NEUTRAL": "stylemotion.models.loading", "EvalModel": "stylemotion.models.loading",
    "SampleSource": "stylemotion.models.loading", "load_model": "stylemotion.models.loading",
}

__getattr__, __dir__ = lazy_exports(__name__, _WHERE)
