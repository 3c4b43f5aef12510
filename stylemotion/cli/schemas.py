"""The settings dataclasses the packaged YAML takes as Hydra structured configs (group ``schema``).

Settings defaults live once, in the dataclasses that use them: ``segment`` =
:class:`~stylemotion.primitives.segmentation.SegmentSettings`, ``evaluation`` =
:class:`~stylemotion.evaluation.settings.EvalSettings`, ``follow`` =
:class:`~stylemotion.synthesis.controller.FollowSettings`. The YAML files take them in their defaults
lists (``- schema@segment: segment``) instead of repeating their values; keys and types are checked by
Hydra.

Registering them imports the modules that define them (evaluation, synthesis: Lightning and more), so it
is not done on import of :mod:`stylemotion.config` but explicitly, before a config is composed:
:func:`~stylemotion.cli.skeleton.hydra_command` registers what its config needs; a notebook or test
that composes ``eval``, ``reproduce``, ``segment`` or ``generate`` itself calls :func:`register_schemas`
first (registering twice is harmless).
"""

from __future__ import annotations

from collections.abc import Callable


def _segment() -> type:
    from stylemotion.primitives.segmentation import SegmentSettings

    return SegmentSettings


def _evaluation() -> type:
    from stylemotion.evaluation.settings import EvalSettings

    return EvalSettings


def _follow() -> type:
    from stylemotion.synthesis.controller import FollowSettings

    return FollowSettings


#: Schema name (``schema/<name>`` in a defaults list) → the dataclass, imported when registered.
SCHEMAS: dict[str, Callable[[], type]] = {"segment": _segment, "evaluation": _evaluation, "follow": _follow}

#: Each packaged top-level config whose defaults take a schema → the schemas it needs (others need none;
#: tests/test_config_schemas.py checks that this list is complete).
CONFIG_SCHEMAS: dict[str, tuple[str, ...]] = {
    "segment": ("segment",), "eval": ("evaluation",), "reproduce": ("evaluation",), "generate": ("follow",),
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
