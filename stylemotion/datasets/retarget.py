"""One skeleton for a whole dataset (``data.retarget``), and which takes share an actor's skeleton.

``data.retarget: <style>`` puts every take on the median bone lengths of that style's takes
(:func:`retarget_takeset`, applied by :func:`stylemotion.datasets.load_dataset` to every dataset
kind after conversion); ``null`` keeps each recording's own bones (which takes share an actor:
:mod:`stylemotion.datasets.actors`). Transform and units: :mod:`stylemotion.bones`.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from stylemotion.bones import BONE_NAMES, retarget_positions, target_bone_lengths
from stylemotion.config import ConfigError
from stylemotion.datasets.base import Take, TakeSet


def check_retarget(value: Any) -> str | None:
    """``data.retarget`` as a style name or None; ValueError naming the key for anything else."""
    if value is None or (isinstance(value, str) and value.strip()):
        return value
    raise ConfigError(f"data.retarget must be a style name (every take gets the median bone lengths of that "
                     f"style's takes) or null (each take keeps its own bones), got {value!r}")


def skeleton_record(style: str | None, takes: int, lengths: np.ndarray) -> dict[str, Any]:
    """The ``TakeSet.retarget`` record of a skeleton: the style whose takes set it (None: all takes), how
    many takes, and its ``(20,)`` bone lengths in metres by bone name."""
    return {"style": style, "takes": int(takes),
            "bone_lengths_m": {name: round(float(x), 6) for name, x in zip(BONE_NAMES, lengths)}}


def retarget_takeset(takeset: TakeSet, style: str) -> TakeSet:
    """Every take of ``takeset`` on the median bone lengths of the takes of ``style``.

    The target is :func:`stylemotion.bones.target_bone_lengths` of those takes; each take goes
    through :func:`stylemotion.bones.retarget_positions`. The result records the target in
    ``TakeSet.retarget`` (``style``, ``takes``, ``bone_lengths_m`` by bone).

    ``style=None`` returns ``takeset`` itself (the original bones).

    Raises:
        ValueError: ``style`` is not a style of the takes (the message lists them), or a take
            cannot be retargeted (naming it).
    """
    if check_retarget(style) is None:
        return takeset
    styles = takeset.label_values("style")
    examples = takeset.filter(style=style)
    if not examples:
        raise ConfigError(f"data.retarget={style!r} is not a style of dataset {takeset.name!r}; its styles are "
                         f"{styles} (data.styles must keep the target style; null keeps each take's own bones)")
    target = target_bone_lengths(t.positions for t in examples)
    takes = []
    for take in takeset.takes:
        try:
            positions = retarget_positions(take.positions, target)
        except ValueError as exc:
            raise ConfigError(f"data.retarget={style!r}: take {take.name!r} ({take.source}): {exc}") from None
        takes.append(Take(take.name, positions, take.fps, dict(take.labels), take.source))
    record = skeleton_record(style, len(examples), target)
    return replace(takeset, takes=takes, retarget=record)
