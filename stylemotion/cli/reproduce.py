"""``stylemotion-reproduce``: data → autoencoder → VAEs → style CVAEs → evaluation, in one command.

    stylemotion-reproduce                                   # the embedded synthetic data, a few minutes
    stylemotion-reproduce data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right]'
    stylemotion-reproduce data=bandai ... out=runs/reproduce/bandai_2   # a second, independent run

The work is :func:`stylemotion.training.reproduction.reproduce`; its module doc describes the stages.
"""

from __future__ import annotations

import logging
from typing import Any

from hydra.experimental.callback import Callback
from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command, one_line_errors

log = logging.getLogger(__name__)


class OutFolderCheck(Callback):
    """Refuses an ``out`` that is a file (or below one, or in a read-only folder) in one line before Hydra makes its
    log folder ``<out>/hydra/<time>`` in it (Hydra's own error would be a traceback); registered in reproduce.yaml."""

    def on_run_start(self, config: DictConfig, **kwargs: Any) -> None:
        from stylemotion.training.reproduction import check_out_folder

        with one_line_errors("stylemotion-reproduce"):  # SystemExit(2) passes Hydra's error report
            check_out_folder(config.out)


def reproduce(cfg: DictConfig, command: str) -> None:
    from stylemotion.training.reproduction import reproduce

    reproduce(cfg)  # progress is logged: the console and <out>/hydra/<time>/reproduce.log


main = hydra_command("stylemotion-reproduce", "reproduce", reproduce)


if __name__ == "__main__":
    main()
