"""The settings dataclasses the packaged YAML takes as Hydra structured configs (group ``schema``).

Settings defaults live once, in the dataclasses that use them: ``segment`` =
:class:`~stylemotion.primitives.segmentation.SegmentSettings`, ``evaluation`` =
:class:`~stylemotion.evaluation.settings.EvalSettings`, ``follow`` =
:class:`~stylemotion.synthesis.settings.FollowSettings`, and the whole of a command's own keys for
``search``, ``annotate``, ``reconstruct``, ``texture``, ``keyframes`` and ``style`` (each wing's
``settings.py``). The YAML files take them in their defaults lists (``- schema@segment: segment``; the
command's own keys at the top level: ``- schema@_here_: search``) instead of repeating their values; keys
and types are checked by Hydra, and before it by :func:`check_overrides` (one line naming the key).

Registering them imports the modules that define them (evaluation, synthesis: Lightning and more), so it
is not done on import of :mod:`stylemotion.config` but explicitly, before a config is composed:
:func:`~stylemotion.cli.skeleton.hydra_command` registers what its config needs; a notebook or test
that composes ``eval``, ``reproduce``, ``segment`` or ``generate`` itself calls :func:`register_schemas`
first (registering twice is harmless).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Sequence
from functools import partial

#: Schema name (``schema/<name>`` in a defaults list) → ``module:Class`` of its dataclass.
SCHEMA_CLASSES: dict[str, str] = {
    "segment": "stylemotion.primitives.segmentation:SegmentSettings",
    "evaluation": "stylemotion.evaluation.settings:EvalSettings",
    "follow": "stylemotion.synthesis.settings:FollowSettings",
    "search": "stylemotion.search.settings:SearchSettings",
    "annotate": "stylemotion.annotate.settings:AnnotateSettings",
    "reconstruct": "stylemotion.reconstruct.settings:ReconstructSettings",
    "keyframes": "stylemotion.reconstruct.settings:KeyframesSettings",
    "texture": "stylemotion.reconstruct.settings:TextureSettings",
    "style": "stylemotion.style_example.settings:StyleSettings",
}


def _import_class(path: str) -> type:
    """The class ``module:Class`` names, its module imported now (not when this module is)."""
    module, _, name = path.partition(":")
    return getattr(importlib.import_module(module), name)


#: Schema name → the dataclass, imported when registered.
SCHEMAS: dict[str, Callable[[], type]] = {name: partial(_import_class, path) for name, path in SCHEMA_CLASSES.items()}

#: Where each schema sits in the configs that take it: a key (``- schema@segment: segment``) or the top level
#: (``""``: ``- schema@_here_: search``, the command's own keys).
PACKAGES: dict[str, str] = {
    "segment": "segment", "evaluation": "evaluation", "follow": "follow", "search": "", "annotate": "",
    "reconstruct": "", "keyframes": "", "texture": "", "style": "",
}

#: Each packaged top-level config whose defaults take a schema → the schemas it needs (others need none;
#: tests/test_config_schemas.py checks that this list is complete).
CONFIG_SCHEMAS: dict[str, tuple[str, ...]] = {
    "segment": ("segment",), "eval": ("evaluation",), "reproduce": ("evaluation",), "generate": ("follow",),
    "search": ("search",), "annotate": ("annotate",), "reconstruct": ("reconstruct",), "keyframes": ("keyframes",),
    "texture": ("texture",), "style": ("style",),
}


def register_schemas(*names: str) -> None:
    """Store the structured configs ``names`` (all of :data:`SCHEMAS` when none) in Hydra's ConfigStore."""
    from hydra.core.config_store import ConfigStore

    from stylemotion.config import structured_schema

    store = ConfigStore.instance()
    for name in names or tuple(SCHEMAS):
        store.store(group="schema", name=name, node=structured_schema(SCHEMAS[name]()))


def register_schemas_for(config_name: str) -> None:
    """Register the schemas the packaged config ``config_name`` needs (:data:`CONFIG_SCHEMAS`), none for others."""
    needed = CONFIG_SCHEMAS.get(config_name, ())
    if needed:
        register_schemas(*needed)


def check_overrides(config_name: str, overrides: Sequence[str]) -> None:
    """Check the command-line overrides of keys of the schemas ``config_name`` takes before Hydra composes it, so
    that a value of the wrong type or an unknown key of a schema is one line naming it (Hydra's own message is
    several lines and exit status 1). Anything else (other keys, sweeps, deletions, Hydra's options, a syntax
    Hydra's parser refuses) is left to Hydra.

    Raises:
        ConfigError: the first override that does not fit its schema, as ``<key>: <what is wrong>``.
    """
    needed = CONFIG_SCHEMAS.get(config_name, ())
    candidates = [a for a in overrides if "=" in a and not a.startswith("-")]
    if not needed or not candidates:
        return
    from hydra.core.override_parser.overrides_parser import OverridesParser
    from hydra.errors import HydraException
    from omegaconf import OmegaConf
    from omegaconf.errors import OmegaConfBaseException

    from stylemotion.config import ConfigError, structured_schema

    try:
        parsed = OverridesParser.create().parse_overrides(candidates)
    except HydraException:
        return
    for name in needed:
        package, fields = PACKAGES[name], None
        for override in parsed:
            key = override.key_or_group
            if override.is_sweep_override() or override.is_delete() or override.package is not None:
                continue
            parts = key.split(".")
            if package:
                if parts[0] != package or len(parts) < 2:
                    continue
                parts = parts[1:]
            schema = structured_schema(SCHEMAS[name]())
            fields = fields or set(schema.keys())
            if parts[0] not in fields:
                continue
            value: object = override.value()
            for part in reversed(parts):
                value = {part: value}
            try:
                OmegaConf.merge(schema, value)
            except OmegaConfBaseException as exc:
                raise ConfigError(f"{key}={override.get_value_string()}: "
                                  f"{str(exc).splitlines()[0]}") from None
