"""One skeleton for a whole dataset (``data.retarget``), and which takes share an actor's skeleton.

``data.retarget: <style>`` puts every take on the median bone lengths of that style's takes
(:func:`retarget_takeset`, applied by :func:`stylemotion.datasets.load_dataset` to every dataset
kind after conversion); ``null`` keeps each recording's own bones. :func:`actor_groups` finds the
takes recorded on the same skeleton (bone lengths within a tolerance), so that a result can be
reported within each group. Transform and units: :mod:`stylemotion.bones`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from scipy.cluster.hierarchy import fcluster, linkage

from stylemotion.bones import BONE_NAMES, median_bone_lengths, retarget_positions, target_bone_lengths
from stylemotion.config import ConfigError
from stylemotion.datasets.base import Take, TakeSet

#: Default tolerance of :func:`actor_groups`: two takes share a skeleton when no bone differs by more, metres.
ACTOR_TOLERANCE_M = 0.001


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


@dataclass(frozen=True)
class ActorGroups:
    """Takes grouped by skeleton (see :func:`actor_groups`).

    Attributes:
        styles: group id → sorted styles of its takes.
        takes: take name → group id.
        bone_lengths: group id → ``(20,)`` median bone lengths of its takes, metres.
    """

    styles: dict[int, list[str]]
    takes: dict[str, int]
    bone_lengths: dict[int, np.ndarray]


def actor_groups(takes: Sequence[Take], tolerance_m: float = ACTOR_TOLERANCE_M) -> ActorGroups:
    """Group takes by actor, i.e. by skeleton: takes whose median bone lengths agree within a tolerance.

    Two takes are linked when every bone's median length (:func:`stylemotion.bones.median_bone_lengths`)
    differs by at most ``tolerance_m``; a group is a connected set of linked takes (single linkage,
    so the result does not depend on the order of ``takes``). Group ids count from 0 in the order of
    each group's first take by name. A style recorded by two actors appears in both groups.

    Args:
        takes: takes with a ``style`` label and ``(frames, 21, 3)`` positions in metres.
        tolerance_m: largest difference of any bone between linked takes, metres.

    Raises:
        ValueError: ``tolerance_m`` is not a non-negative number.
    """
    if isinstance(tolerance_m, bool) or not isinstance(tolerance_m, (int, float)) or not tolerance_m >= 0:
        raise ValueError(f"tolerance_m must be a number of metres ≥ 0, got {tolerance_m!r}")
    ordered = sorted(takes, key=lambda t: t.name)
    if not ordered:
        return ActorGroups({}, {}, {})
    lengths = np.stack([median_bone_lengths(t.positions) for t in ordered])  # (takes, 20)
    if len(ordered) == 1:
        labels = np.zeros(1, dtype=int)
    else:
        labels = fcluster(linkage(lengths, method="single", metric="chebyshev"), t=tolerance_m,
                          criterion="distance")
    ids: dict[int, int] = {}
    for label in labels:
        ids.setdefault(int(label), len(ids))
    group = [ids[int(label)] for label in labels]
    members = {g: [i for i, x in enumerate(group) if x == g] for g in ids.values()}
    return ActorGroups(
        styles={g: sorted({ordered[i].style for i in m}) for g, m in members.items()},
        takes={t.name: g for t, g in zip(ordered, group)},
        bone_lengths={g: np.median(lengths[m], axis=0) for g, m in members.items()},
    )
