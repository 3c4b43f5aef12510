"""Motion-database search (Krüger, *Synthesizing Human Motions*, ch. 2).

Feature sets of canonical positions (§2.3.2, §2.6.1), every frame of a dataset in one
:class:`MotionDatabase`, and a k-NN :class:`FrameIndex` over one feature set, persisted in the dataset cache;
global motion matching of a query (:func:`search_motion`, §2.4.1), numerical and logical similarity searches
(§2.5.1), fast fat-graph base poses and the fat graph that synthesizes, beside a plain motion graph (§2.5.3).
The ``stylemotion-search`` command: :mod:`.command`.

The names below load from their submodules on first use (PEP 562, :func:`stylemotion.lazy_exports`), so a light
submodule of the package loads without the heavy ones.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from stylemotion import lazy_exports

if TYPE_CHECKING:
    from stylemotion.search.clip_graph import (
        ClipGraph,
        DatabaseFrames,
        Walk,
        WalkMotion,
        goal_walk,
        largest_scc,
        random_walk,
        synthesize,
        walk_figures,
        write_walk,
    )
    from stylemotion.search.database import FrameLocation, MotionDatabase
    from stylemotion.search.fat_graph import FatGraphClusters, base_poses, fat_graph, greedy_bases, write_clusters
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
    from stylemotion.search.index import (
        APPROXIMATE_ENGINES,
        AUTO_ENGINES,
        ENGINES,
        EXACT_ENGINES,
        SEARCH_FORMAT,
        FrameIndex,
        auto_engine,
        database_features,
    )
    from stylemotion.search.matching import (
        DEFAULT_K,
        MATCH_KEYS,
        SearchResult,
        SegmentMatch,
        nearest_outside,
        search_features,
        search_motion,
    )
    from stylemotion.search.motion_graph import motion_graph
    from stylemotion.search.similarity import LogicalResult, logical_search, numerical_search


__all__ = [
    "APPROXIMATE_ENGINES", "AUTO_ENGINES", "E15_JOINTS", "E30_JOINTS", "E39_JOINTS", "ENGINES", "EXACT_ENGINES",
    "FEATURE_SETS", "NORMALIZATIONS",
    "SEARCH_FORMAT", "SEGMENTS", "WINDOW_SECONDS", "FeatureSpec", "FittedPCA", "FrameIndex", "FrameLocation",
    "MotionDatabase", "body_frame_positions", "centre_of_mass", "compute_features", "database_features",
    "auto_engine", "feature_names", "feature_spec", "fit_features", "physics_terms", "root_frames",
    "DEFAULT_K", "MATCH_KEYS", "SearchResult", "SegmentMatch", "nearest_outside", "search_features", "search_motion",
    "LogicalResult", "logical_search", "numerical_search",
    "FatGraphClusters", "base_poses", "greedy_bases", "write_clusters", "fat_graph", "motion_graph",
    "ClipGraph", "DatabaseFrames", "Walk", "WalkMotion", "goal_walk", "largest_scc", "random_walk", "synthesize",
    "walk_figures", "write_walk",
]

__getattr__, __dir__ = lazy_exports(__name__, {
    "FrameLocation": "database",
    "MotionDatabase": "database",
    "FatGraphClusters": "fat_graph",
    "base_poses": "fat_graph",
    "greedy_bases": "fat_graph",
    "write_clusters": "fat_graph",
    "fat_graph": "fat_graph",
    "motion_graph": "motion_graph",
    "ClipGraph": "clip_graph",
    "DatabaseFrames": "clip_graph",
    "Walk": "clip_graph",
    "WalkMotion": "clip_graph",
    "goal_walk": "clip_graph",
    "largest_scc": "clip_graph",
    "random_walk": "clip_graph",
    "synthesize": "clip_graph",
    "walk_figures": "clip_graph",
    "write_walk": "clip_graph",
    "E15_JOINTS": "features",
    "E30_JOINTS": "features",
    "E39_JOINTS": "features",
    "FEATURE_SETS": "features",
    "FeatureSpec": "features",
    "FittedPCA": "features",
    "NORMALIZATIONS": "features",
    "SEGMENTS": "features",
    "WINDOW_SECONDS": "features",
    "body_frame_positions": "features",
    "centre_of_mass": "features",
    "compute_features": "features",
    "feature_names": "features",
    "feature_spec": "features",
    "fit_features": "features",
    "physics_terms": "features",
    "root_frames": "features",
    "APPROXIMATE_ENGINES": "index",
    "AUTO_ENGINES": "index",
    "ENGINES": "index",
    "EXACT_ENGINES": "index",
    "FrameIndex": "index",
    "auto_engine": "index",
    "SEARCH_FORMAT": "index",
    "database_features": "index",
    "DEFAULT_K": "matching",
    "MATCH_KEYS": "matching",
    "SearchResult": "matching",
    "SegmentMatch": "matching",
    "nearest_outside": "matching",
    "search_features": "matching",
    "search_motion": "matching",
    "LogicalResult": "similarity",
    "logical_search": "similarity",
    "numerical_search": "similarity",
})
