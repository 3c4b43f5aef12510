"""The one reader of a user's motion: ``<BVH>[:start-end]`` → canonical positions.

Every command that takes a motion file from its user (``stylemotion-style``'s ``example=``,
``stylemotion-search``'s ``query=``, ``stylemotion-annotate``'s ``document=``, ``stylemotion-reconstruct``'s
BVH markers) reads it here. The file is read and converted exactly as the datasets convert theirs
(:func:`stylemotion.datasets.loading.convert_motion`: any skeleton whose joints a built-in or given
joint map names, any units, any frame rate, resampled to the wanted fps). ``start-end`` are frames
of the **file's own frame rate**, counted from 0, ``end`` exclusive (``walk.bvh:120-480`` of a
120 fps file is seconds 1 to 4); they are cut before resampling. :func:`on_run_skeleton` then puts
the motion on a data set's skeleton: the one the data's ``data.retarget`` chose, else the median bones
of its neutral takes — the models only know the data's bodies, and a motion of other proportions would
otherwise be a different "style" in every frame.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from stylemotion.bones import BONE_NAMES, retarget_positions, target_bone_lengths
from stylemotion.datasets.base import Take, TakeSet
from stylemotion.datasets.loading import ConversionSettings, convert_motion
from stylemotion.datasets.retarget import skeleton_record
from stylemotion.io.bvh import parse_bvh
from stylemotion.io.errors import MotionDataError, UserInputError
from stylemotion.io.outputs import safe_name
from stylemotion.io.sources import FileSource

#: The config keys that say how a user's BVH file is converted (None: detected); every command takes them.
CONVERSION_KEYS = ("joint_map", "unit_scale", "up_axis")


def conversion_keys(config: Mapping[str, Any]) -> dict[str, Any]:
    """The :data:`CONVERSION_KEYS` of a command's (plain) config, each None when absent."""
    return {key: config.get(key) for key in CONVERSION_KEYS}


#: A frame range after the file: ``:<start>-<end>``, whatever the two parts hold (checked afterwards).
_RANGE = re.compile(r"^(?P<path>.*[^:]):(?P<range>[^:/\\]*-[^:/\\]*)$")


class UserMotionError(UserInputError, ValueError):
    """A user's motion file or cut that cannot be used; the message names the command's key and the value."""


class FrameSpan(Protocol):
    """Frames ``start:stop`` of a converted motion (a :class:`stylemotion.primitives.segmentation.Clip`, for one)."""

    start: int
    stop: int


@dataclass(frozen=True)
class ExampleSpec:
    """What ``example=`` (or another command's key, e.g. ``stylemotion-search``'s ``query=``) names.

    Attributes:
        path: the BVH file, or ``archive.zip::member.bvh``.
        start: first frame to use, at the file's frame rate (0 = the first), or None (all).
        end: one past the last frame to use, or None (all).
        key: the command's key that named it, for messages (not part of equality).
    """

    path: str
    start: int | None = None
    end: int | None = None
    key: str = field(default="example", compare=False)

    @property
    def source(self) -> FileSource:
        return FileSource.from_name(self.path if "::" in self.path else str(Path(self.path).expanduser()))

    def __str__(self) -> str:
        return self.path if self.start is None else f"{self.path}:{self.start}-{self.end}"


def parse_example(text: str, key: str = "example") -> ExampleSpec:
    """``<BVH>[:start-end]`` → :class:`ExampleSpec` (the range checked for syntax only).

    A value that names an existing file as a whole is that file, even if it ends like a range. ``key``: the
    command's key that gave the value, named in messages (``stylemotion-search`` passes ``query``).

    Raises:
        UserMotionError: an empty value, or a range that is not two whole numbers ``start < end``, ``start ≥ 0``.
    """
    text = str(text or "").strip()
    if not text:
        raise UserMotionError(f"{key}= is empty: give a BVH file, optionally with a frame range "
                                f"({key}=walk.bvh or {key}=walk.bvh:120-480)")
    match = _RANGE.match(text)
    if match is None or Path(text).expanduser().is_file():
        return ExampleSpec(text, key=key)
    bounds = match["range"].split("-")
    if len(bounds) != 2 or not all(re.fullmatch(r"[0-9]+", b.strip()) for b in bounds):
        raise UserMotionError(f"{key}={text}: the frame range {match['range']!r} must be START-END, two whole "
                                f"numbers ≥ 0 of the file's frames (e.g. {key}=walk.bvh:120-480)")
    start, end = (int(b) for b in bounds)
    if start >= end:
        raise UserMotionError(f"{key}={text}: the frame range {start}-{end} is empty; START must be smaller "
                                "than END (frames of the file, END exclusive)")
    return ExampleSpec(match["path"], start, end, key)


@dataclass
class ConvertedExample:
    """The example on the canonical skeleton, with where it came from.

    Attributes:
        spec: what ``example=`` named.
        sha256: hex SHA-256 of the file's bytes (of the zip member's, for a member).
        file_fps: the file's frame rate.
        file_frames: frames in the whole file.
        start, end: the frames used, at ``file_fps`` (``end`` exclusive).
        positions: ``(frames, 21, 3)`` float32 canonical positions, metres, Y up, at ``fps``.
        fps: frames per second of ``positions`` (the run's).
        retarget: the skeleton it was put on (the data's ``TakeSet.retarget`` record), or None (its own bones).
    """

    spec: ExampleSpec
    sha256: str
    file_fps: float
    file_frames: int
    start: int
    end: int
    positions: np.ndarray
    fps: float
    retarget: dict[str, Any] | None = None

    @property
    def name(self) -> str:
        """What messages and records call the file (path, or ``zip::member``)."""
        return self.spec.source.name

    def take(self, style: str, content: str) -> Take:
        """The example as a take of ``style`` and ``content`` (named after the file)."""
        name = safe_name(self.spec.source.stem, "example file name")
        return Take(name, self.positions, self.fps, {"content": content, "style": style, "take": name}, self.name)

    def record(self, clip: FrameSpan) -> dict[str, Any]:
        """Plain values that identify ``clip`` in the file: name, sha256, the clip's frames at the file's rate."""
        scale = self.file_fps / self.fps
        return {"file": self.name, "sha256": self.sha256, "file_fps": self.file_fps,
                "file_range": [self.start, self.end],
                "file_frames": [self.start + int(round(clip.start * scale)),
                                self.start + int(round((clip.stop - 1) * scale)) + 1]}


def convert_example(spec: ExampleSpec, settings: ConversionSettings) -> ConvertedExample:
    """Read, cut and convert the example (see the module doc).

    Raises:
        UserMotionError: the range lies outside the file, or the file cannot be read or converted (a
            skeleton no joint map fits, bad units, a malformed BVH: the message names the file and says
            which key helps).
    """
    source = spec.source
    try:
        data = source.read_bytes(settings.max_file_mb)
        motion = parse_bvh(data, source.name, settings.max_joint_frames)
    except MotionDataError as exc:
        raise UserMotionError(f"{spec.key}={spec}: {exc}") from exc
    total = motion.num_frames
    start, end = (0, total) if spec.start is None else (spec.start, spec.end)
    if end > total:
        raise UserMotionError(f"{spec.key}={spec}: the frame range {start}-{end} ends after the file's last frame: "
                                f"{source.name} has {total} frames (0-{total}) at {motion.fps:g} fps")
    cut = replace(motion, rotations=motion.rotations[start:end], translations=motion.translations[start:end])
    try:
        positions = convert_motion(cut, settings)
    except MotionDataError as exc:
        hint = (" Name its joints with joint_map=<map.yaml> (joints: {Hips: <its hips>, ...}, all 21 canonical "
                "joints) or a built-in map (joint_map=bandai|cmu21|cmu31)") if "joint map" in str(exc) else ""
        raise UserMotionError(f"{spec.key}={spec}: {exc}.{hint}") from exc
    return ConvertedExample(spec, hashlib.sha256(data).hexdigest(), float(motion.fps), total, start, end,
                            positions, float(settings.fps))


def on_run_skeleton(example: ConvertedExample, takeset: TakeSet, neutral_style: str = "normal") -> ConvertedExample:
    """The example on the run's skeleton, by :func:`stylemotion.bones.retarget_positions`: the bone
    lengths ``takeset.retarget`` records (``data.retarget``), else the median bones of the takes of
    ``neutral_style`` (every takeset's fallback; all takes if it has none of that style).

    Raises:
        UserMotionError: its bones cannot be put on that skeleton (naming the bone).
    """
    record = getattr(takeset, "retarget", None)
    if not record:
        neutral = takeset.filter(style=neutral_style)
        takes = neutral or list(takeset.takes)
        record = skeleton_record(neutral_style if neutral else None, len(takes),
                                 target_bone_lengths(t.positions for t in takes))
    target = np.array([record["bone_lengths_m"][bone] for bone in BONE_NAMES])
    try:
        positions = retarget_positions(example.positions, target).astype(np.float32)
    except ValueError as exc:
        raise UserMotionError(f"{example.spec.key}={example.spec}: cannot put it on the run's skeleton (bones of "
                                f"{record.get('style') or 'all takes'}): {exc}") from None
    return replace(example, positions=positions, retarget=dict(record))
