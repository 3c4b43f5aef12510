"""``stylemotion-reproduce``: data → autoencoder → VAEs → style CVAEs → evaluation, in one command.

    stylemotion-reproduce                                   # the embedded synthetic data, a few minutes
    stylemotion-reproduce data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right]'
    stylemotion-reproduce data=bandai ... out=runs/reproduce/bandai_2   # a second, independent run

The work is :func:`stylemotion.reproduction.reproduce`; its module doc describes the stages.
"""

from __future__ import annotations

import logging

import hydra
from omegaconf import DictConfig

from stylemotion.cli import reported
from stylemotion.config import CONFIG_PACKAGE, ConfigError
from stylemotion.io.outputs import OutputExistsError
from stylemotion.reproduction import StageConflictError, reproduce

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    with reported("stylemotion-reproduce", StageConflictError, OutputExistsError, ConfigError):
        reproduce(cfg, say=log.info)  # the console and <out>/hydra/<time>/reproduce.log


def main() -> None:
    """Console script ``stylemotion-reproduce``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="reproduce", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
