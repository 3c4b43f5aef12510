"""``stylemotion-segment``: segment walks and runs into motion primitives and write a report folder.

    stylemotion-segment                                  # the embedded synthetic dataset
    stylemotion-segment data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right,run]' \\
        out=reports/segmentation/bandai

The work and the folder's contents: :mod:`stylemotion.segmentation_report`.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path

import hydra
from omegaconf import DictConfig

from stylemotion.cli import reported
from stylemotion.config import CONFIG_PACKAGE
from stylemotion.io.outputs import OutputExistsError
from stylemotion.segmentation_report import summary_lines, write_report

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    command = "stylemotion-segment " + " ".join(sys.argv[1:])
    with reported("stylemotion-segment", OutputExistsError):
        report = write_report(cfg, Path(cfg.out), bool(cfg.force), command)
    for line in summary_lines(report, Path(cfg.out)):
        log.info(line)


def main() -> None:
    """Console script ``stylemotion-segment``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="segment", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
