"""Learning an annotation model from a labelled dataset, and its folder on disk.

A model is the class motion templates (one per content label) plus, where a class has at least two styles of
two or more train takes, its class motion tensor. The folder holds ``model.json`` (classes, the feature set and
its feature names, fps, settings, the takes used, provenance), ``templates.npz`` (``<class>``: ``(frames,
features)`` values) and ``tensors.npz`` (``<class>/core``, ``<class>/U1..U4``, ``<class>/reference``; styles in
``model.json``).
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.annotate.feature_sets import (
    DEFAULT_FEATURE_SET,
    FeatureSetError,
    checked_feature_set,
    compute_features,
    feature_names,
    same_feature_set,
)
from stylemotion.annotate.templates import DELTA, MotionTemplate, TemplateInputError, learn_template
from stylemotion.annotate.tensors import MotionTensor, TensorInputError, build_tensor
from stylemotion.annotate.turning import speed_statistics, turning_statistics
from stylemotion.datasets.base import Take
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.errors import UserInputError
from stylemotion.io.jsonfile import read_json, write_json
from stylemotion.io.npzfile import load_npz
from stylemotion.io.outputs import inside

MODEL_FORMAT = 1


class ModelFolderError(UserInputError, ValueError):
    """A templates folder that cannot be read; the message names the file and what is wrong."""


@dataclass
class AnnotationModel:
    """Templates and tensors of a set of classes at ``fps``; ``record``: what ``model.json`` says besides."""

    templates: list[MotionTemplate]
    tensors: dict[str, MotionTensor]
    fps: float
    record: dict[str, Any] = field(default_factory=dict)

    @property
    def classes(self) -> tuple[str, ...]:
        return tuple(t.label for t in self.templates)

    @property
    def feature_set(self) -> str:
        """The one relational feature set of the templates (:class:`FeatureSetError` if they mix sets)."""
        return same_feature_set((t.feature_set for t in self.templates), "the model's templates")


def choose_examples(takes: Sequence[Take], per_class: int, seed: int) -> dict[str, list[Take]]:
    """Up to ``per_class`` takes of every content, drawn with ``seed`` (sorted by name first)."""
    rng = np.random.default_rng(seed)
    by: dict[str, list[Take]] = {}
    for take in sorted(takes, key=lambda t: t.name):
        by.setdefault(take.content, []).append(take)
    chosen = {}
    for content in sorted(by):
        group = by[content]
        order = rng.permutation(len(group))[:per_class]
        chosen[content] = [group[i] for i in sorted(order)]
    return chosen


def tensor_examples(takes: Sequence[Take], content: str, repetitions: int | None = None,
                    seed: int = 0) -> dict[str, list[np.ndarray]]:
    """Style → ``(frames, 21, 3)`` motions of ``content`` for its tensor: the same number of takes per style,
    ``repetitions`` (None or more than every style has: as many as every style has), drawn with ``seed`` from
    the takes sorted by name (kept in name order); styles with under two takes are left out."""
    rng = np.random.default_rng(seed)
    by_style: dict[str, list[Take]] = {}
    for take in sorted(takes, key=lambda t: t.name):
        if take.content == content:
            by_style.setdefault(take.style, []).append(take)
    usable = {s: v for s, v in sorted(by_style.items()) if len(v) >= 2}
    counts = [len(v) for v in usable.values()] or [0]
    r = min(min(counts), repetitions or min(counts))
    return {s: [v[i].positions for i in sorted(rng.permutation(len(v))[:r])] for s, v in usable.items()}


def learn_model(train: Sequence[Take], fps: float, per_class: int = 9, seed: int = 0,
                tensor_repetitions: int | None = None, tensors: bool = True,
                feature_set: str = DEFAULT_FEATURE_SET) -> AnnotationModel:
    """Templates (of relational features in ``feature_set``, :mod:`.feature_sets`) from ``per_class`` train takes
    of each content; tensors from the train takes of a content
    (``tensor_repetitions`` per style, None: as many as every style has, drawn with ``seed``:
    :func:`tensor_examples`; a class with under two styles of two takes gets no tensor).

    Raises:
        TemplateInputError: a content with fewer than two train takes (naming it and the count).
    """
    feature_set = checked_feature_set(feature_set)
    examples = choose_examples(train, per_class, seed)
    if not examples:
        raise TemplateInputError("no train takes to learn templates from")
    templates = [learn_template(c, [compute_features(t.positions, fps, feature_set) for t in takes],
                                feature_set=feature_set) for c, takes in examples.items()]
    learned: dict[str, MotionTensor] = {}
    skipped: dict[str, str] = {}
    if tensors:
        for content in examples:
            usable = tensor_examples(train, content, tensor_repetitions, seed)
            try:
                learned[content] = build_tensor(content, usable, fps)[0]
            except TensorInputError as exc:
                skipped[content] = str(exc)
    by_class = {c: [t.positions for t in train if t.content == c] for c in examples}
    turning, speed = turning_statistics(by_class, fps), speed_statistics(by_class, fps)
    record = {"examples": {c: [t.name for t in takes] for c, takes in examples.items()},
              "turning": turning, "speed": speed,
              "tensor_repetitions": tensor_repetitions, "tensors_skipped": skipped, "seed": seed}
    return AnnotationModel(templates, learned, fps, record)


def _npz(arrays: dict[str, np.ndarray]) -> bytes:
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    return buffer.getvalue()


def save_model(model: AnnotationModel, folder: Path, extra: dict[str, Any] | None = None) -> None:
    """Write the three files into ``folder`` (an existing, empty staging folder)."""
    templates = {t.label: t.values for t in model.templates}
    tensors: dict[str, np.ndarray] = {}
    for label, tensor in model.tensors.items():
        tensors[f"{label}/core"] = tensor.core
        tensors[f"{label}/reference"] = tensor.reference
        for n, f in enumerate(tensor.factors, 1):
            tensors[f"{label}/U{n}"] = f
    feature_set = model.feature_set
    meta = {
        "format": MODEL_FORMAT, "fps": model.fps, "feature_set": feature_set,
        "features": list(feature_names(feature_set)), "delta": DELTA,
        "classes": [{"label": t.label, "frames": t.num_frames, "examples": t.examples} for t in model.templates],
        "tensors": {label: {"styles": list(t.styles), "repetitions": t.repetitions, "ranks": list(t.ranks),
                            "frames": t.frames} for label, t in model.tensors.items()},
        **model.record, **(extra or {}),
    }
    atomic_write_bytes(inside(folder, "templates.npz"), _npz(templates))
    atomic_write_bytes(inside(folder, "tensors.npz"), _npz(tensors))
    write_json(inside(folder, "model.json"), meta)


def load_model(folder: str | Path) -> AnnotationModel:
    """Read a folder written by :func:`save_model`.

    Raises:
        ModelFolderError: a missing file, another format or feature set, a class without its arrays.
    """
    folder = Path(folder).expanduser()
    meta_path = folder / "model.json"
    if not meta_path.is_file():
        raise ModelFolderError(f"templates={folder}: no model.json there (learn one with "
                               f"stylemotion-annotate data=<dataset> out={folder})")
    meta = read_json(meta_path, "annotation model's record", f"learn the model again (stylemotion-annotate "
                     f"data=<dataset> out={folder})")
    if not isinstance(meta, dict):
        raise ModelFolderError(f"{meta_path}: holds a {type(meta).__name__}, not an object; learn the model again")
    try:   # folders from before feature sets hold ours
        feature_set = checked_feature_set(meta.get("feature_set", DEFAULT_FEATURE_SET), f"{meta_path}: feature_set")
    except FeatureSetError as exc:
        raise ModelFolderError(str(exc)) from None
    names = list(feature_names(feature_set))
    if meta.get("format") != MODEL_FORMAT or meta.get("features") != names:
        raise ModelFolderError(f"{meta_path}: format {meta.get('format')!r} with {len(meta.get('features') or [])} "
                               f"features; this version reads format {MODEL_FORMAT} with the {len(names)} of "
                               f"feature set {feature_set!r}")
    arrays = load_npz(folder / "templates.npz", "annotation templates")  # NpzFileError: names the file
    npz = load_npz(folder / "tensors.npz", "annotation tensors")
    try:
        fps = float(meta["fps"])
        templates = [MotionTemplate(c["label"], np.array(arrays[c["label"]]), int(c["examples"]),
                                    float(meta["delta"]), feature_set) for c in meta["classes"]]
        wrong = [t.label for t in templates if t.values.ndim != 2 or t.values.shape[1] != len(names)]
        if wrong:
            raise ValueError(f"templates {wrong} do not have the {len(names)} columns of feature set {feature_set!r}")
        tensors = {}
        for label, info in meta.get("tensors", {}).items():
            tensors[label] = MotionTensor(label, tuple(info["styles"]), int(info["repetitions"]),
                                          np.array(npz[f"{label}/reference"]), np.array(npz[f"{label}/core"]),
                                          tuple(np.array(npz[f"{label}/U{n}"]) for n in range(1, 5)),
                                          fps)
    except (OSError, KeyError, TypeError, ValueError) as exc:
        raise ModelFolderError(f"templates={folder}: its arrays do not match model.json ({exc})") from None
    return AnnotationModel(templates, tensors, fps, meta)
