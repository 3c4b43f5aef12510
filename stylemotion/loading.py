"""One loader for every model the commands write: :func:`load` (``stylemotion.load``).

What :func:`load` reads, and what it returns:

=====================================================  ==========================  ====================
path                                                   written by                  returns
=====================================================  ==========================  ====================
``*.ckpt`` of a VAE, CVAE or zero-shot network         ``stylemotion-train``       :class:`Model`
``*.ckpt`` of an autoencoder                           ``stylemotion-train``       :class:`Model` (no sampling)
a training run folder (``checkpoints/best.ckpt``)      ``stylemotion-train``       :class:`Model`
``model.npz`` or its run folder (Morphable Graph)      ``stylemotion-train         :class:`Model`
                                                       experiment=morphable_graph``
a reproduce run folder (``reproduce.json``)            ``stylemotion-reproduce``   :class:`ModelSet`
a style folder (``report.json``, ``kind: style``)      ``stylemotion-style``       :class:`ModelSet`
=====================================================  ==========================  ====================

Both kinds share one sampling interface, ``sample(n, seed=0, example=None)`` → the project's
:class:`~stylemotion.models.sampling.MotionSamples` (``positions`` ``(n, frames, 21, 3)`` metres at ``fps``), and
``describe()`` → a :class:`Description` (kind, primitive, style, data, the command that trained it and its commit,
from the provenance the runs record). A :class:`ModelSet` also takes ``style=`` and ``primitive=`` to pick one of its
models (:meth:`ModelSet.model`). The models themselves load as the commands load them
(:func:`stylemotion.models.loading.load_generative`, :meth:`stylemotion.morphable.MorphableModel.load`,
:func:`stylemotion.synthesis.graph.available_models`); this module only finds out which one a path is.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.io.errors import UserInputError
from stylemotion.io.jsonfile import JsonFileError, read_json

log = logging.getLogger(__name__)

#: What :func:`load` tells apart (:attr:`Description.kind`).
KINDS = ("autoencoder", "vae", "cvae", "zero_shot", "morphable", "reproduce", "style")
#: Kinds that sample (a :class:`Model` of another kind refuses ``sample``).
SAMPLING_KINDS = ("vae", "cvae", "zero_shot", "morphable")
#: Row name of the neutral models of a run (the thesis' "neutral").
NEUTRAL = "neutral"


class LoadError(UserInputError, ValueError):
    """A path :func:`load` cannot read as a model, or a request the model cannot answer (sampling an autoencoder, a
    zero-shot network without an example, a style a run does not have); the message names it and says what it
    expected."""


class NotFoundError(UserInputError, FileNotFoundError):
    """A path that does not exist."""


@dataclass
class Description:
    """What a loaded model is and where it came from (``print`` shows one line per field that is known).

    Attributes:
        kind: one of :data:`KINDS`.
        path: the file or folder loaded.
        primitive: ``<action>_<primitive>`` (e.g. ``walk_leftStance``) of a single model, else None.
        style: the style it produces: ``neutral`` for a plain VAE, the data's style a Morphable Graph model was fitted
            on (``all``: every style), else None (a zero-shot network: the example's).
        data: the data set it was trained on (e.g. ``synthetic``, ``bandai``), or None where not recorded.
        command: the command line that trained it, or None where not recorded.
        commit: the git commit of the code that trained it (``+dirty`` with uncommitted changes), or None.
        models: a run or style folder's models: ``[{primitive, name, style, path}]``; empty for one model.
    """

    kind: str
    path: str
    primitive: str | None = None
    style: str | None = None
    data: str | None = None
    command: str | None = None
    commit: str | None = None
    models: list[dict[str, str]] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    def __str__(self) -> str:
        lines = [f"{key}: {value}" for key, value in self.as_dict().items()
                 if value not in (None, []) and key != "models"]
        if self.models:
            names = sorted({m["name"] for m in self.models})
            primitives = sorted({m["primitive"] for m in self.models})
            lines.append(f"models: {len(self.models)} ({', '.join(names)} × {', '.join(primitives)})")
        return "\n".join(lines)


# -- provenance


def _json(path: Path) -> dict[str, Any]:
    """A JSON object file, or ``{}`` when missing or unreadable (provenance is best effort)."""
    if not path.is_file():
        return {}
    try:
        value = read_json(path, path.name)
    except JsonFileError:
        log.warning("cannot read %s; its provenance is left out", path)
        return {}
    return value if isinstance(value, dict) else {}


def run_provenance(folder: Path) -> dict[str, Any]:
    """The latest start of a run folder's ``run.json`` (``command``, ``git_commit``, …), or ``{}``."""
    starts = _json(folder / "run.json").get("starts") or []
    return dict(starts[-1]) if starts and isinstance(starts[-1], dict) else {}


def _checkpoint_run(path: Path) -> Path:
    """The run folder of a checkpoint (``<run>/checkpoints/<name>.ckpt``), else the checkpoint's folder."""
    return path.parent.parent if path.parent.name == "checkpoints" else path.parent


# -- one model


def _is_motion_file(example: Any) -> bool:
    """``example`` names motion file(s): a path, or a non-empty list or tuple of paths."""
    if isinstance(example, (str, os.PathLike)):
        return True
    return (isinstance(example, (list, tuple)) and bool(example)
            and all(isinstance(e, (str, os.PathLike)) for e in example))


def _motion_file_example(value: str | os.PathLike | Sequence[str | os.PathLike], primitive: str, fps: float) -> list:
    """The clips of ``primitive`` (else of its action) cut from motion file(s) ``file.bvh[:start-end]`` (one, or a
    list: the clips of all, pooled as ``stylemotion-style example=[…]`` pools them,
    :func:`stylemotion.style_example.example.cut_examples`) at ``fps`` (default segmentation settings)."""
    from stylemotion.datasets.loading import ConversionSettings
    from stylemotion.datasets.user_motion import convert_example
    from stylemotion.primitives.segmentation import parse_primitive
    from stylemotion.style_example.example import cut_examples, parse_examples

    value = os.fspath(value) if isinstance(value, os.PathLike) else value
    examples = [convert_example(spec, ConversionSettings(fps=fps)) for spec in parse_examples(value)]
    action = parse_primitive(primitive)[0]
    return cut_examples(examples, "example", action, [primitive], None).used[primitive]


class Model:
    """One trained model (see the module doc); ``model`` is the object underneath (a
    :class:`~stylemotion.models.vae.PrimitiveVAE`, :class:`~stylemotion.models.cvae.StyleCVAE`,
    :class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE`, a zero-shot network's
    :class:`~stylemotion.models.zero_shot.BoundExample`, :class:`~stylemotion.models.MotionAutoencoder` or
    :class:`~stylemotion.morphable.MorphableModel`)."""

    def __init__(self, kind: str, path: Path, model: Any, description: Description):
        self.kind, self.path, self.model, self._description = kind, path, model, description

    def __repr__(self) -> str:
        d = self._description
        return f"<stylemotion Model {d.kind} {d.primitive or ''} {d.style or ''} from {d.path}>".replace("  ", " ")

    @property
    def primitive(self) -> str | None:
        return self._description.primitive

    @property
    def style(self) -> str | None:
        return self._description.style

    @property
    def fps(self) -> float:
        """Frame rate of the motions it samples."""
        return float(self.model.fps if hasattr(self.model, "fps") else self.model.hparams["fps"])

    def describe(self) -> Description:
        """Kind, primitive, style, data, training command and commit (see :class:`Description`)."""
        return self._description

    def sample(self, n: int, seed: int | None = 0, example: Any = None) -> Any:
        """``n`` motions of this model's primitive (:class:`~stylemotion.models.sampling.MotionSamples`).

        Args:
            n: how many.
            seed: the same seed gives the same motions (None: a fresh draw).
            example: only for a zero-shot network that was not bound to one: the style to produce, as a motion file
                (``walk.bvh`` or ``walk.bvh:120-480``, cut into this primitive's steps) or a list of them (several
                examples: the network is conditioned on the clips of all, their mean embedding, as
                ``stylemotion-style example=[…]``), clip(s) with ``frames`` ``(frames, 66)``, or autoencoder
                features ``(C, T')``.

        Raises:
            LoadError: the model does not sample (an autoencoder), or ``example`` is missing or not wanted.
        """
        if self.kind not in SAMPLING_KINDS:
            raise LoadError(f"{self.path} is an {self.kind}: it encodes and decodes motion (model.encode/decode) but "
                            "does not sample; load a VAE, CVAE, zero-shot or Morphable Graph model")
        from stylemotion.models.zero_shot import ZeroShotStyleVAE

        if isinstance(self.model, ZeroShotStyleVAE):
            if example is None:
                raise LoadError(f"{self.path} is a zero-shot style network: it samples the style of an example; "
                                "pass example='walk.bvh:120-480' (or clips or features)")
            if _is_motion_file(example):
                example = _motion_file_example(example, self.primitive, self.fps)
            return self.model.sample(n, seed=seed, example=example)
        if example is not None:
            raise LoadError(f"{self.path} is a {self.kind} model of style {self.style!r}: its style is built in, so it "
                            "takes no example (a zero-shot network does)")
        return self.model.sample(n, seed=seed)


def _checkpoint_model(path: Path, autoencoder: Any = None) -> Model:
    from stylemotion.models.checkpoints import checkpoint_kind, read_checkpoint

    checkpoint = read_checkpoint(path, "checkpoint")
    hparams = checkpoint.get("hyper_parameters") or {}
    kind = checkpoint_kind(hparams if isinstance(hparams, Mapping) else {})
    if kind is None:
        raise LoadError(f"{path} is a checkpoint of no stylemotion model (neither an autoencoder nor a VAE, CVAE "
                        "or zero-shot network)")
    provenance = run_provenance(_checkpoint_run(path))
    if kind == "autoencoder":
        from stylemotion.models.checkpoints import load_autoencoder

        data = ((checkpoint.get("datamodule_hyper_parameters") or {}).get("data") or {}).get("name")
        return Model(kind, path, load_autoencoder(path),
                     Description(kind, str(path), data=data, command=provenance.get("command"),
                                 commit=provenance.get("git_commit")))
    from stylemotion.models.loading import load_generative

    model = load_generative(path, autoencoder)
    spec = hparams["spec"]
    style = str(spec["style"]) if kind == "cvae" else None if kind == "zero_shot" else NEUTRAL
    return Model(kind, path, model,
                 Description(kind, str(path), primitive=str(spec.get("primitive")), style=style,
                             data=spec.get("dataset"), command=provenance.get("command"),
                             commit=provenance.get("git_commit")))


def _morphable_model(path: Path) -> Model:
    from stylemotion.morphable import MorphableModel

    try:
        model = MorphableModel.load(path)
    except (OSError, ValueError, KeyError) as err:
        raise LoadError(f"{path}: not a Morphable Graph model file ({err})") from None
    provenance = run_provenance(path.parent)
    return Model("morphable", path, model,
                 Description("morphable", str(path), primitive=model.primitive_name, style=model.style_name,
                             data=model.meta.get("data"),
                             command=provenance.get("command"), commit=provenance.get("git_commit")))


# -- a run or style folder


class ModelSet:
    """The models of a ``stylemotion-reproduce`` run or a ``stylemotion-style`` folder (a style folder also offers
    the models of the run it extends). Each is loaded on first use and kept.

    Attributes:
        kind: ``reproduce`` or ``style``.
        path: the folder.
        entries: ``[{primitive, name, style, path}]``: ``name`` is ``neutral`` for the neutral VAEs, else the style.
        default_style: what :meth:`sample` draws without ``style=`` (a style folder's new style, else ``neutral``).
    """

    def __init__(self, kind: str, path: Path, entries: list[dict[str, Any]], description: Description,
                 default_style: str):
        self.kind, self.path, self.entries = kind, path, entries
        self.default_style = default_style
        self._description = description
        self._loaded: dict[tuple[str, str], Model] = {}
        self._autoencoder: Any = None

    def __repr__(self) -> str:
        return (f"<stylemotion ModelSet {self.kind} from {self.path}: styles {self.styles}, "
                f"primitives {self.primitives}>")

    @property
    def styles(self) -> list[str]:
        """Model names: ``neutral`` first, then the styles, in the order the folder records them."""
        return list(dict.fromkeys(e["name"] for e in self.entries))

    @property
    def primitives(self) -> list[str]:
        return list(dict.fromkeys(e["primitive"] for e in self.entries))

    def describe(self) -> Description:
        """Kind, data, the command that made the folder and its commit, and the models it holds."""
        return self._description

    def model(self, style: str | None = None, primitive: str | None = None) -> Model:
        """One model of the folder: ``style`` (a name of :attr:`styles`; default :attr:`default_style`) and
        ``primitive`` (default: the first the folder has of that style).

        Raises:
            LoadError: no such model (the message lists the ones there are).
        """
        style = self.default_style if style is None else str(style)
        chosen = [e for e in self.entries if e["name"] == style and (primitive is None or e["primitive"] == primitive)]
        if not chosen:
            raise LoadError(f"{self.path} has no model of style {style!r}"
                            + (f" and primitive {primitive!r}" if primitive else "")
                            + f"; styles: {self.styles}, primitives: {self.primitives}")
        entry = chosen[0]
        key = (entry["name"], entry["primitive"])
        if key not in self._loaded:
            self._loaded[key] = self._load_entry(entry)
        return self._loaded[key]

    def _load_entry(self, entry: Mapping[str, Any]) -> Model:
        from stylemotion.synthesis.graph import load_bound_style, run_autoencoder

        if self._autoencoder is None:
            self._autoencoder = run_autoencoder(self.path)
        path = Path(entry["path"])
        if entry.get("example"):  # a zero-shot style: its network bound again to the style's example clips
            bound = load_bound_style(entry, self._autoencoder)
            provenance = run_provenance(_checkpoint_run(path))
            loaded = Model("zero_shot", path, bound,
                           Description("zero_shot", str(path), primitive=str(entry["primitive"]),
                                       style=str(entry["name"]), data=self._description.data,
                                       command=provenance.get("command"), commit=provenance.get("git_commit")))
        else:
            loaded = _checkpoint_model(path, self._autoencoder)
        self._autoencoder = self._autoencoder or loaded.model.autoencoder  # one autoencoder for all its models
        return loaded

    def sample(self, n: int, seed: int | None = 0, example: Any = None, *, style: str | None = None,
               primitive: str | None = None) -> Any:
        """``n`` motions of one of the folder's models (:meth:`model`; see :meth:`Model.sample`)."""
        return self.model(style, primitive).sample(n, seed=seed, example=example)


def _records(entries: Sequence[Mapping[str, Any]]) -> list[dict[str, str]]:
    return [{k: str(e[k]) for k in ("primitive", "name", "style", "path")} for e in entries]


def _reproduce_set(folder: Path) -> ModelSet:
    from stylemotion.synthesis.graph import available_models

    summary = _json(folder / "reproduce.json")
    provenance = summary.get("provenance") or {}
    data = (summary.get("data") or {}).get("name")
    if not (folder / "report" / "report.json").is_file():
        raise LoadError(f"{folder} is a stylemotion-reproduce run that has not finished (no report/report.json); "
                        "run it to the end (the same command resumes it), or load one of its checkpoints")
    entries = available_models(folder)
    return ModelSet("reproduce", folder, entries,
                    Description("reproduce", str(folder), data=data, command=provenance.get("command"),
                                commit=provenance.get("git_commit"),
                                models=_records(entries)),
                    NEUTRAL)


def _style_set(folder: Path, meta: Mapping[str, Any]) -> ModelSet:
    from stylemotion.synthesis.graph import available_models

    entries = available_models(folder, dict(meta))
    return ModelSet("style", folder, entries,
                    Description("style", str(folder), style=str(meta.get("name")),
                                data=meta.get("data_name") or (meta.get("data") or {}).get("name"),
                                command=meta.get("command"), commit=meta.get("git_commit"),
                                models=_records(entries)),
                    str(meta.get("name")))


# -- the loader


def load(path: str | os.PathLike) -> Model | ModelSet:
    """The model(s) at ``path``, whatever command wrote them (the table in the module doc).

    Args:
        path: a checkpoint (``.ckpt``: VAE, CVAE, zero-shot network or autoencoder), a ``stylemotion-train`` run
            folder, a Morphable Graph ``model.npz`` (or its run folder), a ``stylemotion-reproduce`` run folder or a
            ``stylemotion-style`` folder.

    Returns:
        :class:`Model` for one model, :class:`ModelSet` for a reproduce or style folder; both have
        ``sample(n, seed=0, example=None)`` (→ :class:`~stylemotion.models.sampling.MotionSamples`) and
        ``describe()`` (→ :class:`Description`).

    Raises:
        NotFoundError: nothing at ``path``.
        LoadError: something that is none of these (the message says what was looked for).

    Example::

        run = stylemotion.load("runs/reproduce/synthetic")
        print(run.describe())                                   # kind, data, command, commit, its models
        motions = run.sample(100, seed=0, style="elderly")      # positions (100, frames, 21, 3) metres
        vae = stylemotion.load("runs/reproduce/synthetic/vae/walk_leftStance")   # one model
        network = stylemotion.load("runs/style/mine/network/walk_leftStance")    # a zero-shot network:
        tired = network.sample(10, seed=0, example="my_walk.bvh:120-480")        #   the example's style
        tired = network.sample(10, seed=0, example=["a.bvh", "b.bvh:0-900"])     #   several examples' style
    """
    from stylemotion.synthesis.graph import style_folder_meta

    path = Path(path).expanduser()
    if not path.exists():
        raise NotFoundError(f"{path} does not exist: give a checkpoint (.ckpt), a model.npz, or a run folder of "
                            "stylemotion-train, stylemotion-reproduce or stylemotion-style")
    if path.is_file():
        if path.suffix == ".npz":
            return _morphable_model(path)
        return _checkpoint_model(path)
    meta = style_folder_meta(path)
    if meta is not None:
        return _style_set(path, meta)
    if (path / "reproduce.json").is_file():
        return _reproduce_set(path)
    if (path / "model.npz").is_file():
        return _morphable_model(path / "model.npz")
    for name in ("best.ckpt", "last.ckpt"):
        if (path / "checkpoints" / name).is_file():
            return _checkpoint_model(path / "checkpoints" / name)
    raise LoadError(f"{path} is a folder of no stylemotion model: it holds no checkpoints/best.ckpt "
                    "(stylemotion-train), model.npz (Morphable Graph), reproduce.json (stylemotion-reproduce) or "
                    "report.json of kind 'style' (stylemotion-style)")


def sample(model: str | os.PathLike | Model | ModelSet, n: int, seed: int | None = 0, example: Any = None,
           **choice: Any) -> Any:
    """``n`` motions of a model in one call: :func:`load` then ``sample``.

    Args:
        model: a path :func:`load` reads, or a model it returned.
        n: how many motions.
        seed: the same seed gives the same motions (None: a fresh draw).
        example: a zero-shot network's style example (see :meth:`Model.sample`).
        choice: ``style=`` and ``primitive=`` of a run or style folder (:meth:`ModelSet.model`).

    Returns:
        :class:`~stylemotion.models.sampling.MotionSamples`: ``positions`` ``(n, frames, 21, 3)`` metres at ``fps``,
        padded past each ``num_frames[i]`` (``samples.motion(i)`` is motion ``i`` alone).

    Example::

        motions = stylemotion.sample("runs/reproduce/synthetic", 16, seed=1, style="youthful")
    """
    loaded = model if isinstance(model, (Model, ModelSet)) else load(model)
    if choice and not isinstance(loaded, ModelSet):
        raise LoadError(f"{loaded.path} is one model; style=/primitive= choose among a run folder's models")
    return loaded.sample(n, seed=seed, example=example, **choice)


def as_arrays(samples: Any) -> list[np.ndarray]:
    """Each motion of a :class:`~stylemotion.models.sampling.MotionSamples` without its padding:
    ``[(frames_i, 21, 3)]`` float32 metres."""
    return [samples.motion(i).numpy() for i in range(len(samples))]


__all__: Sequence[str] = ["KINDS", "Description", "LoadError", "Model", "ModelSet", "NotFoundError", "as_arrays",
                          "load", "run_provenance", "sample"]
