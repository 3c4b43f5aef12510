"""The motion graph of one action and one style (thesis §4.5, §5.4.4): primitives and their transitions.

Nodes are the six primitives of :mod:`stylemotion.primitives.segmentation` that have a trained model; edges
follow the foot that carries the body. A clip that ends at the transfer onto the **right** foot
(``leftStance``, ``beginLeftStance``) is followed by a clip in which the right foot is planted
(``rightStance`` or ``endRightStance``), and mirrored for the left foot::

    beginLeftStance ─▶ rightStance ─▶ leftStance ─▶ rightStance ─▶ … ─▶ endLeftStance
    beginRightStance ─▶ leftStance ─▶ …                          … ─▶ endRightStance

``end*`` primitives have no successor. Every node is a generative model: a neutral
:class:`~stylemotion.models.vae.PrimitiveVAE`, a :class:`~stylemotion.models.cvae.StyleCVAE` of the
chosen style, or a :class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE` bound to a style's example
(a ``stylemotion-style method=zero_shot`` folder, :func:`load_bound_style`), all decoding through one
autoencoder.

Models come from a ``stylemotion-reproduce`` run folder (its ``report/report.json`` lists every
evaluated checkpoint with its primitive and style), from a ``stylemotion-style`` folder (its
``report.json`` lists the new style's checkpoints and names the reproduce run it extends, whose
models — neutral and the run's styles — it offers as well), or from an explicit
``{primitive: checkpoint}`` mapping.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import torch

from stylemotion.config import ConfigError
from stylemotion.io.errors import UserInputError
from stylemotion.io.jsonfile import read_json
from stylemotion.models.autoencoder import IncompatibleModelError
from stylemotion.models.checkpoints import load_autoencoder
from stylemotion.models.loading import NEUTRAL, load_generative, load_model
from stylemotion.models.vae import PrimitiveVAE
from stylemotion.models.zero_shot import BoundExample, ZeroShotStyleVAE
from stylemotion.primitives.segmentation import PRIMITIVES, check_primitive
from stylemotion.representation import positions_to_frames

#: Successors of each primitive (by planted foot: a clip ending on foot f is followed by one planted on f).
TRANSITIONS: dict[str, tuple[str, ...]] = {
    "beginLeftStance": ("rightStance", "endRightStance"),
    "beginRightStance": ("leftStance", "endLeftStance"),
    "leftStance": ("rightStance", "endRightStance"),
    "rightStance": ("leftStance", "endLeftStance"),
    "endLeftStance": (),
    "endRightStance": (),
}
#: Prior samples drawn per primitive to measure its typical step (length, turn).
PROFILE_SAMPLES = 512
#: ``meta.kind`` in the ``report.json`` of a ``stylemotion-style`` folder.
STYLE_FOLDER_KIND = "style"


class RunFolderError(UserInputError, FileNotFoundError):
    """``run=`` names no finished run (or style folder), or one whose report lacks what synthesis needs."""


def _report_object(path: Path) -> dict:
    """The JSON object in a run's report (a cut-off or damaged file is named, with its line)."""
    value = read_json(path, "run report")
    if not isinstance(value, dict):
        raise RunFolderError(f"{path}: holds no JSON object; the run's report is damaged — rerun its evaluation")
    return value


class UnknownStyleError(UserInputError, KeyError):
    """The requested style has no trained model for a primitive the graph needs."""

    def __str__(self) -> str:  # KeyError quotes its message otherwise
        return str(self.args[0])


@dataclass(frozen=True)
class StepProfile:
    """What one primitive's model typically does, from :data:`PROFILE_SAMPLES` prior samples.

    Attributes:
        length_m: mean root displacement over a clip, metres.
        turn_rad: 99th percentile of the absolute heading change over a clip, radians (the sharpest
            turn the model takes in one step, give or take its tail).
        duration_s: mean clip duration, seconds.
    """

    length_m: float
    turn_rad: float
    duration_s: float


@dataclass
class MotionGraph:
    """Primitive models of one action and style, and the allowed transitions.

    Attributes:
        action: e.g. ``walk``.
        style: ``neutral`` or a style name.
        models: primitive name without the action (e.g. ``leftStance``) → model (eval mode, frozen): a
            PrimitiveVAE/StyleCVAE or a zero-shot network's :class:`BoundExample`.
        sources: primitive → checkpoint path.
        profiles: primitive → :class:`StepProfile` (filled by :meth:`profile`).
    """

    action: str
    style: str
    models: dict[str, PrimitiveVAE | BoundExample]
    sources: dict[str, str] = field(default_factory=dict)
    profiles: dict[str, StepProfile] = field(default_factory=dict)

    def __post_init__(self) -> None:
        unknown = sorted(set(self.models) - set(PRIMITIVES))
        if unknown:
            raise ValueError(f"unknown primitives {unknown}; primitives are {list(PRIMITIVES)}")
        if not {"leftStance", "rightStance"} <= set(self.models):
            raise ValueError(f"a {self.action} graph needs leftStance and rightStance models to walk any "
                             f"distance; it has {sorted(self.models)}")
        for model in self.models.values():
            model.eval().requires_grad_(False)

    @property
    def fps(self) -> float:
        return self.models["leftStance"].fps

    def successors(self, primitive: str) -> tuple[str, ...]:
        """Primitives with a model that may follow ``primitive``."""
        return tuple(p for p in TRANSITIONS[primitive] if p in self.models)

    def first(self, foot: str = "left") -> str:
        """The first primitive of a walk whose first planted foot is ``foot`` (``left``/``right``):
        ``begin<Foot>Stance`` if modelled, else ``<foot>Stance``."""
        if foot not in ("left", "right"):
            raise ValueError(f"first foot must be 'left' or 'right', got {foot!r}")
        begin = f"begin{foot.capitalize()}Stance"
        return begin if begin in self.models else f"{foot}Stance"

    def next(self, primitive: str, last: bool = False) -> str:
        """The primitive after ``primitive``: the ``end*`` successor when ``last`` and modelled, else
        the alternating stance."""
        options = self.successors(primitive)
        if not options:
            raise ValueError(f"{primitive} ends a walk; nothing follows it")
        ends = [p for p in options if p.startswith("end")]
        stances = [p for p in options if not p.startswith("end")]
        return ends[0] if last and ends else stances[0]

    @torch.no_grad()
    def profile(self, seed: int = 0) -> dict[str, StepProfile]:
        """Measure (and keep) each primitive's :class:`StepProfile` from prior samples."""
        from stylemotion.representation import integrate_root

        for primitive, model in self.models.items():
            samples = model.sample(PROFILE_SAMPLES, seed=seed)
            root, yaw = integrate_root(samples.frames.double(), samples.fps)
            last = (samples.num_frames - 1)[:, None]
            end_xz = torch.gather(root, 1, last[..., None].expand(-1, 1, 2))[:, 0]
            end_yaw = torch.gather(yaw, 1, last)[:, 0]
            self.profiles[primitive] = StepProfile(
                length_m=float(end_xz.norm(dim=-1).mean()),
                turn_rad=float(np.quantile(end_yaw.abs().numpy(), 0.99)),
                duration_s=float(samples.duration_s.mean()))
        return self.profiles


def style_folder_meta(run: str | Path) -> dict | None:
    """``meta`` of a ``stylemotion-style`` folder's ``report.json`` (``kind: style``), or None when ``run``
    is no such folder."""
    report = Path(run).expanduser() / "report.json"
    if not report.is_file():
        return None
    meta = _report_object(report).get("meta", {})
    return meta if meta.get("kind") == STYLE_FOLDER_KIND else None


def extended_run(folder: str | Path, meta: dict) -> Path:
    """The ``stylemotion-reproduce`` run a style folder extends: where it was (``meta.run``), else where it
    lies relative to the style folder (``meta.run_relative``: both moved together).

    Raises:
        FileNotFoundError: neither holds a finished run (``report/report.json``).
    """
    candidates = [Path(str(meta[key])) if key == "run" else Path(folder).expanduser() / str(meta[key])
                  for key in ("run", "run_relative") if meta.get(key)]
    for candidate in candidates:
        if (candidate / "report" / "report.json").is_file():
            return candidate
    raise RunFolderError(f"{folder} is a style that extends the stylemotion-reproduce run {meta.get('run')}, "
                            f"which is gone (looked at {[str(c) for c in candidates]}): put the run back, or give "
                            "models={primitive: checkpoint}")


def report_meta(run: str | Path) -> dict:
    """``meta`` of a ``stylemotion-reproduce`` run's ``report/report.json`` (checkpoints, autoencoder), or of
    a ``stylemotion-style`` folder's ``report.json`` (:func:`style_folder_meta`)."""
    style = style_folder_meta(run)
    if style is not None:
        return style
    report = Path(run).expanduser() / "report" / "report.json"
    if not report.is_file():
        raise RunFolderError(f"run={run}: {report} does not exist: point run= at a finished stylemotion-reproduce "
                             "folder (e.g. runs/reproduce/synthetic), or give models={primitive: checkpoint}")
    return _report_object(report).get("meta", {})


def available_models(run: str | Path, meta: dict | None = None) -> list[dict[str, Any]]:
    """Checkpoints of a ``stylemotion-reproduce`` run: ``[{primitive, name, style, path}]`` from its
    report's ``meta`` (read from ``run`` unless given; ``name`` is ``neutral`` or the style). For a
    ``stylemotion-style`` folder: its own style's checkpoints, then those of the run it extends; a zero-shot
    style's entries add ``example`` (its example file) and ``clips`` (``[start, stop)`` frames in it)."""
    meta = report_meta(run) if meta is None else meta
    if meta.get("kind") == STYLE_FOLDER_KIND:
        return [_style_entry(e, Path(run).expanduser()) for e in meta.get("checkpoints", [])] + available_models(
            extended_run(run, meta))
    entries = meta.get("checkpoints")
    if not entries:
        raise RunFolderError(f"{Path(run) / 'report' / 'report.json'}: meta.checkpoints is empty; no model to "
                             "synthesize with")
    return [{**{k: str(e[k]) for k in ("primitive", "name", "style")}, "path": recorded(e["path"], run, meta)}
            for e in entries]


def _style_entry(entry: Mapping[str, Any], folder: Path) -> dict[str, Any]:
    """An entry of a style folder's ``meta.checkpoints`` with its paths resolved: ``path`` (relative to the folder,
    or absolute; ``path_relative`` when that file is gone: both folders moved together) and ``example``."""
    out: dict[str, Any] = {k: str(entry[k]) for k in ("primitive", "name", "style")}
    path = Path(os.path.normpath(folder / entry["path"]))
    if not path.is_file() and entry.get("path_relative"):
        path = Path(os.path.normpath(folder / entry["path_relative"]))
    out["path"] = str(path)
    if entry.get("example"):  # one file, or several (``stylemotion-style example=[…]``: clips [start, stop, file])
        files = entry["example"]
        out["example"] = (os.path.normpath(folder / files) if isinstance(files, str)
                          else [os.path.normpath(folder / f) for f in files])
        out["clips"] = [[int(v) for v in clip] for clip in entry["clips"]]
    if isinstance(entry.get("sampling"), Mapping):  # how stylemotion-style sampled the network (folders since it)
        out["sampling"] = dict(entry["sampling"])
    return out


def load_bound_style(entry: Mapping[str, Any], autoencoder=None) -> BoundExample:
    """The zero-shot network of a style folder's entry (:func:`available_models`) bound again to the clips
    the style was made from: ``entry["example"]`` (``positions`` (frames, 21, 3) metres, ``fps``; or a list of such
    files) cut at ``entry["clips"]`` (``[start, stop]``, or ``[start, stop, file index]``), as ``stylemotion-style
    method=zero_shot`` bound them, sampling as it sampled them (``entry["sampling"]``,
    :meth:`ZeroShotStyleVAE.set_sampling`; folders made before that record: the checkpoint's own settings).

    Raises:
        FileNotFoundError: the checkpoint or the example file is gone.
        IncompatibleModelError: the checkpoint is no zero-shot network, or ``autoencoder`` is not its own.
    """
    network = load_generative(entry["path"], autoencoder)
    if not isinstance(network, ZeroShotStyleVAE):
        raise IncompatibleModelError(f"{entry['path']} is a {type(network).__name__}, not the zero-shot network the "
                                     f"style {entry['name']} records")
    files = [entry["example"]] if isinstance(entry["example"], (str, os.PathLike)) else list(entry["example"])
    frames = []
    for example in map(Path, files):
        if not example.is_file():
            raise RunFolderError(f"style {entry['name']}: its example {example} is gone; the zero-shot network "
                                 "samples the style only with it")
        with np.load(example) as npz:
            frames.append(positions_to_frames(npz["positions"], float(npz["fps"]))[0])
    clips = [_Frames(frames[clip[2] if len(clip) > 2 else 0][clip[0]:clip[1]]) for clip in entry["clips"]]
    if entry.get("sampling"):
        try:
            network.set_sampling(entry["sampling"])
        except ValueError as exc:
            raise RunFolderError(f"style {entry['name']}: its recorded sampling is not usable: {exc}") from None
    return network.bind_example(clips, entry["name"])


@dataclass(frozen=True)
class _Frames:
    """A clip as :meth:`ZeroShotStyleVAE.bind_example` reads one: ``frames`` ``(frames, 66)``."""

    frames: np.ndarray


def recorded(path: str | Path, run: str | Path, meta: dict | None = None) -> str:
    """A path from a run's report: a relative one is relative to the folder ``meta.paths_relative_to``
    names (from ``<run>/report``; reports of runs before that key: absolute paths, see :func:`relocated`)."""
    path = Path(path).expanduser()
    if path.is_absolute():
        return relocated(path, run)
    base = Path(run).expanduser() / "report" / str((meta or {}).get("paths_relative_to", ".."))
    return os.path.normpath(base / path)


def relocated(path: str | Path, run: str | Path) -> str:
    """``path`` as recorded in a run's report, or, when the run folder has been moved or copied since,
    the same file under ``run`` (the longest tail of ``path`` that exists below ``run``)."""
    path = Path(path)
    if path.is_file():
        return str(path)
    for start in range(1, len(path.parts)):
        candidate = Path(run) / Path(*path.parts[start:])
        if candidate.is_file():
            return str(candidate)
    return str(path)  # load_model names the missing file


def run_autoencoder(run: str | Path, meta: dict | None = None):
    """The autoencoder of a ``stylemotion-reproduce`` run (report ``meta.autoencoder``, located like
    the checkpoints), checked against its recorded fingerprint; None if the report names none or the
    file is gone (the models then use the autoencoder embedded in their checkpoints)."""
    meta = report_meta(run) if meta is None else meta
    if meta.get("kind") == STYLE_FOLDER_KIND:  # the new style's models were trained on the run's autoencoder
        return run_autoencoder(extended_run(run, meta))
    info = meta.get("autoencoder") or {}
    if not info.get("path"):
        return None
    path = Path(recorded(info["path"], run, meta))
    if not path.is_file():
        return None
    return load_autoencoder(path, expected=info if info.get("fingerprint") else None)


def load_graph(style: str, run: str | Path | None = None, models: Mapping[str, str] | None = None,
               action: str = "walk", neutral_style: str = "normal") -> MotionGraph:
    """A :class:`MotionGraph` for ``style`` (``neutral``, the data's neutral style name, or a style).

    Args:
        style: which models: ``neutral`` (or ``neutral_style``) picks the neutral VAEs, anything else
            the StyleCVAEs trained for that style.
        run: a ``stylemotion-reproduce`` or ``stylemotion-style`` folder to take checkpoints from (see
            :func:`available_models`).
        models: explicit ``{primitive: checkpoint}`` (``walk_leftStance`` or ``leftStance``); overrides ``run``.
        action: the action whose primitives to use.
        neutral_style: the data's name of the neutral style (Bandai: ``normal``).

    Raises:
        UnknownStyleError: no model of ``style`` (the message lists the styles there are).
    """
    wanted = NEUTRAL if style in (NEUTRAL, neutral_style) else style
    if models:
        chosen: dict[str, dict[str, Any]] = {short_primitive(k, action): {"path": str(v)} for k, v in models.items()}
    elif run is not None:
        meta = report_meta(run)
        entries = [e for e in available_models(run, meta) if e["primitive"].startswith(f"{action}_")]
        chosen = {short_primitive(e["primitive"], action): e for e in entries if e["name"] == wanted}
        if not chosen:
            have = sorted({e["name"] for e in entries})
            raise UnknownStyleError(f"style {style!r} has no {action} model in {run}; styles there: {have} "
                                    f"('{NEUTRAL}' = the neutral VAEs)")
    else:
        raise ConfigError("give run=<stylemotion-reproduce folder> or models={primitive: checkpoint}")
    paths = {p: e["path"] for p, e in chosen.items()}
    loaded: dict[str, PrimitiveVAE | BoundExample] = {}
    autoencoder = run_autoencoder(run, meta) if not models else None  # models= names its own checkpoints
    for primitive, path in sorted(paths.items()):
        if chosen[primitive].get("example"):  # a zero-shot style: its network, bound to the style's example
            loaded[primitive] = load_bound_style(chosen[primitive], autoencoder)
            autoencoder = loaded[primitive].autoencoder
            continue
        entry = load_model(path, neutral_style=neutral_style, autoencoder=autoencoder)
        if entry.name != wanted:
            raise UnknownStyleError(f"{path} models style {entry.name!r}, not {style!r}")
        loaded[primitive] = entry.source
        autoencoder = entry.source.autoencoder  # one autoencoder for all (load_model checks it is the same)
    return MotionGraph(action=action, style=wanted, models=loaded, sources=paths)


def short_primitive(primitive: str, action: str) -> str:
    """``walk_leftStance`` (or ``leftStance``) → ``leftStance``, checked."""
    return check_primitive(primitive.split("_", 1)[1] if primitive.startswith(f"{action}_") else primitive)
