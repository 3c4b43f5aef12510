"""What ``stylemotion-search`` runs: a query motion against every frame of a dataset (Krüger §2.4.1).

    stylemotion-search query=my_walk.bvh:120-480 data=bandai features=E15 top=10 out=runs/search/walk
    stylemotion-search query=synthetic_walk_normal_000:30-90 features=E15x3 k=32

``query`` is a BVH file of any skeleton a joint map names (or ``archive.zip::member.bvh``), converted as
datasets convert theirs (:mod:`stylemotion.datasets.user_motion`, the reader ``stylemotion-style`` uses for its
example; ``start-end`` frames of the **file's** rate, end exclusive) and put on the dataset's skeleton
(``retarget_query``); or the name of a take of the dataset, ``start-end`` then frames of the take at the
dataset's fps. A take query's own take is left out of the results unless ``exclude_query_take=false``.

The folder ``out`` (refused when it exists unless ``force``; built beside it and renamed into place):

* ``matches.json``: a list, best first, each exactly ``{"take", "content", "style", "start", "end", "cost"}``
  (frames of the take at the dataset's fps, ``end`` exclusive; ``cost`` the LNG's accumulated feature distance);
* ``search.json``: the query, the settings, the database, the timings, the warping paths and provenance;
* ``distance_matrix.png``: the thesis' Fig. 2.8 for the best matches (:mod:`stylemotion.search.figures`);
* on request ``bvh/`` (``export.bvh``: the query and the top ``export.top`` matches as BVH) and ``gif/``
  (``export.gif``: stick-figure animations of them).
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig

from stylemotion.config import positive_int, settings_from_config
from stylemotion.datasets import TakeSet, build_dataset
from stylemotion.datasets.loading import ConversionSettings
from stylemotion.datasets.user_motion import (
    UserMotionError,
    conversion_keys,
    convert_example,
    on_run_skeleton,
    parse_example,
)
from stylemotion.io.atomic import atomic_folder
from stylemotion.io.errors import UserInputError
from stylemotion.io.jsonfile import write_json
from stylemotion.io.outputs import check_new_output, inside, safe_name
from stylemotion.provenance import provenance
from stylemotion.search.database import MotionDatabase
from stylemotion.search.features import feature_names, feature_spec
from stylemotion.search.index import ENGINES, FrameIndex
from stylemotion.search.lng import NORMALIZATIONS, STEP_SETS
from stylemotion.search.matching import GROWTH, SearchResult, SegmentMatch, search_motion
from stylemotion.search.settings import ExportSettings, FigureSettings, SearchSettings

log = logging.getLogger(__name__)
_D = SearchSettings


class SearchInputError(UserInputError, ValueError):
    """A ``stylemotion-search`` input that cannot be used; the message names the key and the value."""


@dataclass(frozen=True)
class Query:
    """The query motion: ``positions`` ``(frames, 21, 3)`` metres at the dataset's fps, where it came from
    (``record``: JSON-ready), and the take it was cut from (None for a file)."""

    positions: np.ndarray
    record: dict[str, Any]
    take: str | None = None


def _take_query(text: str, database: MotionDatabase) -> Query | None:
    """The query as frames of a take of the dataset, or None when ``text`` names no take."""
    try:
        spec = parse_example(text, key="query")
    except UserMotionError:
        prefix, _, bounds = text.rpartition(":")
        if prefix in database.take_names and not Path(prefix).expanduser().is_file():
            raise SearchInputError(f"query={text}: the frame range {bounds!r} must be START-END, two whole numbers "
                                   f"0 ≤ START < END (frames of the take at {database.fps:g} fps, END exclusive)"
                                   ) from None
        return None
    name = spec.path
    if name not in database.take_names or Path(name).expanduser().is_file():
        return None
    frames = database.take_positions(name)
    start, end = (0, len(frames)) if spec is None or spec.start is None else (spec.start, spec.end)
    if end > len(frames):
        raise SearchInputError(f"query={text}: the frame range {start}-{end} ends after the take's last frame: "
                               f"{name} has {len(frames)} frames (0-{len(frames)}) at {database.fps:g} fps")
    return Query(np.asarray(frames[start:end], dtype=np.float32),
                 {"kind": "take", "take": name, "start": start, "end": end, "fps": database.fps}, name)


def load_query(text: str, takeset: TakeSet, database: MotionDatabase, conversion: Mapping[str, Any] | None = None,
               retarget: bool = True) -> Query:
    """``query=`` as a :class:`Query` (see the module docstring).

    Raises:
        SearchInputError: an empty value, a bad range or one outside the take or file, a file that cannot be
            read or whose skeleton no joint map fits (naming ``joint_map=``), a skeleton that cannot be put
            on the dataset's.
    """
    text = str(text or "").strip()
    taken = _take_query(text, database) if text else None
    if taken is not None:
        return taken
    try:
        spec = parse_example(text, key="query")
        if "::" not in spec.path and not Path(spec.path).expanduser().is_file():
            raise SearchInputError(f"query={text}: no such file, and {spec.path!r} is no take of dataset "
                                   f"{database.name!r} (takes like {database.take_names[0]!r})")
        settings = ConversionSettings(fps=database.fps, **{k: v for k, v in (conversion or {}).items()
                                                           if v is not None})
        example = convert_example(spec, settings)
        if retarget:
            example = on_run_skeleton(example, takeset)
    except UserMotionError as exc:
        raise SearchInputError(str(exc)) from None
    record = {"kind": "bvh", "file": example.name, "sha256": example.sha256, "file_fps": example.file_fps,
              "file_frames": example.file_frames, "file_range": [example.start, example.end],
              "frames": int(example.positions.shape[0]), "fps": example.fps,
              "retargeted_to": (example.retarget or {}).get("style", "all takes") if retarget else None}
    return Query(example.positions, record)


def _checked_settings(features: Any, k: Any, top: Any, engine: Any, normalize: Any) -> tuple[str, int, int]:
    try:
        feature_spec(str(features))
    except ValueError:
        raise SearchInputError(f"features={features} is no feature set; valid: {feature_names()}") from None
    if engine not in ENGINES:
        raise SearchInputError(f"engine={engine} is no search engine; valid: {list(ENGINES)}")
    if normalize not in NORMALIZATIONS:
        raise SearchInputError(f"normalize={normalize} is none of {list(NORMALIZATIONS)}")
    return str(features), positive_int(k, "k"), positive_int(top, "top")


def _number(value: Any) -> float:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else float("nan")


def _checked_search(eps: Any, radius: Any) -> tuple[float, float | None]:
    if not (_number(eps) >= 0 and np.isfinite(_number(eps))):
        raise SearchInputError(f"eps={eps} must be a finite number ≥ 0")
    if radius is not None and not (_number(radius) > 0 and np.isfinite(_number(radius))):
        raise SearchInputError(f"radius={radius} must be a positive number of feature units, or null")
    return _number(eps), None if radius is None else _number(radius)


def _checked_growth(k: int, k_max: Any, grow: Any, steps: Any, skip_cost: Any,
                    stable_for: Any = 1) -> tuple[int, str, str, float | None, int]:
    k_max = positive_int(k_max, "k_max")
    stable_for = positive_int(stable_for, "stable_for")
    if k_max < k:
        raise SearchInputError(f"k_max={k_max} is below k={k}: the growth bound must be at least the first k")
    if grow not in GROWTH:
        raise SearchInputError(f"grow={grow} is none of {list(GROWTH)}")
    if steps not in STEP_SETS:
        raise SearchInputError(f"steps={steps} is none of {list(STEP_SETS)}")
    if skip_cost is not None and not (_number(skip_cost) >= 0 and np.isfinite(_number(skip_cost))):
        raise SearchInputError(f"skip_cost={skip_cost} must be a finite number ≥ 0 (feature units), or null")
    return k_max, str(grow), str(steps), None if skip_cost is None else _number(skip_cost), stable_for


def search(data: Mapping[str, Any], query: str, out: str | os.PathLike, *, features: str = _D.features,
           k: int = _D.k, k_max: int = _D.k_max, grow: str = _D.grow, stable_for: int = _D.stable_for,
           refine: int = _D.refine, verify: bool = _D.verify, steps: str = _D.steps,
           skip_cost: float | None = _D.skip_cost, top: int = _D.top, eps: float = _D.eps,
           radius: float | None = _D.radius,
           engine: str = _D.engine, normalize: str = _D.normalize, exclude_query_take: bool = _D.exclude_query_take,
           retarget_query: bool = _D.retarget_query, conversion: Mapping[str, Any] | None = None,
           export_bvh: bool = ExportSettings.bvh, export_gif: bool = ExportSettings.gif,
           export_top: int = ExportSettings.top, figure_matches: int = FigureSettings.matches,
           figure_margin_s: float = FigureSettings.margin_s, force: bool = _D.force,
           command: str = "") -> dict[str, Any]:
    """Search ``data`` (a ``data`` config) for ``query`` and write the folder ``out`` (module docstring).

    The keyword defaults are :class:`~stylemotion.search.settings.SearchSettings`'s (what each key means).

    Returns:
        What ``search.json`` holds (its ``matches`` are ``matches.json``'s records).

    Raises:
        OutputExistsError: ``out`` exists and ``force`` is off (before any work).
        SearchInputError, ConfigError: a bad value (naming its key); nothing is written then.
    """
    started = time.perf_counter()
    out = check_new_output(out, force)
    features, k, top = _checked_settings(features, k, top, engine, normalize)
    eps, radius = _checked_search(eps, radius)
    k_max, grow, steps, skip_cost, stable_for = _checked_growth(k, k_max, grow, steps, skip_cost, stable_for)
    if isinstance(refine, bool) or not isinstance(refine, int) or refine < 0:
        raise SearchInputError(f"refine={refine} must be a whole number ≥ 0 (LNG candidates re-ranked; 0: off)")
    if not isinstance(verify, bool):
        raise SearchInputError(f"verify={verify} must be true or false")
    if verify and (steps != "thesis" or normalize != "none"):
        raise SearchInputError(f"verify=true needs steps=thesis and normalize=none (got steps={steps}, normalize="
                               f"{normalize}); set verify=false for these")
    export_top = positive_int(export_top, "export.top")
    figure_matches = positive_int(figure_matches, "figure.matches")
    try:
        takeset = build_dataset(data)
    except (KeyError, ValueError) as exc:
        message = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        raise SearchInputError(f"data={data.get('name')}: {message}") from None
    try:
        database = MotionDatabase.from_takeset(takeset)
    except ValueError as exc:
        raise SearchInputError(f"data={data.get('name')}: {exc}") from None
    q = load_query(query, takeset, database, conversion, retarget_query)
    if q.positions.shape[0] < 1:
        raise SearchInputError(f"query={query}: no frame left after conversion to {database.fps:g} fps")
    need = feature_spec(features).window_frames(database.fps)
    if q.positions.shape[0] < need:
        raise SearchInputError(f"query={query}: {q.positions.shape[0]} frames at {database.fps:g} fps is shorter "
                               f"than the window of features={features} ({need} frames)")
    exclude = (q.take,) if q.take is not None and exclude_query_take else ()
    available = database.num_frames - sum(database.take_slice(t).stop - database.take_slice(t).start for t in exclude)
    if k > available:
        raise SearchInputError(f"k={k} exceeds the database's {available} frames" +
                               (f" outside the query's take {exclude[0]}" if exclude else ""))
    log.info(f"database {database.name}: {database.num_takes} takes, {database.num_frames} frames at "
             f"{database.fps:g} fps; query {q.positions.shape[0]} frames")
    t0 = time.perf_counter()
    cfg_cache = data.get("cache_dir")
    index = FrameIndex.build(database, features, engine=engine, cache_dir=cfg_cache,
                             use_cache=bool(data.get("use_cache", True)))
    build_s = time.perf_counter() - t0
    try:
        result = search_motion(q.positions, index, k, top, exclude_takes=exclude, eps=eps, radius=radius,
                               normalize=normalize, k_max=k_max, grow=grow, stable_for=stable_for,
                               refine=refine, verify=verify, steps=STEP_SETS[steps],
                               skip_cost=skip_cost)
    except ValueError as exc:
        raise SearchInputError(f"query={query}: {exc}") from None
    records = [m.record() for m in result.matches]
    report = {
        "query": {"value": str(query), **q.record}, "features": features, "k": k, "k_max": k_max, "grow": grow,
        "stable_for": stable_for, "refine": refine, "verify": verify, "takes_verified": result.takes_verified,
        "k_used": result.k, "k_tried": list(result.k_tried), "steps": steps,
        "skip_cost": skip_cost, "top": top, "eps": eps,
        "radius": radius, "engine": engine, "normalize": normalize, "excluded_takes": list(result.excluded_takes),
        "database": {"name": database.name, "takes": database.num_takes, "frames": database.num_frames,
                     "fps": database.fps, "digest": database.digest},
        "index": {"cache": str(index.cache_path) if index.cache_path else None, "from_cache": index.from_cache,
                  "engine": index.engine},
        "timing_s": {"index": round(build_s, 4), **{key: round(v, 5) for key, v in result.timings.items()}},
        "matches": records,
        "paths": [m.path.tolist() for m in result.matches],
        "provenance": provenance(command or None),
    }
    with atomic_folder(out, on_exists=lambda: check_new_output(out, force)) as tmp:
        write_json(inside(tmp, "matches.json"), records)
        if result.matches:
            from stylemotion.search.figures import plot_distance_matrix

            plot_distance_matrix(result, index, inside(tmp, "distance_matrix.png"), figure_matches,
                                 int(round(figure_margin_s * database.fps)),
                                 f"{database.name}, features={features}, k={result.k}: query {query}")
        report["files"] = _exports(tmp, q, result, index, export_bvh, export_gif, export_top)
        report["timing_s"]["total"] = round(time.perf_counter() - started, 3)
        write_json(inside(tmp, "search.json"), report)
    if not records:
        log.info(f"no match: no path through the k-NN graph of the {q.positions.shape[0]} query frames at "
                 f"k={result.k} (tried {', '.join(map(str, result.k_tried))}); raise k_max (now {k_max})")
    elif len(records) < top and result.k < database.num_frames:
        log.info(f"{len(records)} of top={top} found: the {result.k} nearest frames of each query frame hold few "
                 f"paths; a larger k finds more (benchmarks/search.md)")
    if len(result.k_tried) > 1:
        log.info(f"k grew {' → '.join(map(str, result.k_tried))} (grow={grow}, stable_for={stable_for}, "
                 f"k_max={k_max}); k used {result.k}")
    log.info(f"{len(records)} match(es) written to {out}" + (f"; best: {records[0]['take']} "
                                                         f"{records[0]['start']}-{records[0]['end']} cost "
                                                         f"{records[0]['cost']:.4g}" if records else ""))
    return report


def _match_stem(match: SegmentMatch) -> str:
    return f"{match.rank:02d}_{safe_name(match.take, 'take name')}_{match.start}-{match.end}"


def _exports(folder: Path, q: Query, result: SearchResult, index: FrameIndex, bvh: bool, gif: bool,
             top: int) -> list[str]:
    """BVH and GIF files of the query and the best ``top`` matches; their paths relative to ``folder``."""
    if not (bvh or gif):
        return (["distance_matrix.png"] if result.matches else [])
    fps = index.database.fps
    motions = [("query", q.positions)]
    motions += [(_match_stem(m), index.database.positions[m.global_start:m.global_end]) for m in result.matches[:top]]
    written = ["distance_matrix.png"] if result.matches else []
    for stem, positions in motions:
        if bvh:
            from stylemotion.io.export import write_motion_bvh

            write_motion_bvh(positions, inside(folder, "bvh", f"{stem}.bvh"), fps)
            written.append(f"bvh/{stem}.bvh")
        if gif and positions.shape[0] >= 2:
            from stylemotion.skeleton import JOINT_INDEX
            from stylemotion.viz.walk import save_walk_animation

            root = np.asarray(positions)[:, JOINT_INDEX["Hips"]]
            save_walk_animation(positions, fps, root[:, [0, 2]], inside(folder, "gif", f"{stem}.gif"), title=stem)
            written.append(f"gif/{stem}.gif")
    return written


def search_from_config(cfg: DictConfig, command: str = "") -> dict[str, Any]:
    """:func:`search` with the keys of ``stylemotion/configs/search.yaml`` (:class:`SearchSettings`)."""
    data, settings = settings_from_config(cfg, SearchSettings, "search")
    return search(
        data, settings.query, settings.out, features=settings.features, k=settings.k, k_max=settings.k_max,
        grow=settings.grow, stable_for=settings.stable_for, refine=settings.refine, verify=settings.verify,
        steps=settings.steps,
        skip_cost=settings.skip_cost,
        top=settings.top,
        eps=settings.eps, radius=settings.radius, engine=settings.engine, normalize=settings.normalize,
        exclude_query_take=settings.exclude_query_take, retarget_query=settings.retarget_query,
        conversion=conversion_keys(vars(settings)), export_bvh=settings.export.bvh, export_gif=settings.export.gif,
        export_top=settings.export.top, figure_matches=settings.figure.matches,
        figure_margin_s=settings.figure.margin_s, force=settings.force, command=command)
