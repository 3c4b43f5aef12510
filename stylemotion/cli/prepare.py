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

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command

log = logging.getLogger(__name__)


def prepare(cfg: DictConfig, command: str) -> None:
    from hydra.core.hydra_config import HydraConfig

    from stylemotion.datasets.summary import format_summary, write_dataset_summary

    out_dir = Path(HydraConfig.get().runtime.output_dir)
    summary = write_dataset_summary(cfg.data, out_dir)
    log.info(format_summary(summary))
    log.info("summary written to %s", out_dir / "summary.json")


main = hydra_command("stylemotion-data", "prepare", prepare)


if __name__ == "__main__":
    main()
