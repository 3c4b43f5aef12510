"""Lightning DataModules over datasets, and the normalization statistics of their frames."""

from stylemotion.datamodules.normalization import channel_stats
from stylemotion.datamodules.windows import (
    REPRESENTATION,
    EmptySplitError,
    MotionWindowDataModule,
    WindowDataset,
    window_starts,
)

__all__ = ["REPRESENTATION", "EmptySplitError", "MotionWindowDataModule", "WindowDataset",
           "channel_stats", "window_starts"]
