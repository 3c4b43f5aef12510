"""Datasets: every source becomes a :class:`TakeSet` of canonical takes."""

from stylemotion.datasets.base import Take, TakeSet, spread_over_styles
from stylemotion.datasets.loading import ConversionSettings, DatasetBuildError
from stylemotion.datasets.registry import DATASETS, build_dataset, data_config_key, load_dataset, register_dataset

__all__ = ["DATASETS", "ConversionSettings", "DatasetBuildError", "Take", "TakeSet", "build_dataset",
           "data_config_key", "load_dataset", "register_dataset", "spread_over_styles"]
