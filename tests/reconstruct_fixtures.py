"""Shared data of the reconstruction tests: the synthetic split (one take per content and style, 15 % test per
content)."""

from __future__ import annotations

from stylemotion.datasets.base import Take, TakeSet
from stylemotion.datasets.registry import load_dataset
from stylemotion.search.database import MotionDatabase


def synthetic_split() -> tuple[MotionDatabase, list[Take], list[Take]]:
    """``(database of the train takes, train takes, test takes)``."""
    ts = load_dataset("synthetic", takes_per_pair=1)
    parts = ts.split(0, 0.0, 0.15, group_by=("content",))
    return MotionDatabase.from_takeset(TakeSet("synthetic", parts["train"], ts.fps)), parts["train"], parts["test"]
