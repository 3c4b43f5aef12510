"""What the reconstruction commands read first: the dataset of a ``data`` config and the motion database made of
its takes without the ones the query came from."""

from __future__ import annotations

from collections.abc import Collection, Mapping
from typing import Any

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
