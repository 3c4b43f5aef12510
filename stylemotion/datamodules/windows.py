"""Sliding windows over whole takes, as a Lightning DataModule (thesis §5.4.1).

Every take of the dataset (every content and style) is cut into windows of ``window_frames``
frames (60 = the canonical timeline) with a stride of ``stride`` frames (30 = half overlap). With
``cover_tail`` a last window aligned to the take's end is added when the stride leaves frames
uncovered, so every frame of a take of at least one window's length is seen. Takes shorter than
one window are left out (counted in :attr:`MotionWindowDataModule.summary`).

The split is by take (:meth:`stylemotion.datasets.TakeSet.split`, seeded, with the data config's
``split`` settings); the per-channel z-score statistics come from the train split only. ``exclude_styles``
drops every take of those styles from every split *after* splitting, so the other takes keep the parts they
have in the full data (an autoencoder that never saw a style, for the leave-one-style-out evaluation of
:mod:`stylemotion.evaluation.zero_shot`, shares the full run's split). Batches are
raw (un-normalized) frames ``(batch, window_frames, 66)``: the model owns its normalization.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import torch
from torch.utils.data import Dataset

from stylemotion.datamodules.base import SplitDataModule
from stylemotion.datamodules.normalization import DEFAULT_STD_FLOOR, channel_stats
from stylemotion.datasets import Take, TakeSet
from stylemotion.io.errors import UserInputError
from stylemotion.representation import FRAME_DIM, REPRESENTATION

log = logging.getLogger(__name__)

SPLITS = ("train", "val", "test")


class EmptySplitError(UserInputError, ValueError):
    """A split needed for training or testing holds no window."""


class UnknownStyleError(UserInputError, ValueError):
    """``datamodule.exclude_styles`` names a style the data does not have (or leaves none)."""


def window_starts(num_frames: int, window: int, stride: int, cover_tail: bool = True) -> list[int]:
    """First frame of each window of a take of ``num_frames`` frames (empty if shorter than one)."""
    if window < 1 or stride < 1:
        raise ValueError(f"window and stride must be ≥ 1, got {window} and {stride}")
    if num_frames < window:
        return []
    starts = list(range(0, num_frames - window + 1, stride))
    if cover_tail and starts[-1] != num_frames - window:
        starts.append(num_frames - window)
    return starts


class WindowDataset(Dataset):
    """Windows cut on the fly from the concatenated frames of a list of takes.

    Attributes:
        frames: ``(total_frames, 66)`` float32 raw frames of all takes, one after another.
        starts: ``(windows,)`` int64 index of each window's first frame in ``frames``.
        window: frames per window.
        take_names: name of the take each window comes from.
    """

    def __init__(self, takes: Sequence[Take], window: int, stride: int, cover_tail: bool = True):
        self.window = window
        chunks, starts, names, offset = [], [], [], 0
        for take in takes:
            frames = take.frames
            if not np.isfinite(frames).all():
                raise ValueError(f"take {take.name!r} ({take.source or 'no source'}) has non-finite frames")
            local = window_starts(len(frames), window, stride, cover_tail)
            if not local:
                continue
            chunks.append(frames)
            starts.extend(offset + s for s in local)
            names.extend([take.name] * len(local))
            offset += len(frames)
        self.frames = torch.from_numpy(np.concatenate(chunks).astype(np.float32)) if chunks \
            else torch.zeros(0, FRAME_DIM)
        self.starts = torch.as_tensor(starts, dtype=torch.int64)
        self.take_names = names

    def __len__(self) -> int:
        return int(self.starts.numel())

    def __getitem__(self, index: int) -> torch.Tensor:
        """``(window, 66)`` raw frames of window ``index``."""
        start = int(self.starts[index])
        return self.frames[start:start + self.window]


class MotionWindowDataModule(SplitDataModule):
    """Train/val/test windows of a dataset, with train-split normalization statistics.

    Args:
        data: a ``data`` config node as a plain mapping (``name``, loader options, ``split``);
            see ``configs/data/``. Ignored when ``takeset`` is given.
        takeset: an already built :class:`TakeSet` (Python use; not saved in checkpoints).
        window_frames: frames per window (at the dataset's fps).
        stride: frames between window starts.
        cover_tail: add an end-aligned last window where the stride leaves frames out.
        batch_size: training batch size (windows).
        eval_batch_size: validation/test batch size; None = ``batch_size``.
        num_workers: DataLoader worker processes (0 = load in the training process).
        std_floor: smallest per-channel standard deviation (see :mod:`.normalization`).
        split: split settings (``seed``, ``val_fraction``, ``test_fraction``); None = ``data.split``.
        exclude_styles: styles whose takes no split holds (see the module doc).
    """

    #: What a model checks the data against (see ``MotionAutoencoder.check_compatible``).
    representation = REPRESENTATION
    frame_dim = FRAME_DIM

    def __init__(
        self,
        data: Mapping[str, Any] | None = None,
        takeset: TakeSet | None = None,
        window_frames: int = 60,
        stride: int = 30,
        cover_tail: bool = True,
        batch_size: int = 64,
        eval_batch_size: int | None = None,
        num_workers: int = 0,
        std_floor: float = DEFAULT_STD_FLOOR,
        split: Mapping[str, Any] | None = None,
        exclude_styles: Sequence[str] = (),
    ):
        super().__init__(data, takeset, batch_size, eval_batch_size, num_workers, split)
        if window_frames < 2 or stride < 1:
            raise ValueError(f"need window_frames ≥ 2 and stride ≥ 1; got {window_frames}, {stride}")
        if isinstance(exclude_styles, str):
            raise UnknownStyleError(f"datamodule.exclude_styles must be a list of style names, got the string "
                                    f"{exclude_styles!r} (write [{exclude_styles}])")
        if not all(isinstance(s, str) for s in exclude_styles or []):
            raise UnknownStyleError(f"datamodule.exclude_styles must be a list of style names, got {exclude_styles!r}")
        self.exclude_styles = list(exclude_styles or [])
        self.save_hyperparameters(ignore=["takeset"])
        self.window_frames, self.stride, self.cover_tail = window_frames, stride, cover_tail
        self.std_floor = std_floor
        self.datasets: dict[str, WindowDataset] = {}
        self.split_takes: dict[str, list[Take]] = {}
        self.mean: np.ndarray | None = None
        self.std: np.ndarray | None = None
        self.summary: dict[str, Any] = {}

    @property
    def normalization(self) -> tuple[np.ndarray, np.ndarray]:
        """``(mean, std)``, each ``(66,)``, of the train split's frames (after :meth:`setup`)."""
        if self.mean is None or self.std is None:
            raise RuntimeError("call setup() before asking for normalization statistics")
        return self.mean, self.std

    def setup(self, stage: str | None = None) -> None:
        takeset = self.takeset
        if not self.split_takes:
            self.split_takes = self._without_excluded(takeset.split(**self.split_cfg))
            for name in SPLITS:
                self.datasets[name] = WindowDataset(self.split_takes[name], self.window_frames, self.stride,
                                                    self.cover_tail)
            self.summary = {
                name: {"takes": len(self.split_takes[name]), "windows": len(self.datasets[name]),
                       "frames": int(self.datasets[name].frames.shape[0])} for name in SPLITS
            }
            log.info("windows of %d frames (stride %d) from %s: %s", self.window_frames, self.stride,
                     takeset.name, self.summary)
        needed = {"fit": ("train", "val"), "validate": ("train", "val"), "test": ("train", "test"),
                  "predict": ("train", "test"), None: ("train", "val", "test")}[stage]
        for name in needed:
            self._require(name)
        if self.mean is None:
            self.mean, self.std = channel_stats([self.datasets["train"].frames.numpy()], self.std_floor)

    def _without_excluded(self, parts: dict[str, list[Take]]) -> dict[str, list[Take]]:
        """``parts`` without the takes of ``exclude_styles`` (each of which must be a style of the data)."""
        if not self.exclude_styles:
            return parts
        styles = self.takeset.label_values("style")
        unknown = [s for s in self.exclude_styles if s not in styles]
        if unknown:
            raise UnknownStyleError(f"datamodule.exclude_styles: style(s) {unknown} are not in dataset "
                                    f"{self.takeset.name!r} (styles: {styles}); name styles of the data")
        if not set(styles) - set(self.exclude_styles):
            raise UnknownStyleError(f"datamodule.exclude_styles {self.exclude_styles} leaves no style of dataset "
                                    f"{self.takeset.name!r} to train on")
        return {name: [t for t in takes if t.style not in self.exclude_styles] for name, takes in parts.items()}

    def _require(self, name: str) -> None:
        if len(self.datasets[name]):
            return
        takes = self.split_takes[name]
        short = sum(t.num_frames < self.window_frames for t in takes)
        raise EmptySplitError(
            f"the {name!r} split of dataset {self.takeset.name!r} has no window of {self.window_frames} "
            f"frames: it holds {len(takes)} of the dataset's {len(self.takeset)} takes"
            + (f" ({short} shorter than one window)" if short else "")
            + f"; split settings {self.split_cfg or '(defaults)'}. A (content, style) group needs at least "
            "3 takes to give val and test one each: use more takes, other split fractions or a shorter "
            "window."
        )

