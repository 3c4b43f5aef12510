"""Every frame of a dataset in one array, with the way back from a global frame index to its take.

The search indexes frames by a *global index* ``g`` in ``[0, num_frames)``: takes are concatenated in
the TakeSet's order (sorted by name), so take ``i`` holds ``g`` in ``take_start[i]:take_start[i + 1]``.
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from functools import cached_property
from typing import NamedTuple

import numpy as np

from stylemotion.datasets.base import TakeSet
from stylemotion.search.lng import TakeBounds
from stylemotion.skeleton import NUM_JOINTS


class FrameLocation(NamedTuple):
    """Where a global frame lies: take name, frame within the take (at the database's fps), labels."""

    take: str
    frame: int
    content: str
    style: str


@dataclass(frozen=True)
class MotionDatabase:
    """The frames of a :class:`~stylemotion.datasets.base.TakeSet`, concatenated.

    Attributes:
        name: dataset name.
        fps: frames per second of every take.
        positions: ``(frames, 21, 3)`` float32 canonical positions, metres, Y up.
        take_names, contents, styles: per take (tuples of strings).
        take_start: ``(takes + 1,)`` int64 offsets; take ``i`` is ``positions[take_start[i]:take_start[i+1]]``.
        take_id: ``(frames,)`` int32 take of each global frame.  frame_in_take: ``(frames,)`` int32.
    """

    name: str
    fps: float
    positions: np.ndarray
    take_names: tuple[str, ...]
    contents: tuple[str, ...]
    styles: tuple[str, ...]
    take_start: np.ndarray
    take_id: np.ndarray = field(repr=False)
    frame_in_take: np.ndarray = field(repr=False)

    @classmethod
    def from_takeset(cls, takeset: TakeSet) -> MotionDatabase:
        """Concatenate every take; ValueError for a dataset without takes or with a take of another fps."""
        if not takeset.takes:
            raise ValueError(f"dataset {takeset.name!r} has no takes to search (check its root and its "
                             f"contents/styles filters)")
        odd = [t.name for t in takeset.takes if t.fps != takeset.fps]
        if odd:
            raise ValueError(f"dataset {takeset.name!r}: takes {odd[:5]} are not at the dataset's {takeset.fps} fps")
        lengths = np.array([t.num_frames for t in takeset.takes], dtype=np.int64)
        start = np.concatenate([[0], np.cumsum(lengths)])
        take_id = np.repeat(np.arange(len(lengths), dtype=np.int32), lengths)
        frame = (np.arange(start[-1], dtype=np.int64) - start[take_id]).astype(np.int32)
        positions = np.concatenate([np.asarray(t.positions, dtype=np.float32) for t in takeset.takes])
        if positions.shape[1:] != (NUM_JOINTS, 3):
            raise ValueError(f"dataset {takeset.name!r}: positions must be (frames, {NUM_JOINTS}, 3), "
                             f"got {positions.shape}")
        return cls(takeset.name, float(takeset.fps), positions, tuple(t.name for t in takeset.takes),
                   tuple(t.content for t in takeset.takes), tuple(t.style for t in takeset.takes), start,
                   take_id, frame)

    @property
    def num_frames(self) -> int:
        return int(self.positions.shape[0])

    @property
    def num_takes(self) -> int:
        return len(self.take_names)

    def take_slice(self, take: int | str) -> slice:
        """Global frames of take ``take`` (index or name)."""
        i = self.take_index(take)
        return slice(int(self.take_start[i]), int(self.take_start[i + 1]))

    def take_index(self, take: int | str) -> int:
        """Index of a take given by index or name; KeyError/IndexError naming it otherwise."""
        if isinstance(take, str):
            if take not in self._name_to_index:
                raise KeyError(f"no take {take!r} in dataset {self.name!r}")
            return self._name_to_index[take]
        if not 0 <= int(take) < self.num_takes:
            raise IndexError(f"take index {take} out of range [0, {self.num_takes})")
        return int(take)

    def take_positions(self, take: int | str) -> np.ndarray:
        """``(frames, 21, 3)`` positions of one take (a view)."""
        return self.positions[self.take_slice(take)]

    def global_index(self, take: int | str, frame: int) -> int:
        """Global index of ``frame`` of ``take``; IndexError naming the frame and the take's length."""
        i = self.take_index(take)
        length = int(self.take_start[i + 1] - self.take_start[i])
        if not 0 <= frame < length:
            raise IndexError(f"frame {frame} out of range for take {self.take_names[i]!r} ({length} frames)")
        return int(self.take_start[i]) + int(frame)

    def _check_global(self, index: np.ndarray) -> np.ndarray:
        index = np.asarray(index)
        if not np.issubdtype(index.dtype, np.integer):
            raise TypeError(f"global frame indices must be integers, got {index.dtype}")
        bad = index[(index < 0) | (index >= self.num_frames)]
        if bad.size:
            raise IndexError(f"global frame index {int(bad.flat[0])} out of range [0, {self.num_frames}) "
                             f"(-1 marks a missing neighbour, not a frame)")
        return index

    def locate(self, global_index: int) -> FrameLocation:
        """``(take, frame, content, style)`` of one global frame index."""
        g = int(self._check_global(np.asarray(global_index)))
        i = int(self.take_id[g])
        return FrameLocation(self.take_names[i], int(self.frame_in_take[g]), self.contents[i], self.styles[i])

    def locate_many(self, global_indices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Take index and frame-in-take arrays for global indices of any shape."""
        g = self._check_global(global_indices)
        return self.take_id[g], self.frame_in_take[g]

    @cached_property
    def next_in_take(self) -> np.ndarray:
        """``(frames,)`` bool: frame ``g + 1`` exists and belongs to the same take as ``g``."""
        same = np.zeros(self.num_frames, dtype=bool)
        same[:-1] = self.take_id[1:] == self.take_id[:-1]
        return same

    @cached_property
    def take_bounds(self) -> TakeBounds:
        """The take layout the lazy neighbourhood graph walks within (:class:`~stylemotion.search.lng.TakeBounds`)."""
        return TakeBounds.from_next_in_take(self.next_in_take, self.take_id)

    def has_next(self, global_index: int | np.ndarray) -> bool | np.ndarray:
        """Whether the frame after each global index is in the same take (scalar in, bool out)."""
        g = self._check_global(global_index)
        result = self.next_in_take[g]
        return bool(result) if np.ndim(result) == 0 else result

    @cached_property
    def _name_to_index(self) -> dict[str, int]:
        return {name: i for i, name in enumerate(self.take_names)}

    @cached_property
    def digest(self) -> str:
        """Hex digest of the whole content (names, labels, fps, offsets and positions' bytes): two databases
        with the same digest hold the same frames, so caches derived from one fit the other."""
        h = hashlib.sha256()
        h.update(json.dumps({"name": self.name, "fps": self.fps, "takes": self.take_names, "contents": self.contents,
                             "styles": self.styles, "start": self.take_start.tolist()}).encode())
        h.update(np.ascontiguousarray(self.positions, dtype=np.float32).data)
        return h.hexdigest()[:32]
