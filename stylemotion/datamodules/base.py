"""What the DataModules share: where the takes come from, their split settings, the loaders.

:class:`SplitDataModule` holds the data (a ``data`` config node, built lazily and cached on disk by
:func:`stylemotion.datasets.build_dataset`, or an already built :class:`TakeSet`), the split
settings, the batch sizes and ``num_workers``, and serves ``train``/``val``/``test`` (and
``predict`` = test) loaders over ``self.datasets``, which each subclass fills in ``setup``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import lightning.pytorch as pl
from torch.utils.data import DataLoader, Dataset

from stylemotion.datasets import TakeSet, build_dataset


class SplitDataModule(pl.LightningDataModule):
    """Base of the window, clip and feature DataModules (see the module doc).

    Args:
        data: a ``data`` config node as a plain mapping (``name``, loader options, ``split``).
        takeset: an already built :class:`TakeSet` (Python use; not saved in checkpoints).
        batch_size: training batch size.
        eval_batch_size: validation/test batch size; None = ``batch_size``.
        num_workers: DataLoader worker processes (0 = load in the training process).
        split: split settings (``seed``, ``val_fraction``, ``test_fraction``); None = ``data.split``.
    """

    def __init__(self, data: Mapping[str, Any] | None = None, takeset: TakeSet | None = None, batch_size: int = 64,
                 eval_batch_size: int | None = None, num_workers: int = 0, split: Mapping[str, Any] | None = None):
        super().__init__()
        if data is None and takeset is None:
            raise ValueError(f"{type(self).__name__} needs a data config or a takeset")
        if isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1:
            raise ValueError(f"datamodule.batch_size must be an integer ≥ 1, got {batch_size!r}")
        if eval_batch_size is not None and (isinstance(eval_batch_size, bool) or not isinstance(eval_batch_size, int)
                                            or eval_batch_size < 1):
            raise ValueError(f"datamodule.eval_batch_size must be an integer ≥ 1 or null, got {eval_batch_size!r}")
        if isinstance(num_workers, bool) or not isinstance(num_workers, int) or num_workers < 0:
            raise ValueError(f"datamodule.num_workers must be an integer ≥ 0, got {num_workers!r}")
        self.data_cfg = dict(data) if data is not None else None
        self.split_cfg = dict(split if split is not None else (self.data_cfg or {}).get("split") or {})
        self._takeset = takeset
        self.batch_size = batch_size
        self.eval_batch_size = eval_batch_size or batch_size
        self.num_workers = num_workers
        self.datasets: dict[str, Dataset] = {}

    @property
    def takeset(self) -> TakeSet:
        """The takes (built from ``data`` on first use)."""
        if self._takeset is None:
            self._takeset = build_dataset(self.data_cfg)
        return self._takeset

    @property
    def fps(self) -> float:
        return float(self.takeset.fps)

    def prepare_data(self) -> None:
        """Build (and cache on disk) the dataset once, on the first process of each machine."""
        _ = self.takeset

    def check_part(self, part: str) -> None:
        """Raise a subclass' clear error if ``part`` cannot be served (default: anything goes)."""

    def _loader(self, part: str, shuffle: bool) -> DataLoader:
        if part not in self.datasets:
            raise RuntimeError("call setup() before asking for a DataLoader")
        self.check_part(part)
        return DataLoader(self.datasets[part], batch_size=self.batch_size if part == "train" else self.eval_batch_size,
                          shuffle=shuffle, num_workers=self.num_workers, persistent_workers=self.num_workers > 0)

    def train_dataloader(self) -> DataLoader:
        return self._loader("train", shuffle=True)

    def val_dataloader(self) -> DataLoader:
        return self._loader("val", shuffle=False)

    def test_dataloader(self) -> DataLoader:
        return self._loader("test", shuffle=False)

    def predict_dataloader(self) -> DataLoader:
        return self._loader("test", shuffle=False)
