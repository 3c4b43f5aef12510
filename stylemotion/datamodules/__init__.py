"""Lightning DataModules over datasets, and normalization."""

from stylemotion.datamodules.normalization import Normalizer, channel_stats
from stylemotion.datamodules.windows import (
    REPRESENTATION,
    EmptySplitError,
    MotionWindowDataModule,
    WindowDataset,
    window_starts,
)

__all__ = ["REPRESENTATION", "EmptySplitError", "MotionWindowDataModule", "Normalizer", "WindowDataset",
           "channel_stats", "window_starts"]
