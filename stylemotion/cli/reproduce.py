"""``stylemotion-reproduce``: data → autoencoder → VAEs → style CVAEs → evaluation, in one command.

    stylemotion-reproduce                                   # the embedded synthetic data, a few minutes
    stylemotion-reproduce data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right]'
    stylemotion-reproduce data=bandai ... out=runs/reproduce/bandai_2   # a second, independent run

The work is :func:`stylemotion.training.reproduction.reproduce`; its module doc describes the stages.
"""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command

log = logging.getLogger(__name__)


def reproduce(cfg: DictConfig, command: str) -> None:
    from stylemotion.training.reproduction import reproduce

    reproduce(cfg, say=log.info)  # the console and <out>/hydra/<time>/reproduce.log


main = hydra_command("stylemotion-reproduce", "reproduce", reproduce)


if __name__ == "__main__":
    main()
