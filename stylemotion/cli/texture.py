"""``stylemotion-texture``: motion completion or texturing with a motion database (Krüger §4.2).

    stylemotion-texture motion=legs.npz mode=complete data=bandai out=runs/texture/mine
    stylemotion-texture motion=synthetic_walk_normal_000 mode=complete 'data.styles=[elderly]'

The work and the folder it writes: :mod:`stylemotion.reconstruct.texture_command`. A bad motion, joint, mode,
setting, dataset or an existing ``out`` ends in one line naming it.
"""

from __future__ import annotations

import logging
import sys

import hydra
from omegaconf import DictConfig

from stylemotion.cli import reported
from stylemotion.config import CONFIG_PACKAGE, ConfigError
from stylemotion.io.outputs import OutputExistsError
from stylemotion.reconstruct.markers import MarkerInputError
from stylemotion.reconstruct.texture import TextureInputError
from stylemotion.reconstruct.texture_command import texture_from_config

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    with reported("stylemotion-texture", ConfigError, OutputExistsError, MarkerInputError, TextureInputError):
        texture_from_config(cfg, say=log.info, command="stylemotion-texture " + " ".join(sys.argv[1:]))


def main() -> None:
    """Console script ``stylemotion-texture``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="texture", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
