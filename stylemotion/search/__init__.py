"""Motion-database search (Krüger, *Synthesizing Human Motions*, ch. 2).

Feature sets of canonical positions (§2.3.2, §2.6.1), every frame of a dataset in one
:class:`MotionDatabase`, and a k-NN :class:`FrameIndex` over one feature set, persisted in the dataset cache.
"""

from stylemotion.search.database import FrameLocation, MotionDatabase
from stylemotion.search.features import (
    E15_JOINTS,
    E30_JOINTS,
    E39_JOINTS,
    FEATURE_SETS,
    NORMALIZATIONS,
    SEGMENTS,
    WINDOW_SECONDS,
    FeatureSpec,
    FittedPCA,
    body_frame_positions,
    centre_of_mass,
    compute_features,
    feature_names,
    feature_spec,
    fit_features,
    physics_terms,
    root_frames,
)
from stylemotion.search.index import ENGINES, EXACT_ENGINES, SEARCH_FORMAT, FrameIndex, database_features

__all__ = [
    "E15_JOINTS", "E30_JOINTS", "E39_JOINTS", "ENGINES", "EXACT_ENGINES", "FEATURE_SETS", "NORMALIZATIONS",
    "SEARCH_FORMAT", "SEGMENTS", "WINDOW_SECONDS", "FeatureSpec", "FittedPCA", "FrameIndex", "FrameLocation",
    "MotionDatabase", "body_frame_positions", "centre_of_mass", "compute_features", "database_features",
    "feature_names", "feature_spec", "fit_features", "physics_terms", "root_frames",
]
