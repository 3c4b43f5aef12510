"""What a reproduction stage was trained with, beyond its overrides: a stage reused or resumed must have been trained
with the settings its composed ``train`` config gives now, including defaults in ``configs/`` that changed since.

A stage's ``settings_hash`` (:mod:`stylemotion.training.reproduction`) covers its overrides, values, data, seed and
parent, not the config files they compose: when a default changes (e.g. ``model.style_duration_weight`` 0 → 50),
the hash stays and an old stage would be reused silently. So each stage also records its composed config
(:func:`config_record`: dotted keys, interpolations left unresolved, run-specific keys left out), and a rerun lists the
keys whose values differ (:func:`changed_settings`). Records written before this one carry no config: for those the
model's keys are read against the checkpoint's ``hyper_parameters`` (a key the checkpoint lacks was trained at the
model class's constructor default).
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from typing import Any

from omegaconf import DictConfig, OmegaConf

#: Top-level keys that say where and how fast a stage runs, not what it learns (the data, seed and parent stage are
#: in the settings hash).
RUN_SPECIFIC = ("data", "hydra", "output_dir", "threads", "ckpt_path", "autoencoder_ckpt", "seed", "logger")
#: Dotted keys of the same kind below the top level.
RUN_SPECIFIC_KEYS = ("trainer.enable_progress_bar", "trainer.enable_model_summary", "callbacks.progress_bar")
#: Differences listed in one refusal at most.
SHOWN = 3


def _flattened(node: Any, prefix: str, into: dict[str, Any]) -> None:
    if isinstance(node, Mapping) and node:
        for key, value in node.items():
            _flattened(value, f"{prefix}.{key}" if prefix else str(key), into)
    else:
        into[prefix] = node


def config_record(cfg: DictConfig) -> dict[str, Any]:
    """A stage's composed ``train`` config as ``{dotted key: value}`` (interpolations unresolved, so a moved run
    folder records the same), without the run-specific keys (:data:`RUN_SPECIFIC`, :data:`RUN_SPECIFIC_KEYS`)."""
    container = OmegaConf.to_container(cfg, resolve=False)
    flat: dict[str, Any] = {}
    _flattened({k: v for k, v in container.items() if k not in RUN_SPECIFIC}, "", flat)
    return {k: v for k, v in flat.items()
            if not any(k == key or k.startswith(key + ".") for key in RUN_SPECIFIC_KEYS)}


def constructor_default(target: str, name: str) -> tuple[bool, Any]:
    """``(True, default)`` of argument ``name`` of the class ``target`` names (its own or a base class's
    ``__init__``), else ``(False, None)`` (no such class, argument or default)."""
    from hydra.utils import get_class

    try:
        cls = get_class(target)
    except Exception:  # noqa: BLE001 - a target that no longer imports has no default to read
        return False, None
    for klass in cls.__mro__:
        parameter = inspect.signature(klass.__init__).parameters.get(name) if "__init__" in vars(klass) else None
        if parameter is not None and parameter.default is not inspect.Parameter.empty:
            return True, parameter.default
    return False, None


def _plain(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value


def _same(a: Any, b: Any) -> bool:
    return _plain(a) == _plain(b)


def _shown(value: Any) -> str:
    return repr(value) if isinstance(value, str) else str(value)


def changed_settings(now: Mapping[str, Any], recorded: Mapping[str, Any] | None,
                     trained_hparams: Mapping[str, Any] | None = None) -> list[str]:
    """The keys whose trained value differs from ``now`` (a :func:`config_record`), each as
    ``"key=<trained> (now <value>)"``.

    ``recorded``: the stage's recorded config, or None for a record that predates it; then only the ``model.*`` keys
    are read, against ``trained_hparams`` (the checkpoint's ``hyper_parameters``). A key missing from what was
    recorded was trained at the model class's constructor default when it is a ``model.*`` key (a new option), and is
    a difference otherwise; a key no longer composed is not (the option is gone).
    """
    if recorded is None and trained_hparams is None:
        return []  # an old record without its checkpoint: nothing to read the model's keys against
    target = str(now.get("model._target_", ""))
    changes: list[str] = []
    for key, value in now.items():
        trained = _trained_value(key, value, recorded, trained_hparams, target)
        if trained is None:
            continue
        if not trained[0]:
            changes.append(f"{key} absent (now {_shown(value)})")
        elif not _same(trained[1], value):
            changes.append(f"{key}={_shown(trained[1])} (now {_shown(value)})")
    return changes


def _trained_value(key: str, value: Any, recorded: Mapping[str, Any] | None,
                   trained_hparams: Mapping[str, Any] | None, target: str) -> tuple[bool, Any] | None:
    """What ``key`` was trained with, as ``(known, value)`` (see :func:`changed_settings`); None when nothing can
    say (an old record: a key outside the model, an interpolation, or one the model class does not take)."""
    if recorded is not None and key in recorded:
        return True, recorded[key]
    if recorded is None and isinstance(value, str) and "${" in value:
        return None  # an interpolation (e.g. ${data.fps}): its source is in the settings hash
    name = key[len("model."):]
    if not (key.startswith("model.") and key != "model._target_" and "." not in name):
        return None if recorded is None else (False, None)  # outside the model nothing says how it was trained
    if recorded is None and trained_hparams is not None and name in trained_hparams:
        return True, trained_hparams[name]
    default = constructor_default(target, name)
    return None if recorded is None and not default[0] else default


def changes_line(changes: list[str]) -> str:
    """At most :data:`SHOWN` changes on one line, with the count of the rest."""
    more = len(changes) - SHOWN
    return "; ".join(changes[:SHOWN]) + (f"; and {more} more" if more > 0 else "")
