"""What the reconstruction commands read first: the dataset of a ``data`` config and the motion database made of
its takes without the ones the query came from."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Any

from omegaconf import DictConfig, OmegaConf

from stylemotion.config import ConfigError
from stylemotion.datasets import TakeSet, build_dataset
from stylemotion.search.database import MotionDatabase


def command_takeset(data: Mapping[str, Any]) -> TakeSet:
    """The dataset of a ``data`` config; ConfigError naming it when it cannot be built."""
    try:
        return build_dataset(data)
    except (KeyError, ValueError) as exc:
        raise ConfigError(f"data={data.get('name')}: {exc}") from None


def database_without(takeset: TakeSet, excluded: Collection[str], query: str) -> MotionDatabase:
    """The database of every take of ``takeset`` except ``excluded`` (take names); ConfigError naming ``query``
    (what the excluded takes gave, e.g. ``motion=<take>``) when no take is left."""
    kept = [t for t in takeset.takes if t.name not in excluded]
    if not kept:
        raise ConfigError(f"data={takeset.name}: no take is left in the database besides {query}")
    return MotionDatabase.from_takeset(TakeSet(takeset.name, kept, takeset.fps, retarget=takeset.retarget))


def plain_config(cfg: DictConfig, command: str) -> dict[str, Any]:
    """A command's resolved config as a plain dict; ConfigError when it is not a mapping."""
    plain = OmegaConf.to_container(cfg, resolve=True)
    if not isinstance(plain, dict):
        raise ConfigError(f"the {command} config must be a mapping")
    return plain


def joints_option(plain: Mapping[str, Any], example: str) -> list[str] | None:
    """The ``joints`` key: None or a list; ConfigError with ``example`` (e.g. ``'[Hips,Foot_L]'``) otherwise."""
    joints = plain.get("joints")
    if joints is not None and not isinstance(joints, list):
        raise ConfigError(f"joints={joints} must be a list of canonical joints, e.g. {example}")
    return joints
