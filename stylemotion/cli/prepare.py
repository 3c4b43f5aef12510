"""``stylemotion-data``: build a dataset (or load it from the cache), log and save its summary.

    stylemotion-data                              # the embedded synthetic dataset
    stylemotion-data data=bandai                  # Bandai from ../shared/data (or $STYLEMOTION_DATA)
    stylemotion-data data=bvh_folder data.root=my_bvhs data.pattern='(?P<style>[a-z]+)_(?P<take>\\d+)'

The run folder (``runs/prepare/<data>/<time>/``) gets ``summary.json`` and ``prepare.log`` (the summary
as shown on the console).
"""

from __future__ import annotations

import logging
from pathlib import Path

import hydra
from hydra.core.hydra_config import HydraConfig
from omegaconf import DictConfig

from stylemotion.config import CONFIG_PACKAGE
from stylemotion.datasets.summary import format_summary, write_dataset_summary

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    out_dir = Path(HydraConfig.get().runtime.output_dir)
    summary = write_dataset_summary(cfg.data, out_dir)
    log.info(format_summary(summary))
    log.info("summary written to %s", out_dir / "summary.json")


def main() -> None:
    """Console script ``stylemotion-data``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="prepare", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
