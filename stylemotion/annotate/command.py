"""``stylemotion-annotate``: learn class motion templates and tensors, or annotate a document with them.

Learning (no ``document=``): the dataset's train takes (its ``split``), ``per_class`` of each content for the
templates and up to ``repetitions`` per style for the tensors; ``out`` becomes a templates folder
(:mod:`stylemotion.annotate.model`).

Annotating (``document=<BVH>``, ``templates=<folder>``): the BVH is converted as datasets are (any skeleton a
joint map fits) at the model's fps and annotated (:mod:`stylemotion.annotate.annotation`); ``out`` gets

* ``labels.csv``: one row per frame, columns exactly ``frame,label`` (the class, empty where none);
* ``segments.json``: the settings, and each labelled run ``{label, start, end, cost}`` (frames, ``end``
  exclusive; ``cost`` the smallest ``Δ`` over it) with ``style``/``style_weights`` where the class has a tensor;
* ``timeline.png``: the class and sub-class segments over time (Fig. 3.1).

Outputs are written atomically into a new folder; an existing one is refused unless ``force``.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig

from stylemotion.annotate.annotation import (
    AnnotationInputError,
    AnnotationSettings,
    annotate_distances,
    class_distances,
    segments,
)
from stylemotion.annotate.feature_sets import (
    DEFAULT_FEATURE_SET,
    FeatureSetError,
    checked_feature_set,
    compute_features,
)
from stylemotion.annotate.model import AnnotationModel, ModelFolderError, learn_model, load_model, save_model
from stylemotion.annotate.settings import AnnotateSettings
from stylemotion.annotate.templates import TemplateInputError
from stylemotion.config import positive_int, settings_from_config
from stylemotion.datasets import build_dataset
from stylemotion.datasets.loading import ConversionSettings
from stylemotion.datasets.user_motion import UserMotionError, conversion_keys, convert_example, parse_example
from stylemotion.io.atomic import atomic_folder, atomic_write_bytes
from stylemotion.io.errors import UserInputError
from stylemotion.io.jsonfile import write_json
from stylemotion.io.outputs import check_new_output, inside
from stylemotion.provenance import provenance

log = logging.getLogger(__name__)
_D = AnnotateSettings


class AnnotateInputError(UserInputError, ValueError):
    """A ``stylemotion-annotate`` input that cannot be used; the message names the key and the value."""


def learn(data: Mapping[str, Any], out: str | os.PathLike, *, per_class: int = _D.per_class, seed: int = _D.seed,
          repetitions: int | None = _D.repetitions, tensors: bool = _D.tensors,
          feature_set: str | None = _D.feature_set, force: bool = _D.force, command: str = "") -> AnnotationModel:
    """Learn templates (and tensors) from ``data``'s train split and write the folder ``out`` (the keyword
    defaults are :class:`~stylemotion.annotate.settings.AnnotateSettings`'s; ``feature_set`` None: ours)."""
    out = check_new_output(out, force)
    try:
        feature_set = checked_feature_set(feature_set or DEFAULT_FEATURE_SET)
    except FeatureSetError as exc:
        raise AnnotateInputError(str(exc)) from None
    per_class = positive_int(per_class, "per_class")
    if repetitions is not None:
        repetitions = positive_int(repetitions, "repetitions")
    try:
        takeset = build_dataset(data)
    except (KeyError, ValueError) as exc:
        message = exc.args[0] if isinstance(exc, KeyError) and exc.args else exc
        raise AnnotateInputError(f"data={data.get('name')}: {message}") from None
    split = dict(data.get("split") or {})
    train = takeset.split(int(split.get("seed", 0)), float(split.get("val_fraction", 0.1)),
                          float(split.get("test_fraction", 0.1)))["train"]
    started = time.perf_counter()
    try:
        model = learn_model(train, takeset.fps, per_class, seed, repetitions, tensors, feature_set)
    except TemplateInputError as exc:
        raise AnnotateInputError(f"data={data.get('name')}: {exc}") from None
    extra = {"data": {k: v for k, v in data.items() if k in ("name", "root", "contents", "styles", "split")},
             "learn_s": round(time.perf_counter() - started, 3), "provenance": provenance(command or None)}
    with atomic_folder(out, on_exists=lambda: check_new_output(out, force)) as tmp:
        save_model(model, tmp, extra)
    log.info(f"{len(model.templates)} templates ({', '.join(model.classes)}; feature set {feature_set}) and "
             f"{len(model.tensors)} tensors from "
             f"{takeset.name}'s train takes written to {out}")
    for label, reason in model.record["tensors_skipped"].items():
        log.info(f"no tensor for {label}: {reason}")
    return model


def load_document(document: str, fps: float, conversion: Mapping[str, Any] | None = None) -> tuple[np.ndarray,
                                                                                                     dict[str, Any]]:
    """``(frames, 21, 3)`` positions of ``document=`` at ``fps`` and a JSON-ready record of the file."""
    try:
        spec = parse_example(document, key="document")
        if "::" not in spec.path and not Path(spec.path).expanduser().is_file():
            raise AnnotateInputError(f"document={document}: no such file")
        settings = ConversionSettings(fps=fps, **{k: v for k, v in (conversion or {}).items() if v is not None})
        example = convert_example(spec, settings)
    except UserMotionError as exc:
        raise AnnotateInputError(str(exc)) from None
    record = {"file": example.name, "sha256": example.sha256, "file_fps": example.file_fps,
              "file_frames": example.file_frames, "file_range": [example.start, example.end],
              "frames": int(example.positions.shape[0]), "fps": fps}
    return np.asarray(example.positions, dtype=np.float32), record


def annotate_positions(positions: np.ndarray, model: AnnotationModel,
                       settings: AnnotationSettings | None = None) -> tuple[list[str], list[dict[str, Any]]]:
    """Frame labels (``""`` where none) and segment records (with sub-class fits where a tensor exists)."""
    from stylemotion.annotate.turning import refine_annotation

    settings = settings or AnnotationSettings()
    distances = class_distances(compute_features(positions, model.fps, model.feature_set), model.templates,
                                settings)
    annotation = annotate_distances(distances, settings.tau, settings.keyframes, settings.min_run)
    annotation = refine_annotation(annotation, distances, positions, model.fps, model.templates,
                                   model.record.get("turning"), settings.tau, settings.turning_z,
                                   settings.turning_window_s, model.record.get("speed"))
    labels = annotation.label_names()
    records = []
    for start, end, label in segments(labels):
        record: dict[str, Any] = {"label": label, "start": start, "end": end,
                                  "cost": round(float(np.min(annotation.distance[start:end])), 5)}
        tensor = model.tensors.get(label)
        if tensor is not None and end - start >= 2:
            fit = tensor.parametrize(positions[start:end])
            record.update(style=fit.style, style_weights=dict(zip(tensor.styles, np.round(fit.style_weights, 4)
                                                                  .tolist())), fit_rms_m=round(fit.rms, 5))
        records.append(record)
    return labels, records


def annotate(document: str, templates: str | os.PathLike, out: str | os.PathLike, *,
             settings: AnnotationSettings | None = None, conversion: Mapping[str, Any] | None = None,
             feature_set: str | None = _D.feature_set, force: bool = _D.force, command: str = "") -> dict[str, Any]:
    """Annotate ``document`` with the model in ``templates`` and write the folder ``out`` (module docstring).
    ``feature_set``: None, or the set the folder must have been learned with (another is refused)."""
    started = time.perf_counter()
    settings = settings or AnnotationSettings()
    out = check_new_output(out, force)
    if not (isinstance(settings.tau, (int, float)) and settings.tau > 0):
        raise AnnotateInputError(f"tau={settings.tau} must be a positive number (the thesis used 0.13)")
    for key in ("turning_z", "turning_window_s", "sub_frames"):
        value = getattr(settings, key)
        if not (isinstance(value, (int, float)) and value >= 0):
            raise AnnotateInputError(f"{key}={value} must be a number ≥ 0 (0: off)")
    tolerance = settings.keyframe_tolerance
    if not (isinstance(tolerance, (int, float)) and 0 <= tolerance <= 1):
        raise AnnotateInputError(f"keyframes.tolerance={tolerance} must be a fraction in [0, 1] (of a key frame's "
                                 "features a matching frame may contradict)")
    try:
        model = load_model(templates)
        if feature_set is not None and checked_feature_set(feature_set) != model.feature_set:
            raise AnnotateInputError(f"feature_set={feature_set}: templates={templates} were learned with feature set "
                                     f"{model.feature_set!r}; drop the key or learn templates with {feature_set!r}")
    except (ModelFolderError, FeatureSetError) as exc:
        raise AnnotateInputError(str(exc)) from None
    positions, record = load_document(document, model.fps, conversion)
    shortest = min(model.templates, key=lambda t: t.num_frames)
    least = shortest.num_frames if settings.sub_frames <= 0 else min(settings.sub_frames, shortest.num_frames)
    if positions.shape[0] < least:
        raise AnnotateInputError(f"document={document}: {positions.shape[0]} frames at {model.fps:g} fps is shorter "
                                 f"than every template (the shortest, {shortest.label!r}, matches with {least})")
    try:
        labels, records = annotate_positions(positions, model, settings)
    except AnnotationInputError as exc:
        raise AnnotateInputError(f"document={document}: {exc}") from None
    report = {"document": {"value": str(document), **record}, "templates": str(templates),
              "classes": list(model.classes), "feature_set": model.feature_set, "tensors": sorted(model.tensors),
              "settings": {"tau": settings.tau, "keyframes": settings.keyframes,
                           "keyframe_count": settings.keyframe_count,
                           "keyframe_tolerance": settings.keyframe_tolerance, "min_run": settings.min_run,
                           "sub_frames": settings.sub_frames, "turning_z": settings.turning_z,
                           "turning_window_s": settings.turning_window_s,
                           "turning_layer": bool(settings.turning_z > 0 and (model.record.get("turning")
                                                                               or model.record.get("speed")))},
              "labelled_fraction": round(float(np.mean([lab != "" for lab in labels])), 4),
              "segments": records, "provenance": provenance(command or None)}
    with atomic_folder(out, on_exists=lambda: check_new_output(out, force)) as tmp:
        rows = "".join(f"{i},{lab}\n" for i, lab in enumerate(labels))
        atomic_write_bytes(inside(tmp, "labels.csv"), ("frame,label\n" + rows).encode())
        from stylemotion.annotate.figures import plot_timeline

        plot_timeline(records, list(model.classes), len(labels), model.fps, inside(tmp, "timeline.png"),
                      f"{record['file']}: tau={settings.tau}, key frames {'on' if settings.keyframes else 'off'}")
        report["timing_s"] = round(time.perf_counter() - started, 3)
        write_json(inside(tmp, "segments.json"), report)
    log.info(f"{len(records)} segment(s), {report['labelled_fraction']:.0%} of {len(labels)} frames labelled; "
             f"written to {out}")
    return report


def annotate_from_config(cfg: DictConfig, command: str = "") -> Any:
    """:func:`learn` (no ``document``) or :func:`annotate` with the keys of ``stylemotion/configs/annotate.yaml``
    (:class:`AnnotateSettings`)."""
    data, s = settings_from_config(cfg, AnnotateSettings, "annotate")
    if not s.document:
        return learn(data, s.out, per_class=s.per_class, seed=s.seed, repetitions=s.repetitions, tensors=s.tensors,
                     feature_set=s.feature_set, force=s.force, command=command)
    if not s.templates:
        raise AnnotateInputError("document= needs templates=<folder> (learn one with stylemotion-annotate "
                                 "data=<dataset> out=<folder>)")
    settings = AnnotationSettings(tau=s.tau, keyframes=s.keyframes.use,
                                  keyframe_count=positive_int(s.keyframes.count, "keyframes.count"),
                                  keyframe_tolerance=s.keyframes.tolerance, min_run=s.min_run,
                                  sub_frames=s.sub_frames, turning_z=s.turning_z,
                                  turning_window_s=s.turning_window_s)
    return annotate(str(s.document), s.templates, s.out, settings=settings, conversion=conversion_keys(vars(s)),
                    feature_set=s.feature_set, force=s.force, command=command)
