"""The tasks of a researcher's day as Python calls (``stylemotion.<name>``; the notebooks in ``notebooks/`` use them).

Each call is the library function of a command, with the command's defaults (their dataclasses), so a notebook
and the shell give the same result:

====================================  =========================  ==============================================
call                                  the command                returns
====================================  =========================  ==============================================
:func:`evaluate`                      ``stylemotion-eval``       the report (``report.json``'s contents)
:func:`walk`                          ``stylemotion-generate``   the walk's summary; ``<out>/motion.npz|bvh``
:func:`search_motion`                 ``stylemotion-search``     the search record (``search.json``)
:func:`reconstruct_motion`            ``stylemotion-reconstruct`` the summary; ``<out>/motion.npz``
:func:`learn_templates`,              ``stylemotion-annotate``   the templates; the labels and segments
:func:`annotate_motion`
====================================  =========================  ==============================================

Every call writes the command's output folder ``out`` (refused if it exists unless ``force=True``), so what a
notebook made can be opened with ``stylemotion-view`` or read by the next command. ``data`` is a data set's name
(``"synthetic"``, ``"bandai"``, ``"bvh_folder"``) with keyword overrides (:func:`data_config`), or a whole ``data``
config mapping. (``search``, ``reconstruct`` and ``annotate`` are the names of the wings' packages, so their calls
are :func:`search_motion`, :func:`reconstruct_motion` and :func:`annotate_motion`.)
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from stylemotion.io.errors import UserInputError


def data_config(name: str | Mapping[str, Any] = "synthetic", **overrides: Any) -> dict[str, Any]:
    """A ``data`` config as the commands take it: the packaged ``configs/data/<name>.yaml`` with ``overrides``
    (nested keys as dicts, e.g. ``split={"seed": 1}``), plain values.

    Args:
        name: ``synthetic`` (the embedded generator), ``bandai`` or ``bvh_folder`` (give ``root=``), or a whole
            ``data`` config mapping.
        overrides: keys of that config (``configs/data/<name>.yaml`` lists them).

    Example:

    >>> data_config("synthetic", takes_per_pair=2, styles=["normal", "elderly"])["takes_per_pair"]
    2
    """
    from omegaconf import OmegaConf

    from stylemotion.config import config_dir

    if isinstance(name, Mapping):
        base = OmegaConf.create(dict(name))
    else:
        path = Path(config_dir()) / "data" / f"{name}.yaml"
        if not path.is_file():
            have = sorted(p.stem for p in path.parent.glob("*.yaml"))
            raise UserInputError(f"data={name!r}: no such data set config; one of {have}")
        base = OmegaConf.load(path)
    merged = OmegaConf.merge(base, OmegaConf.create(dict(overrides)))
    return OmegaConf.to_container(merged, resolve=True)


def _run_data(run: Path) -> dict[str, Any] | None:
    """The ``data`` config a reproduce run was trained and evaluated on (``report/report.json`` ``meta.data``)."""
    from stylemotion.io.jsonfile import read_json

    report = run / "report" / "report.json"
    if not report.is_file():
        return None
    meta = read_json(report, "report").get("meta") or {}
    return dict(meta["data"]) if isinstance(meta.get("data"), Mapping) else None


def evaluate(models: str | os.PathLike | Sequence[str | os.PathLike], out: str | os.PathLike, *,
             data: str | Mapping[str, Any] | None = None, samples: int | None = None, seed: int = 0,
             force: bool = False, **evaluation: Any) -> dict[str, Any]:
    """Evaluate models as ``stylemotion-eval`` does: Tables 5.1–5.3, held-out style recognition, Fréchet distance,
    diversity, foot skating, nearest-clip distance; writes ``out`` (``report.md``, ``report.html``, CSVs, figures).

    Args:
        models: a ``stylemotion-reproduce`` run folder, or checkpoints and folders holding them.
        out: the report folder.
        data: the data to compare with (:func:`data_config`); default: the run's own data (a run folder given).
        samples: samples per model for every table and metric (default: the command's, 1,000 and 10,000).
        seed: seeds sampling and the classifier.
        force: replace an existing ``out``.
        evaluation: further ``evaluation.*`` keys (:class:`~stylemotion.evaluation.settings.EvalSettings`).

    Returns:
        What ``report.json`` holds (``tables``, ``models``, ``meta``, …).

    Example::

        report = stylemotion.evaluate("runs/reproduce/synthetic", "runs/eval/mine", samples=200)
    """
    from stylemotion.evaluation.run import run_evaluation

    paths = [models] if isinstance(models, (str, os.PathLike)) else list(models)
    if data is None:
        found = [_run_data(Path(p).expanduser()) for p in paths if Path(p).expanduser().is_dir()]
        data_cfg = next((d for d in found if d), None)
        if data_cfg is None:
            raise UserInputError("evaluate: give data= (e.g. data='synthetic'); it is read from a "
                                 "stylemotion-reproduce run folder only")
    else:
        data_cfg = data_config(data)
    if samples is not None:
        evaluation = {**evaluation, "samples": {"table_5_1": int(samples), "variance": int(samples),
                                                "metrics": int(samples)}}
    return run_evaluation(data_cfg, [str(p) for p in paths], evaluation, out, seed=seed, force=force)


def _path_node(path: Any) -> dict[str, Any]:
    if path is None:
        return {}
    if isinstance(path, (str, os.PathLike)):
        return {"file": str(path)}
    if isinstance(path, Mapping):
        return dict(path)
    return {"points": [[float(x), float(z)] for x, z in path]}


def walk(run: str | os.PathLike | Mapping[str, Any], out: str | os.PathLike, *, style: str = "neutral",
         path: Any = None, seed: int = 0, morphable: bool = False, bvh: bool = True, gif: bool = False,
         force: bool = False, **keys: Any) -> dict[str, Any]:
    """A walk along a ground path, as ``stylemotion-generate`` makes it (thesis §5.4.4): the primitive models step
    along the path, the steps are stitched, the feet cleaned up; writes ``out``: ``motion.npz`` (``positions``
    ``(frames, 21, 3)`` metres, ``fps``, ``path``), ``motion.bvh``, ``summary.json`` (and ``motion.gif``).

    Args:
        run: a ``stylemotion-reproduce`` or ``stylemotion-style`` folder; or ``{primitive: checkpoint}``; with
            ``morphable=True``: ``{primitive: Morphable Graph run folder or model.npz}``.
        out: the folder written.
        style: ``neutral`` or a style the run has models of.
        path: ``[(x, z), …]`` metres (a spline through them), a ``.csv``/``.json`` path file, a ``path`` config
            mapping, or None: a 10 m S-curve.
        seed: another seed, another walk along the same path.
        morphable: walk with Morphable Graph primitives (Du ch. 3–4) instead of the VAEs.
        bvh, gif: write ``motion.bvh`` and ``motion.gif``.
        force: replace an existing ``out``.
        keys: further keys of ``stylemotion-generate`` (``follow={"candidates": 64}``, ``clean_feet=False``, …).

    Returns:
        ``summary.json``'s contents: path deviation, speed, foot skating, steps, the BVH round trip, provenance.

    Example::

        summary = stylemotion.walk("runs/reproduce/synthetic", "runs/generate/elderly", style="elderly",
                                   path=[(0, 0), (0, 4), (3, 7)])
    """
    from stylemotion.synthesis.generate import generate

    cfg: dict[str, Any] = {"out": str(out), "style": style, "seed": int(seed), "path": _path_node(path),
                           "force": force, "outputs": {"bvh": bvh, "gif": gif}, **keys}
    if isinstance(run, Mapping):
        cfg["models"] = {str(k): (str(v) if isinstance(v, (str, os.PathLike)) else [str(p) for p in v])
                         for k, v in run.items()}
    elif morphable:
        raise UserInputError("walk(morphable=True) takes {primitive: model folder or model.npz}, e.g. "
                             "{'walk_leftStance': 'runs/train/left', 'walk_rightStance': 'runs/train/right'}")
    else:
        cfg["run"] = str(run)
    if morphable:
        cfg["model"] = {"family": "morphable"}
    return generate(cfg, "stylemotion.walk")


def search_motion(query: str | os.PathLike, out: str | os.PathLike, *, data: str | Mapping[str, Any] = "synthetic",
                  force: bool = False, **keys: Any) -> dict[str, Any]:
    """The database segments most like a query motion, as ``stylemotion-search`` finds them (Krüger §2.4.1: k-NN of
    every query frame, then the best paths through the lazy neighbourhood graph, the best made exact DTW's with
    ``verify=True``, the default); writes ``out``: ``matches.json``,
    ``search.json``, ``distance_matrix.png`` (the thesis' Fig. 2.8).

    Args:
        query: a BVH file ``walk.bvh[:start-end]`` (frames of the file) or a take of the data set
            ``<take>[:start-end]``.
        out: the folder written.
        data: the database (:func:`data_config`).
        force: replace an existing ``out``.
        keys: ``features`` (``E15``, ``E15x3``, …), ``k``, ``top``, ``eps``, … (``stylemotion-search --help``).

    Returns:
        ``search.json``'s contents; ``["matches"]``: ``[{take, content, style, start, end, cost}]``, best first.

    Example::

        found = stylemotion.search_motion("synthetic_walk_elderly_000:30-90", "runs/search/mine", top=5)
    """
    from stylemotion.search.command import search

    data_cfg = data_config(data) if isinstance(data, str) else dict(data)
    return search(data_cfg, str(query), out, force=force, command="stylemotion.search_motion", **keys)


def reconstruct_motion(markers: str | os.PathLike, out: str | os.PathLike, *,
                       data: str | Mapping[str, Any] = "synthetic", force: bool = False, **keys: Any) -> dict[str, Any]:
    """Whole-body motion from a few marker tracks, as ``stylemotion-reconstruct`` makes it (Krüger §4.2: the
    nearest database poses of each frame's markers and a local pose model); writes ``out``: ``motion.npz``
    (``positions`` ``(frames, 21, 3)`` metres, ``fps``), ``summary.json``.

    Args:
        markers: a CSV/NPZ/BVH of marker tracks, or a take of the data set ``<take>[:start-end]`` (its six
            default markers: hands, feet, head, hips; the take is then left out of the database and the error
            against it is measured).
        out: the folder written.
        data: the database (:func:`data_config`).
        force: replace an existing ``out``.
        keys: ``features``, ``k``, ``joints``, ``noise_mm``, ``model={…}`` (``stylemotion-reconstruct --help``).

    Returns:
        ``summary.json``'s contents (``error``: ``mean_cm``, ``max_cm`` when the truth is known).

    Example::

        summary = stylemotion.reconstruct_motion("synthetic_walk_normal_000:0-120", "runs/reconstruct/mine")
    """
    from stylemotion.reconstruct.command import reconstruct_command

    data_cfg = data_config(data) if isinstance(data, str) else dict(data)
    return reconstruct_command(data_cfg, str(markers), out, force=force, command="stylemotion.reconstruct_motion",
                               **keys)


def learn_templates(out: str | os.PathLike, *, data: str | Mapping[str, Any] = "synthetic", force: bool = False,
                    **keys: Any) -> Any:
    """Motion templates (and motion tensors) of each content class of ``data``'s train split, as
    ``stylemotion-annotate`` learns them (Krüger ch. 3, §4.1); writes ``out`` for :func:`annotate_motion`.

    Args:
        out: the templates folder.
        data: the labelled data (:func:`data_config`).
        force: replace an existing ``out``.
        keys: ``per_class``, ``seed``, ``repetitions``, ``tensors`` (``stylemotion-annotate --help``).

    Returns:
        The :class:`~stylemotion.annotate.model.AnnotationModel` (``classes``, ``templates``, ``tensors``).
    """
    from stylemotion.annotate.command import learn

    data_cfg = data_config(data) if isinstance(data, str) else dict(data)
    return learn(data_cfg, out, force=force, command="stylemotion.learn_templates", **keys)


def annotate_motion(document: str | os.PathLike, templates: str | os.PathLike, out: str | os.PathLike, *,
                    tau: float | None = None, force: bool = False, **keys: Any) -> dict[str, Any]:
    """Label every frame of a motion with the templates' classes, as ``stylemotion-annotate document=…`` does;
    writes ``out``: ``labels.csv`` (frame, label), ``segments.json``, ``timeline.png``.

    Args:
        document: a BVH file ``capture.bvh[:start-end]``.
        templates: a folder :func:`learn_templates` (or ``stylemotion-annotate``) wrote.
        out: the folder written.
        tau: the match threshold (default: the command's, the thesis' 0.13).
        force: replace an existing ``out``.
        keys: further :class:`~stylemotion.annotate.annotation.AnnotationSettings` fields (``keyframes``,
            ``min_run``, …).

    Returns:
        ``segments.json``'s contents; ``["segments"]``: ``[{label, start, end, cost, (style)}]``.
    """
    from stylemotion.annotate.annotation import AnnotationSettings
    from stylemotion.annotate.command import annotate

    settings = AnnotationSettings(**({"tau": tau} if tau is not None else {}), **keys)
    return annotate(str(document), templates, out, settings=settings, force=force,
                    command="stylemotion.annotate_motion")


__all__ = ["annotate_motion", "data_config", "evaluate", "learn_templates", "reconstruct_motion", "search_motion",
           "walk"]
