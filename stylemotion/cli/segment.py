"""``stylemotion-segment``: segment walks and runs into motion primitives and write a report folder.

    stylemotion-segment                                  # the embedded synthetic dataset
    stylemotion-segment data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right,run]' \\
        out=reports/segmentation/bandai

The work and the folder's contents: :mod:`stylemotion.primitives.report`.
"""

from __future__ import annotations

import logging
from pathlib import Path

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command

log = logging.getLogger(__name__)


def segment(cfg: DictConfig, command: str) -> None:
    from stylemotion.primitives.report import summary_lines, write_report

    report = write_report(cfg, Path(cfg.out), bool(cfg.force), command)
    for line in summary_lines(report, Path(cfg.out)):
        log.info(line)


main = hydra_command("stylemotion-segment", "segment", segment, record_in="out")


if __name__ == "__main__":
    main()
