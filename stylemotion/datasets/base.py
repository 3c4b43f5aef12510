"""Takes and take collections: what every dataset produces.

A *take* is one continuous recording converted to canonical positions (metres, Y up, canonical
21-joint order) at the dataset's fps, with string labels (``content``, ``style``, ``take`` and
whatever else the source knows).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from stylemotion.config import ConfigError
from stylemotion.representation import positions_to_frames


@dataclass
class Take:
    """One recording on the canonical skeleton.

    Attributes:
        name: unique id within its dataset (e.g. the file stem), a safe file-name component
            (:func:`stylemotion.io.outputs.safe_name`).
        positions: ``(frames, 21, 3)`` float32 global positions, metres, Y up.
        fps: frames per second.
        labels: at least ``content`` and ``style``; ``take`` identifies the recording.
        source: file path or ``zip::member`` it came from.
    """

    name: str
    positions: np.ndarray
    fps: float
    labels: dict[str, str] = field(default_factory=dict)
    source: str = ""

    @property
    def num_frames(self) -> int:
        return int(self.positions.shape[0])

    @property
    def content(self) -> str:
        return self.labels.get("content", "")

    @property
    def style(self) -> str:
        return self.labels.get("style", "")

    @cached_property
    def frames(self) -> np.ndarray:
        """``(frames, 66)`` float32 frame representation (see :mod:`stylemotion.representation`)."""
        return positions_to_frames(self.positions, self.fps)[0]


@dataclass
class TakeSet:
    """The takes of a dataset plus its deterministic split into train/val/test by take.

    Attributes:
        name: dataset name (``bandai``, ``bvh_folder``, ``synthetic``).
        takes: all takes, sorted by name.
        fps: the common frame rate of all takes.
        skipped: ``[(source, reason)]`` for inputs that were skipped (only with skip_broken).
        warnings: messages about inputs that loaded but look wrong (each names its file).
        retarget: None when every take keeps its own bones; else the skeleton all takes were put
            on (``style``, ``takes``, ``bone_lengths_m``; see :mod:`stylemotion.datasets.retarget`).
    """

    name: str
    takes: list[Take]
    fps: float
    skipped: list[tuple[str, str]] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    retarget: dict[str, Any] | None = None

    def __len__(self) -> int:
        return len(self.takes)

    @property
    def num_frames(self) -> int:
        return sum(t.num_frames for t in self.takes)

    def filter(self, **labels: str | list[str] | tuple[str, ...]) -> list[Take]:
        """Takes whose labels match, e.g. ``filter(content="walk", style=["normal", "elderly"])``."""
        def ok(take: Take) -> bool:
            for key, want in labels.items():
                allowed = [want] if isinstance(want, str) else list(want)
                if take.labels.get(key) not in allowed:
                    return False
            return True

        return [t for t in self.takes if ok(t)]

    def label_values(self, key: str) -> list[str]:
        """Sorted distinct values of label ``key``."""
        return sorted({t.labels.get(key, "") for t in self.takes})

    def split(
        self, seed: int = 0, val_fraction: float = 0.1, test_fraction: float = 0.1,
        group_by: tuple[str, ...] = ("content", "style"), test_actor: str | None = None,
    ) -> dict[str, list[Take]]:
        """Seeded split by take: each take is wholly in one of ``train``, ``val``, ``test``.

        Takes are shuffled within each group of equal ``group_by`` labels so that every group
        contributes to every split in proportion (a group of n takes gives
        ``round(n·fraction)`` to val and test, at least one each when n ≥ 3).

        ``test_actor`` (``data.split.test_actor``, a style name): the actor split. Every take of the actor who
        performed that style (:func:`stylemotion.datasets.actors.actor_groups`; in Bandai the actor's other styles
        too) is ``test``, and the other takes split into ``train`` and ``val`` as above (``test_fraction`` unused).
        """
        if test_actor is not None:
            return self._actor_split(seed, val_fraction, group_by, test_actor)
        if not 0 <= val_fraction < 1 or not 0 <= test_fraction < 1 or val_fraction + test_fraction >= 1:
            raise ConfigError(f"data.split: fractions must be in [0, 1) and sum below 1, got val={val_fraction}, "
                             f"test={test_fraction}")
        rng = np.random.default_rng(seed)
        groups: dict[tuple[str, ...], list[Take]] = {}
        for take in self.takes:
            groups.setdefault(tuple(take.labels.get(k, "") for k in group_by), []).append(take)
        out: dict[str, list[Take]] = {"train": [], "val": [], "test": []}
        for key in sorted(groups):
            members = groups[key]
            order = rng.permutation(len(members))
            n = len(members)
            n_val = _share(n, val_fraction)
            n_test = _share(n, test_fraction)
            if n_val + n_test >= n:  # always keep at least one take for training
                n_val, n_test = (min(n_val, max(n - 1, 0)), 0) if n < 3 else (n_val, n - 1 - n_val)
            picks = [members[i] for i in order]
            out["val"].extend(picks[:n_val])
            out["test"].extend(picks[n_val:n_val + n_test])
            out["train"].extend(picks[n_val + n_test:])
        for part in out.values():
            part.sort(key=lambda t: t.name)
        return out

    def _actor_split(self, seed: int, val_fraction: float, group_by: tuple[str, ...], test_actor: Any
                     ) -> dict[str, list[Take]]:
        """:meth:`split` with ``test_actor``: that actor's takes as ``test``, the rest split into train and val."""
        from stylemotion.datasets.actors import actor_groups

        styles = self.label_values("style")
        if not isinstance(test_actor, str) or test_actor not in styles:
            raise ConfigError(f"data.split.test_actor must name a style of dataset {self.name!r} (its actor's takes "
                              f"become the test split; null: split by take), got {test_actor!r}; its styles are "
                              f"{styles}")
        groups = actor_groups(self.takes)
        held = {g for g, members in groups.styles.items() if test_actor in members}
        test = [t for t in self.takes if groups.takes[t.name] in held]
        rest = [t for t in self.takes if groups.takes[t.name] not in held]
        if not rest:
            raise ConfigError(f"data.split.test_actor={test_actor!r}: every take of dataset {self.name!r} is that "
                              "actor's; an actor split needs the takes of another actor to train on")
        out = TakeSet(self.name, rest, self.fps).split(seed, val_fraction, 0.0, group_by)
        out["test"] = sorted(test, key=lambda t: t.name)
        return out


def _share(n: int, fraction: float) -> int:
    if fraction <= 0:
        return 0
    return max(1, round(n * fraction)) if n >= 3 else 0


def spread_over_styles(takes: Sequence[Take], contents: Sequence[str], per_content: int,
                       rng: np.random.Generator | None = None) -> list[Take]:
    """``per_content`` takes of each content, taken in turn from each style, so a benchmark's queries cover every
    style rather than the first one alphabetically. Without ``rng``: takes by name within a style, styles in name
    order; with it: a random order of the takes and of the styles (the same draws for the same generator state)."""
    chosen: list[Take] = []
    for content in contents:
        pool = sorted((t for t in takes if t.content == content), key=lambda t: t.name)
        if rng is not None:
            pool = [pool[i] for i in rng.permutation(len(pool))]
        by_style: dict[str, list[Take]] = {}
        for take in pool:
            by_style.setdefault(take.style, []).append(take)
        order = sorted(by_style) if rng is None else list(rng.permutation(sorted(by_style)))
        queues = [by_style[s] for s in order]
        picked: list[Take] = []
        while len(picked) < per_content and any(queues):
            for queue in queues:
                if queue and len(picked) < per_content:
                    picked.append(queue.pop(0))
        chosen += picked
    return chosen
