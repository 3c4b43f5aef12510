"""What the evaluation evaluates: anything that samples motions of a primitive, plus what it targets.

A :class:`SampleSource` has ``sample(n, seed) -> MotionSamples`` (:mod:`stylemotion.models.sampling`):
the trained :class:`~stylemotion.models.vae.PrimitiveVAE` and
:class:`~stylemotion.models.cvae.StyleCVAE` are sources, and so is :class:`RealClipSource`
(real clips drawn with replacement: an "oracle model" for tests and reference rows). A
:class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE` becomes one model per example it is bound to
(:func:`zero_shot_models`): the styles' own example clips, or a user's recording (:func:`read_user_example`).
:class:`EvalModel` wraps a source with the primitive it models, the style it targets and the style
example it was conditioned on; :func:`load_model` makes one from a checkpoint. Those three and
:data:`NEUTRAL` live with the models (:mod:`stylemotion.models.loading`, the one loading path) and are
named here too, as the evaluation's inputs.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

from stylemotion.io.errors import UserInputError
from stylemotion.models.autoencoder import IncompatibleModelError
from stylemotion.models.loading import EvalModel, zero_shot_model
from stylemotion.models.sampling import MotionSamples, pad_motions
from stylemotion.primitives.segmentation import Clip, time_normalize


class MixedAutoencodersError(IncompatibleModelError):
    """Models of one evaluation were trained on features of different autoencoders."""


class MissingExampleError(UserInputError, ValueError):
    """A style model's example clip cannot be found (or does not match) in the evaluation data."""


class EvaluationInputError(UserInputError, ValueError):
    """Models that cannot be evaluated together (two of one primitive and name, another data set, a row without a
    model of its primitive)."""


#: The file of a Morphable Graph model (``stylemotion-train experiment=morphable_graph``) in its run folder.
MORPHABLE_FILE = "model.npz"
#: Row name of a Morphable Graph model in Tables 5.1–5.3: ``morphable`` (the neutral style's, as
#: ``stylemotion-reproduce morphable=true`` names it), ``morphable:<style>`` for another style (``all``: every style).
MORPHABLE_ROW = "morphable"


def is_morphable_entry(entry: str) -> bool:
    """Whether a ``checkpoints=`` entry is a Morphable Graph model: a ``.npz`` file, or a folder holding
    ``model.npz`` (its run folder)."""
    path = Path(str(entry)).expanduser()
    return (path.is_file() and path.suffix == ".npz") or (path.is_dir() and (path / MORPHABLE_FILE).is_file())


@dataclass
class MorphableRows:
    """Morphable Graph models as rows of Tables 5.1–5.3: ``rows`` ``{primitive: {row: model}}`` (:data:`MORPHABLE_ROW`)
    (each samples ``MotionSamples``, time-normalized onto the evaluation's timeline by the pipeline), ``records``
    one ``{path, primitive, name, style, kind}`` per model for the report's ``meta.checkpoints``."""

    rows: dict[str, dict[str, Any]]
    records: list[dict[str, Any]]


def morphable_rows(entries: Sequence[str], data_name: str, fps: float, neutral_style: str = "normal") -> MorphableRows:
    """Load Morphable Graph models (:func:`is_morphable_entry`) as rows beside the evaluated VAE/CVAEs: a Morphable
    Graph has no autoencoder features or style example, so it gets the rows the shift baseline gets (Tables
    5.1–5.3), not recognition or a Table 5.1 column.

    Raises:
        EvaluationInputError: a model of another data set or frame rate, one without a recorded primitive, or two
            of one primitive and style (one line naming the file).
    """
    from stylemotion.morphable.model import MorphableModel

    rows: dict[str, dict[str, Any]] = defaultdict(dict)
    records = []
    for entry in entries:
        path = Path(str(entry)).expanduser()
        path = path / MORPHABLE_FILE if path.is_dir() else path
        try:
            model = MorphableModel.load(path)
        except (OSError, ValueError, KeyError) as err:
            raise EvaluationInputError(f"{path}: not a Morphable Graph model file ({err})") from None
        primitive, style, data = model.primitive_name, model.style_name, model.meta.get("data")
        if not primitive:
            raise EvaluationInputError(f"{path}: a Morphable Graph model without a recorded primitive")
        if data not in (None, "None") and data != data_name:
            raise EvaluationInputError(f"{path} was fitted on data set {data!r}, not {data_name!r}")
        if not math.isclose(float(model.fps), float(fps), rel_tol=1e-6):
            raise EvaluationInputError(f"{path} samples at {model.fps:g} fps, the data at {fps:g} fps: fit it on "
                                       "the evaluated data")
        name = MORPHABLE_ROW if style == neutral_style else f"{MORPHABLE_ROW}:{style}"
        if name in rows[primitive]:
            raise EvaluationInputError(f"{path}: two Morphable Graph models of {primitive} and style {style}")
        rows[primitive][name] = model
        records.append({"path": str(path), "primitive": primitive, "name": name, "style": style,
                        "kind": "morphable"})
    return MorphableRows(dict(rows), records)


def check_one_autoencoder(models: Sequence[EvalModel], fingerprint: str | None = None) -> str | None:
    """The one autoencoder fingerprint all models share (and ``fingerprint`` if given).

    Raises:
        MixedAutoencodersError: naming each autoencoder and the checkpoints trained on it.
    """
    groups: dict[str, list[str]] = defaultdict(list)
    paths: dict[str, str] = {}
    for m in models:
        if m.autoencoder is None:
            continue
        fp = str(m.autoencoder.get("fingerprint"))
        groups[fp].append(m.checkpoint or m.label)
        paths[fp] = str(m.autoencoder.get("path"))
    if fingerprint is not None and groups and set(groups) != {fingerprint}:
        others = {fp: v for fp, v in groups.items() if fp != fingerprint}
        raise MixedAutoencodersError(
            f"the evaluation's autoencoder has weights {fingerprint}, but these models were trained on features of "
            "another autoencoder: " + "; ".join(f"weights {fp} ({paths[fp]}): {v}" for fp, v in others.items())
            + ". Evaluate them with their own autoencoder_ckpt, in a separate evaluation")
    if len(groups) > 1:
        raise MixedAutoencodersError(
            "the models were trained on features of different autoencoders and cannot share one evaluation "
            "(Table 5.1 re-encodes every sample with one autoencoder): "
            + "; ".join(f"weights {fp} ({paths[fp]}): {v}" for fp, v in groups.items())
            + ". Evaluate each group separately")
    return fingerprint if fingerprint is not None else next(iter(groups), None)


def motions_from_clips(clips: Sequence[Clip], length: int) -> MotionSamples:
    """Real clips as :class:`MotionSamples`: recorded positions and frames (padded by holding the last
    frame), real durations, and frames resampled to the canonical ``length`` (``normalized_frames``).
    ``features`` is empty ``(n, 0, 0)`` (real clips have no sampled features)."""
    if not clips:
        raise ValueError("no clip")
    positions, num_frames = pad_motions([c.positions for c in clips])
    frames, _ = pad_motions([c.frames for c in clips])
    normalized = torch.from_numpy(np.stack([time_normalize(c.frames, length) for c in clips]))
    duration = torch.tensor([c.duration_s for c in clips], dtype=torch.float32)
    return MotionSamples(positions, frames, num_frames, duration, torch.zeros(len(clips), 0, 0), normalized,
                         float(clips[0].fps))


class RealClipSource:
    """Real clips drawn uniformly with replacement, as a :class:`SampleSource` (an oracle model).

    Args:
        clips: the clips to draw from.
        length: the canonical timeline, frames.
    """

    def __init__(self, clips: Sequence[Clip], length: int):
        self.motions = motions_from_clips(clips, length)

    def sample(self, n: int, seed: int | None = None) -> MotionSamples:
        if n < 1:
            raise ValueError(f"n must be ≥ 1, got {n}")
        index = torch.from_numpy(np.random.default_rng(seed).integers(0, len(self.motions), n))
        return self.motions.subset(index)


# -- zero-shot networks: one model per example


@dataclass
class UserExample:
    """A user's recording that zero-shot networks are bound to (``stylemotion-eval example=… example_style=…``).

    Attributes:
        spec: what ``example=`` named (files and frame ranges), for messages and records.
        style: the data's style the recording shows (its samples' ground truth and recognition target).
        clips: primitive → the recording's clips of that primitive (cut as ``stylemotion-style`` cuts an example;
            where it has none of a primitive, every clip of the same action).
        records: primitive → plain-value records of those clips (file, sha256, frames, take, start, stop, …).
    """

    spec: str
    style: str
    clips: dict[str, list]
    records: dict[str, list[dict[str, Any]]]


def read_user_example(files: Any, style: str, takeset, primitives: Sequence[str], segment: Mapping[str, Any] | Any,
                      neutral_style: str = "normal", conversion: Mapping[str, Any] | None = None) -> UserExample:
    """``example=`` of ``stylemotion-eval``: a motion file ``<BVH>[:start-end]`` or a list of them, read exactly as
    ``stylemotion-style`` reads its examples (:func:`stylemotion.style_example.example.parse_examples`, each converted
    and put on the data's skeleton, then :func:`~stylemotion.style_example.example.cut_examples` with the
    evaluation's segmentation: the clips of each primitive pooled over the files). ``conversion``: the files'
    ``joint_map``, ``unit_scale``, ``up_axis`` (None or missing: auto-detected, Y up).

    Raises:
        MissingExampleError: no zero-shot network's ``primitives`` to condition, ``style`` missing, no file, a file
            that cannot be read or put on the data's skeleton (a joint map no skeleton fits), or a recording without
            one whole step of a primitive's action (each one line naming ``example=``).
    """
    from stylemotion.datamodules.features import describe_clip
    from stylemotion.datasets.loading import ConversionSettings
    from stylemotion.datasets.user_motion import UserMotionError, convert_example, on_run_skeleton
    from stylemotion.primitives.segmentation import parse_primitive
    from stylemotion.style_example.example import cut_examples, parse_examples

    if hasattr(files, "_content") and not isinstance(files, str):  # an OmegaConf list from the command line
        from omegaconf import OmegaConf

        files = OmegaConf.to_container(files, resolve=True)
    shown = ", ".join(map(str, files)) if isinstance(files, (list, tuple)) else str(files)
    if not primitives:
        raise MissingExampleError(f"example={shown} conditions zero-shot networks, but checkpoints= holds none "
                                  "(VAE/CVAE checkpoints carry their style themselves)")
    if not style:
        raise MissingExampleError(f"example={shown} needs example_style=<a style of the data>: the style the "
                                  "recording shows (its samples' ground truth and recognition target)")
    segment = asdict(segment) if not isinstance(segment, Mapping) else dict(segment)
    clips: dict[str, list] = {}
    records: dict[str, list[dict[str, Any]]] = {}
    try:
        options = {k: v for k, v in dict(conversion or {}).items() if v is not None}
        converted = [on_run_skeleton(convert_example(spec, ConversionSettings(fps=takeset.fps, **options)), takeset,
                                     neutral_style) for spec in parse_examples(files)]
        for action in dict.fromkeys(parse_primitive(p)[0] for p in primitives):
            cut = cut_examples(converted, style, action, [p for p in primitives if parse_primitive(p)[0] == action],
                               segment)
            for p, used in cut.used.items():
                clips[p] = list(used)
                records[p] = [{**describe_clip(c), **r} for c, r in zip(used, cut.records[p])]
    except UserMotionError as err:
        raise MissingExampleError(str(err)) from None
    return UserExample(shown, str(style), clips, records)


def zero_shot_models(models: Sequence[EvalModel], user: UserExample | None = None) -> list[EvalModel]:
    """``models`` with each zero-shot network (an unbound :class:`EvalModel`, ``load_model(…, zero_shot=True)``)
    replaced by one model per example (:func:`stylemotion.models.loading.zero_shot_model`, row
    ``zero_shot:<style>``):

    * ``user``: the user's recording, bound now (its clips are not the data's);
    * else, per style, the example clip(s) of the evaluated CVAE of the network's primitive and that style (as
      the leave-one-style-out evaluation conditions it, :mod:`stylemotion.evaluation.zero_shot`); without a
      CVAE of its primitive, each style's example as the network records it (``spec.style_examples_by_style``,
      the clip a StyleCVAE of that style takes by default; the neutral style left out). Those clips are found
      in the evaluation data and bound there (:func:`stylemotion.evaluation.pipeline.real_side`).

    Raises:
        MissingExampleError: a network with no example (``user`` without clips of its primitive, or nothing else).
    """
    out: list[EvalModel] = []
    for m in models:
        if not m.unbound:
            out.append(m)
            continue
        network = m.source
        if user is not None:
            if not user.clips.get(m.primitive):
                raise MissingExampleError(f"example={user.spec} has no clip for {m.checkpoint} (primitive "
                                          f"{m.primitive})")
            out.append(zero_shot_model(network, user.style, user.records[m.primitive], user.clips[m.primitive],
                                       user_clips=True))
            continue
        cvaes = [c for c in models if c.kind == "cvae" and c.primitive == m.primitive]
        neutral = network.spec.get("neutral_style")
        chosen = ([(c.style, c.examples) for c in cvaes] if cvaes else
                  [(s, [r]) for s, r in (network.spec.get("style_examples_by_style") or {}).items() if s != neutral])
        if not chosen:
            raise MissingExampleError(f"{m.checkpoint} is a zero-shot style network and nothing gives it an example: "
                                      "evaluate it with CVAEs of its primitive (their examples), or give "
                                      "example=<BVH>[:start-end] example_style=<style>")
        out += [zero_shot_model(network, style, records) for style, records in chosen]
    return out
