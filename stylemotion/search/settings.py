"""The settings of ``stylemotion-search``: every key of ``configs/search.yaml`` and its one default.

``configs/search.yaml`` takes :class:`SearchSettings` as its structured config (``- schema@_here_: search``,
:mod:`stylemotion.cli.schemas`) and repeats no value; :func:`stylemotion.search.command.search_from_config`
builds it with :func:`stylemotion.config.build_settings`. This module imports no numpy or torch, so
``stylemotion-search --help`` stays fast.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from omegaconf import MISSING

from stylemotion.config import MotionFileKeys


@dataclass(frozen=True)
class ExportSettings:
    """``bvh``: write ``bvh/query.bvh`` and ``bvh/<rank>_<take>_<start>-<end>.bvh`` of the top matches; ``gif``:
    ``gif/…``, stick-figure animations of the same; ``top``: matches exported."""

    bvh: bool = False
    gif: bool = False
    top: int = 3


@dataclass(frozen=True)
class FigureSettings:
    """``matches``: panels of ``distance_matrix.png`` (the best matches); ``margin_s``: seconds of the take shown
    before and after each match."""

    matches: int = 3
    margin_s: float = 1.0


@dataclass(frozen=True)
class SearchSettings(MotionFileKeys):
    """Every key of ``stylemotion-search`` (besides ``data``), with its default.

    ``query``: ``<BVH>[:start-end]`` (frames of the FILE's rate, 0-based, end exclusive; also
    ``archive.zip::member.bvh``) or ``<take of the dataset>[:start-end]`` (frames at ``data.fps``).
    ``features``: feature set (E15 E30 E39 E15x3 E15x5 E30x3 E39x3 pca8 pca16 pca25 EP17 EP19).
    ``k``: neighbours per query frame (:data:`stylemotion.search.matching.DEFAULT_K` reads it). With the thesis'
    steps a match needs every query frame's neighbours to hold the next frame of the same take, so a small k
    often finds no path. Chosen among 64, 256 and 1024 on 1 s queries cut from Bandai's validation takes against
    its train takes (the smallest k for which the LNG returns exact DTW's best segment for 95 % of the queries;
    else the highest share) by ``python scripts/benchmarks.py run search``; test figures in benchmarks/search.md.
    ``k_max``, ``grow``, ``stable_for``: a search that finds no path, or whose answer still changes, doubles ``k``
    up to ``k_max`` (:func:`stylemotion.search.matching.grow_k`): ``grow=stable`` until the best segment has held
    over ``stable_for`` doublings in a row (1: the same at k and 2k; 2: at k, 2k and 4k), ``path`` until a path
    exists, ``none`` never; ``search.json`` reports the k used and every k tried. Chosen (with ``k``'s role as
    the first k tried) on 1, 3 and 5 s queries cut from Bandai's validation takes against its train takes by
    ``python scripts/benchmarks.py run search`` (blocks ``growth_choice`` and ``growth`` of benchmarks/search.md).
    ``refine``: re-rank the LNG's ``refine`` (at least ``top``) best candidates by exact subsequence DTW in windows
    around them
    (:func:`stylemotion.search.refine.refine_matches`; the costs reported are then exact DTW costs); 0: off.
    Chosen with ``grow``, ``k_max`` and ``stable_for`` on Bandai's validation queries by
    ``python scripts/benchmarks.py run search`` (among 0, 8, 32; block ``growth_choice``).
    ``verify``: make the best match exact subsequence DTW's best segment over the whole database: every take whose
    lower bound (each query frame's nearest frame in it, summed) does not exceed the LNG's best cost is swept by
    exact DTW (:func:`stylemotion.search.refine.verify_best`; ``search.json``'s ``takes_verified`` counts them);
    thesis steps and ``normalize=none`` only. Not tuned: on, because a user asking for the best match should get
    it; its cost is measured by ``python scripts/benchmarks.py run search`` (block ``growth``).
    ``steps``: the LNG's step set: thesis (diagonal, vertical, horizontal: a path may stay on one database
    frame) | online (the OLNG's (1,1), (1,2), (2,1), (2,2)) | gaps (thesis + online skips: a path may skip a query
    frame whose neighbours missed it, paying ``skip_cost``); not tuned: the thesis' set, as §2.4.1.
    ``skip_cost``: penalty per skipped query frame (feature units); None: the frame's k-th distance (a radius
    search: the radius).
    ``top``: most matches reported (non-overlapping, best first).
    ``eps``: approximate k-NN: each distance within ``(1 + eps)`` of the true one; 0 = exact.
    ``radius``: fixed-radius k-NN (feature units): only neighbours within it; None = the k nearest.
    ``engine``: k-NN engine: auto (exact: a kd-tree for few feature dimensions, a projected kd-tree for many, by the
    rule :data:`stylemotion.search.index.AUTO_ENGINES` that ``python scripts/benchmarks.py run engines`` measures;
    docs/search.md, "Engines and scale") | ckdtree | ckdtree-pca | pykdtree | faiss (exact) | faiss-hnsw |
    faiss-ivf (approximate).
    ``normalize``: reported cost: none (the thesis' accumulated distance) | length | query.
    ``exclude_query_take``: a take query: leave its own take out of the results.
    ``retarget_query``: a BVH query: put it on the dataset's skeleton (``data.retarget``'s, else the median bones
    of its normal takes), as ``stylemotion-style`` does with its example.
    ``joint_map``, ``unit_scale``, ``up_axis``: the query file's (:class:`~stylemotion.config.MotionFileKeys`).
    ``export``, ``figure``: :class:`ExportSettings`, :class:`FigureSettings`.
    ``out``: a new folder (an existing one is refused unless ``force``).
    """

    query: str = MISSING
    features: str = "E15"
    k: int = 1024
    k_max: int = 16384
    grow: str = "stable"
    stable_for: int = 1
    refine: int = 8
    verify: bool = True
    steps: str = "thesis"
    skip_cost: float | None = None
    top: int = 10
    eps: float = 0.0
    radius: float | None = None
    engine: str = "auto"
    normalize: str = "none"
    exclude_query_take: bool = True
    retarget_query: bool = True
    export: ExportSettings = field(default_factory=ExportSettings)
    figure: FigureSettings = field(default_factory=FigureSettings)
    out: str = "runs/search/${now:%Y-%m-%d_%H-%M-%S}"
    force: bool = False
