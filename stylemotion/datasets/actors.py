"""Which takes share an actor: :func:`actor_groups` groups takes by skeleton, bone lengths within a tolerance and
one rest pose in their BVH files, so that a result can be reported within each group or an actor left out (the
actor split, ``data.split.test_actor``: :meth:`stylemotion.datasets.base.TakeSet.split`).

Bandai dataset-2 ships every actor on one set of bone lengths and keeps each actor's calibration only in the files'
rest offsets (one rest position of the Hips per actor; docs/data.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import PurePosixPath
from typing import Protocol

import numpy as np
from scipy.cluster.hierarchy import fcluster, linkage

from stylemotion.bones import median_bone_lengths
from stylemotion.io.bvh import MAX_HIERARCHY_BYTES, parse_bvh_skeleton
from stylemotion.io.errors import BvhError
from stylemotion.io.sources import FileSource

#: Default tolerance of :func:`actor_groups`: two takes share a skeleton when no bone differs by more, metres.
ACTOR_TOLERANCE_M = 0.001


class TakeLike(Protocol):
    """What :func:`actor_groups` reads of a take (:class:`stylemotion.datasets.base.Take`)."""

    name: str
    positions: np.ndarray
    source: str

    @property
    def style(self) -> str: ...


@dataclass(frozen=True)
class ActorGroups:
    """Takes grouped by skeleton (see :func:`actor_groups`).

    Attributes:
        styles: group id → sorted styles of its takes.
        takes: take name → group id.
        bone_lengths: group id → ``(20,)`` median bone lengths of its takes, metres.
        rest_poses: group id → the rest offsets its takes' files share (:func:`rest_pose`; None: not read).
    """

    styles: dict[int, list[str]]
    takes: dict[str, int]
    bone_lengths: dict[int, np.ndarray]
    rest_poses: dict[int, tuple[float, ...] | None] = field(default_factory=dict)


def rest_pose(take: TakeLike) -> tuple[float, ...] | None:
    """The rest offsets of every joint of the BVH file a take was read from (file units, rounded to 1e-3, in file
    order), or None for a take not read from a BVH file (synthetic, converted arrays).

    Only the file's hierarchy is read (:func:`stylemotion.io.bvh.parse_bvh_skeleton`), not its frames.

    Raises:
        MotionDataError, BvhError: the file cannot be read any more or its hierarchy is malformed, naming it.
    """
    source = FileSource.from_name(take.source) if take.source else None
    if source is None or not PurePosixPath(source.member or source.path).suffix.lower() == ".bvh":
        return None
    return bvh_rest_pose(source)


def bvh_rest_pose(source: FileSource) -> tuple[float, ...]:
    """The rest offsets of every joint of a BVH file (file units, rounded to 1e-3, in file order), its frames unread.

    Raises:
        MotionDataError, BvhError: the file cannot be read or its hierarchy is malformed, naming it.
    """
    head = source.read_head(MAX_HIERARCHY_BYTES, stop=b"MOTION")
    try:
        offsets = parse_bvh_skeleton(head, source.name).offsets
    except BvhError:  # "MOTION" inside a joint's name stopped the read early: read on, to the bound
        offsets = parse_bvh_skeleton(source.read_head(MAX_HIERARCHY_BYTES), source.name).offsets
    return tuple(round(float(v), 3) for v in np.asarray(offsets, dtype=np.float64).ravel())


def actor_groups(takes: Sequence[TakeLike], tolerance_m: float = ACTOR_TOLERANCE_M, rest_poses: bool = True
                 ) -> ActorGroups:
    """Group takes by actor, i.e. by skeleton: takes whose median bone lengths agree within a tolerance and whose
    files share one rest pose.

    Two takes are linked when every bone's median length (:func:`stylemotion.bones.median_bone_lengths`)
    differs by at most ``tolerance_m`` and (with ``rest_poses``) their BVH files hold the same rest offsets
    (:func:`rest_pose`; takes not read from BVH form one rest pose of their own). A group is a connected set of
    linked takes (single linkage, so the result does not depend on the order of ``takes``). Group ids count from 0
    in the order of each group's first take by name. A style recorded by two actors appears in both groups.

    Why the rest pose: a data set may ship every actor on one set of bone lengths and keep each actor's own
    calibration only in the file's rest offsets (Bandai dataset-2: equal bones in every take, one offset of
    the root's child per actor; docs/data.md).

    Args:
        takes: takes with a ``style`` label and ``(frames, 21, 3)`` positions in metres.
        tolerance_m: largest difference of any bone between linked takes, metres.
        rest_poses: also split by the files' rest offsets (False: bone lengths only).

    Raises:
        ValueError: ``tolerance_m`` is not a non-negative number.
        MotionDataError, BvhError: a take's BVH file cannot be read for its rest pose (with ``rest_poses``).
    """
    if isinstance(tolerance_m, bool) or not isinstance(tolerance_m, (int, float)) or not tolerance_m >= 0:
        raise ValueError(f"tolerance_m must be a number of metres ≥ 0, got {tolerance_m!r}")
    ordered = sorted(takes, key=lambda t: t.name)
    if not ordered:
        return ActorGroups({}, {}, {})
    lengths = np.stack([median_bone_lengths(t.positions) for t in ordered])  # (takes, 20)
    poses = [rest_pose(t) if rest_poses else None for t in ordered]
    pose_ids: dict[tuple[float, ...] | None, int] = {}
    for pose in poses:
        pose_ids.setdefault(pose, len(pose_ids))
    apart = 2.0 * (float(tolerance_m) + 1.0)  # farther than any tolerance: another rest pose is never linked
    points = np.column_stack([lengths, [apart * pose_ids[pose] for pose in poses]])
    if len(ordered) == 1:
        labels = np.zeros(1, dtype=int)
    else:
        labels = fcluster(linkage(points, method="single", metric="chebyshev"), t=tolerance_m,
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
        rest_poses={g: poses[m[0]] for g, m in members.items()},
    )
