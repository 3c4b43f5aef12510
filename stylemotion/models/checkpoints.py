"""Reading checkpoints: the one place that opens a checkpoint file of this package.

Every read goes through :func:`read_checkpoint`, which calls ``torch.load(..., weights_only=True)``
explicitly, so only tensors and plain values are unpickled on every torch the package admits (the
default changed in torch 2.6). Models are rebuilt from the checkpoint's plain hyperparameters
(:func:`restore`), not through Lightning's loader, whose ``weights_only`` default depends on its
version.

What a checkpoint is, from its hyperparameters (:func:`checkpoint_kind`): a
:class:`~stylemotion.models.autoencoder.MotionAutoencoder` (frame layout keys), a
:class:`~stylemotion.models.vae.PrimitiveVAE` (a data ``spec``), a
:class:`~stylemotion.models.cvae.StyleCVAE` (a ``spec`` and a ``style_weight``) or a
:class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE` (a ``spec`` and an ``embedding_dim``; it samples
only given a style example, so folder searches for evaluation, :func:`is_model_checkpoint`, skip it).

Generative models decode through the autoencoder their features came from. Their checkpoints embed
it (key :data:`EMBEDDED_AUTOENCODER`: its hyperparameters and state dict, about 2 MB), so they load
anywhere; the autoencoder's path and weight fingerprint (:func:`autoencoder_info`) are recorded in
the model's ``spec`` as well. :func:`resolve_autoencoder` finds it for a model: embedded, else
(checkpoints written before the embedding) at the recorded path, else at the same tail of that
path below a folder above the model's checkpoint (a run folder that was moved), always checked
against the recorded fingerprint.
"""

from __future__ import annotations

import glob
import hashlib
import inspect
import logging
import os
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import lightning.pytorch as pl
import torch

from stylemotion.io.errors import UserInputError
from stylemotion.models.autoencoder import IncompatibleModelError, MotionAutoencoder

log = logging.getLogger(__name__)

#: Key of a generative model's checkpoint holding its autoencoder: ``{"hyper_parameters", "state_dict"}``.
EMBEDDED_AUTOENCODER = "autoencoder"
#: Hyperparameters every MotionAutoencoder checkpoint has.
AUTOENCODER_KEYS = ("hidden_units", "kernel_size", "representation", "fps")
#: Kinds of checkpoint (see :func:`checkpoint_kind`).
KINDS = ("autoencoder", "vae", "cvae", "zero_shot")
#: Kinds of generative model (their checkpoints embed the autoencoder;
#: :func:`stylemotion.models.loading.load_generative` loads them).
GENERATIVE_KINDS = ("vae", "cvae", "zero_shot")


class MissingCheckpointError(UserInputError, FileNotFoundError):
    """A checkpoint path that names no file (or no regular file: a folder, a FIFO); the message names it."""


class MissingAutoencoderError(UserInputError, FileNotFoundError):
    """A generative model's autoencoder is neither embedded in its checkpoint nor found on disk."""


# -- reading


def read_checkpoint(path: str | os.PathLike, what: str = "checkpoint") -> dict[str, Any]:
    """The checkpoint dict at ``path`` (``~`` expanded), read on the CPU with ``weights_only=True``.

    Raises:
        MissingCheckpointError: no such file, or no regular file (``what`` names it in the message).
        IncompatibleModelError: not a readable checkpoint (not a torch file, or objects other
            than tensors and plain values).
    """
    path = Path(path).expanduser()
    if not path.is_file():
        raise MissingCheckpointError(f"{what} {str(path)!r} " + ("is not a regular file" if path.exists()
                                                                 else "does not exist"))
    try:
        checkpoint = torch.load(path, map_location="cpu", weights_only=True)
    except Exception as exc:  # noqa: BLE001 - zip, pickle and weights_only errors alike: not ours to read
        detail = str(exc).splitlines()[0].split(". ")[0] if str(exc) else ""  # torch's first sentence only
        raise IncompatibleModelError(f"{path} is not a readable checkpoint of plain values and tensors "
                                     f"({type(exc).__name__}: {detail}); it is damaged, cut off or another kind of "
                                     "file") from exc
    if not isinstance(checkpoint, dict):
        raise IncompatibleModelError(f"{path} holds a {type(checkpoint).__name__}, not a checkpoint dict")
    return checkpoint


def checkpoint_hparams(path: str | os.PathLike) -> dict[str, Any]:
    """The ``hyper_parameters`` of a checkpoint (empty if it has none)."""
    hparams = read_checkpoint(path).get("hyper_parameters")
    return dict(hparams) if isinstance(hparams, Mapping) else {}


def checkpoint_kind(hparams: Mapping[str, Any]) -> str | None:
    """``autoencoder``, ``vae``, ``cvae`` or ``zero_shot`` from a checkpoint's hyperparameters; None for anything
    else."""
    if isinstance(hparams.get("spec"), Mapping):
        if "embedding_dim" in hparams:
            return "zero_shot"
        return "cvae" if "style_weight" in hparams else "vae"
    if all(k in hparams for k in AUTOENCODER_KEYS):
        return "autoencoder"
    return None


#: The kinds a folder search for evaluation takes (a zero-shot network samples only given an example).
MODEL_KINDS = ("vae", "cvae")


def is_model_checkpoint(path: str | os.PathLike) -> bool:
    """Whether a checkpoint holds a trained PrimitiveVAE/StyleCVAE (its hyperparameters carry a data ``spec``)."""
    return checkpoint_kind(checkpoint_hparams(path)) in MODEL_KINDS


def restore(cls: type[pl.LightningModule], checkpoint: Mapping[str, Any], source: str) -> pl.LightningModule:
    """A model of class ``cls`` rebuilt from a checkpoint dict, in eval mode on the CPU.

    Built as Lightning's loader does: ``cls(**hyper_parameters)`` (keys the constructor does not take
    are dropped unless it takes ``**kwargs``), ``on_load_checkpoint``, strict ``load_state_dict``.

    Args:
        cls: the model class.
        checkpoint: ``hyper_parameters`` and ``state_dict`` (plus what the model's hooks read).
        source: the checkpoint's name in error messages (a path).

    Raises:
        IncompatibleModelError: the constructor or the hooks refuse it, or the weights do not fit.
    """
    hparams = dict(checkpoint.get("hyper_parameters") or {})
    params = inspect.signature(cls.__init__).parameters
    if not any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values()):
        hparams = {k: v for k, v in hparams.items() if k in params}
    try:
        model = cls(**hparams)
        model.on_load_checkpoint(dict(checkpoint))
    except IncompatibleModelError as err:
        raise IncompatibleModelError(f"{cls.__name__} checkpoint {source}: {err}") from err
    state = checkpoint.get("state_dict")
    if not isinstance(state, Mapping):
        raise IncompatibleModelError(f"{cls.__name__} checkpoint {source} holds no state_dict")
    try:
        model.load_state_dict(state)
    except RuntimeError as err:
        raise IncompatibleModelError(f"{cls.__name__} checkpoint {source}: its weights do not fit the model its "
                                     f"hyperparameters describe ({str(err).splitlines()[0]})") from err
    check_finite_weights(model, source)
    return model.eval()


def check_finite_weights(model: torch.nn.Module, source: str) -> None:
    """Refuse a model whose parameters hold NaN/inf (a diverged training saved them: every sample would be NaN, found
    much later as a puzzling error). Buffers are not checked: some hold NaN for "not known" (``content_spread``).

    Raises:
        IncompatibleModelError: naming ``source`` and the first tensors affected.
    """
    bad = [name for name, value in model.named_parameters() if not torch.isfinite(value).all()]
    if bad:
        shown = ", ".join(bad[:3]) + (f" and {len(bad) - 3} more" if len(bad) > 3 else "")
        raise IncompatibleModelError(f"{source}: the model's weights hold NaN/inf ({shown}); its training diverged "
                                     "— use an earlier checkpoint or train it again")


# -- autoencoders


def fingerprint(module: torch.nn.Module) -> str:
    """Short SHA-256 of a module's state (names, shapes and values of parameters and buffers)."""
    digest = hashlib.sha256()
    for key, value in sorted(module.state_dict().items()):
        tensor = value.detach().cpu().contiguous()
        digest.update(key.encode())
        digest.update(str(tuple(tensor.shape)).encode())
        digest.update(tensor.numpy().tobytes())
    return digest.hexdigest()[:16]


def autoencoder_info(autoencoder: MotionAutoencoder, path: str | os.PathLike | None) -> dict[str, Any]:
    """Plain values that identify an autoencoder: checkpoint path (absolute), weight fingerprint, layout."""
    hp = autoencoder.hparams
    return {"path": None if path is None else str(Path(path).expanduser().resolve()),
            "fingerprint": fingerprint(autoencoder),
            "hidden_units": int(hp["hidden_units"]), "kernel_size": int(hp["kernel_size"]),
            "pooling": str(hp["pooling"]), "fps": float(hp["fps"]), "frame_dim": int(hp["frame_dim"]),
            "representation": str(hp["representation"])}


def _frozen(autoencoder: MotionAutoencoder, source: str, expected: Mapping[str, Any] | None) -> MotionAutoencoder:
    """Check statistics and fingerprint, then freeze (eval mode, no gradients)."""
    if not autoencoder.net.normalizer.initialized:
        raise IncompatibleModelError(f"autoencoder checkpoint {source} holds no frame normalization statistics")
    autoencoder.eval().requires_grad_(False)
    if expected is not None:
        got = fingerprint(autoencoder)
        if got != expected.get("fingerprint"):
            raise IncompatibleModelError(
                f"autoencoder checkpoint {source} has weights {got}, but the model was trained on features of "
                f"the autoencoder with weights {expected.get('fingerprint')} (then at {expected.get('path')}); "
                "load that checkpoint, or retrain the model on this autoencoder")
    return autoencoder


def load_autoencoder(path: str | os.PathLike, expected: Mapping[str, Any] | None = None) -> MotionAutoencoder:
    """Load a frozen :class:`MotionAutoencoder` (eval mode, no gradients) on the CPU.

    Args:
        path: its Lightning checkpoint (``~`` expanded), or the checkpoint of a PrimitiveVAE/StyleCVAE
            that embeds it.
        expected: an :func:`autoencoder_info` dict; when given, the loaded weights must have the
            same fingerprint (they are the ones a VAE was trained on).

    Raises:
        FileNotFoundError: no such file.
        IncompatibleModelError: not an autoencoder checkpoint (nor a model embedding one), a
            representation or skeleton this code does not compute, no normalization statistics, or
            a different fingerprint.
    """
    path = Path(path).expanduser()
    if not path.is_file():
        raise MissingCheckpointError(f"autoencoder checkpoint {str(path)!r} does not exist; train one with "
                                "'stylemotion-train experiment=autoencoder data=...' and pass its "
                                "checkpoints/best.ckpt as autoencoder_ckpt=...")
    checkpoint = read_checkpoint(path, "autoencoder checkpoint")
    saved = checkpoint.get("hyper_parameters") or {}
    kind = checkpoint_kind(saved)
    if kind in GENERATIVE_KINDS and isinstance(checkpoint.get(EMBEDDED_AUTOENCODER), Mapping):
        return autoencoder_from_record(checkpoint[EMBEDDED_AUTOENCODER], str(path), expected)
    if kind != "autoencoder":
        raise IncompatibleModelError(f"{path} is not a MotionAutoencoder checkpoint (its hyperparameters lack "
                                     f"{[k for k in AUTOENCODER_KEYS if k not in saved] or ['nothing']}; it has "
                                     f"{sorted(saved)[:12]}) nor a model checkpoint that embeds one")
    return _frozen(restore(MotionAutoencoder, checkpoint, str(path)), str(path), expected)


def autoencoder_record(autoencoder: MotionAutoencoder) -> dict[str, Any]:
    """What a generative checkpoint embeds of its autoencoder: plain hyperparameters and the state
    dict (CPU tensors, the same values), readable with ``weights_only=True``."""
    return {"hyper_parameters": {k: (list(v) if isinstance(v, tuple) else v) for k, v in autoencoder.hparams.items()},
            "state_dict": {k: v.detach().cpu() for k, v in autoencoder.state_dict().items()}}


def autoencoder_from_record(record: Mapping[str, Any], source: str,
                            expected: Mapping[str, Any] | None = None) -> MotionAutoencoder:
    """The frozen autoencoder embedded in a generative checkpoint (``source`` names it), checked
    against ``expected`` (an :func:`autoencoder_info` dict) when given."""
    if checkpoint_kind(record.get("hyper_parameters") or {}) != "autoencoder":
        raise IncompatibleModelError(f"the autoencoder embedded in {source} lacks its hyperparameters")
    return _frozen(restore(MotionAutoencoder, record, f"embedded in {source}"), f"embedded in {source}", expected)


def _relocations(recorded: Path, checkpoint: Path) -> Iterator[Path]:
    """Where a recorded file may be now that the folders holding ``checkpoint`` moved: each tail of
    ``recorded`` (longest first, at least two parts) below each folder above ``checkpoint``
    (nearest first); never ``checkpoint`` itself."""
    parts = recorded.parts
    tails = [Path(*parts[i:]) for i in range(1, len(parts) - 1)]
    seen = {checkpoint}
    for folder in checkpoint.parents:
        for tail in tails:
            candidate = folder / tail
            if candidate not in seen:
                seen.add(candidate)
                yield candidate


def resolve_autoencoder(info: Mapping[str, Any], record: Mapping[str, Any] | None = None,
                        checkpoint: str | os.PathLike | None = None) -> tuple[MotionAutoencoder, str | None]:
    """The autoencoder a generative model was trained with (frozen, CPU), checked by fingerprint, and
    the file it came from (``checkpoint`` itself when embedded; None when that is unknown).

    Tried in order: the ``record`` embedded in the model's checkpoint; the path recorded in
    ``info``; the same file relocated below a folder above ``checkpoint`` (e.g. a moved
    ``stylemotion-reproduce`` run: ``<run>/autoencoder/checkpoints/best.ckpt`` from
    ``<run>/vae/<primitive>/checkpoints/best.ckpt``).

    Args:
        info: the model's ``spec["autoencoder"]`` (``path``, ``fingerprint``, …).
        record: the embedded autoencoder (:func:`autoencoder_record`), if the checkpoint has one.
        checkpoint: the model's checkpoint file, if known.

    Raises:
        MissingAutoencoderError: nothing found; the message names every place tried.
        IncompatibleModelError: the embedded autoencoder is not the recorded one.
    """
    where = str(checkpoint) if checkpoint is not None else "the model's checkpoint"
    if record is not None:
        return autoencoder_from_record(record, where, info), None if checkpoint is None else str(checkpoint)
    tried: list[str] = []
    recorded = Path(str(info["path"])).expanduser() if info.get("path") else None
    candidates: list[Path] = [] if recorded is None else [recorded]
    if recorded is not None and checkpoint is not None:
        candidates += [c for c in _relocations(recorded, Path(checkpoint).expanduser().resolve()) if c.is_file()]
    for candidate in candidates:
        if not candidate.is_file():
            tried.append(f"{candidate} (no such file)")
            continue
        try:
            return load_autoencoder(candidate, expected=info), str(candidate)
        except IncompatibleModelError as err:
            tried.append(f"{candidate} ({err})")
    if recorded is not None and checkpoint is not None:
        tried.append(f"the tails of {recorded} (from {Path(*recorded.parts[-2:])} up) below every folder above "
                     f"{Path(checkpoint).expanduser().resolve()}")
    raise MissingAutoencoderError(
        f"cannot find the autoencoder (weights {info.get('fingerprint')}) that {where} decodes through: "
        "its checkpoint embeds none (written before autoencoders were embedded)"
        + (f"; tried {'; '.join(tried)}" if tried else "; no autoencoder path is recorded")
        + ". Pass it with model.attach_autoencoder(<autoencoder best.ckpt>) or autoencoder_ckpt=…")


def find_checkpoints(patterns: Sequence[str] | str) -> list[Path]:
    """Checkpoint files from files, glob patterns and folders (``~`` expanded).

    A folder is searched for ``**/checkpoints/best.ckpt`` of primitive models (an autoencoder's
    checkpoint in it is skipped); files and glob matches are taken as given.

    Raises:
        FileNotFoundError: a pattern matches nothing.
    """
    if isinstance(patterns, str):
        patterns = [patterns]
    found: list[Path] = []
    for pattern in patterns:
        path = Path(pattern).expanduser()
        if path.is_dir():
            kinds = {h: checkpoint_kind(checkpoint_hparams(h)) for h in sorted(path.glob("**/checkpoints/best.ckpt"))}
            hits = [h for h, kind in kinds.items() if kind in MODEL_KINDS]
            networks = [h for h, kind in kinds.items() if kind == "zero_shot"]
            if not hits and networks:
                raise MissingCheckpointError(
                    f"{pattern!r} holds zero-shot networks only, which a folder search skips (they sample only given "
                    f"an example): name each one, e.g. checkpoints=[<the run's vae>,{networks[0]}] (docs/zero_shot.md)")
        elif path.is_file():
            hits = [path]
        else:
            hits = sorted(Path(p) for p in glob.glob(str(path), recursive=True))
        if not hits:
            raise MissingCheckpointError(f"no checkpoint matches {pattern!r} (a file, a glob pattern, or a folder "
                                         "holding **/checkpoints/best.ckpt of a PrimitiveVAE/StyleCVAE)")
        found += [h for h in hits if h not in found]
    return found
