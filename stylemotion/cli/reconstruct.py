"""``stylemotion-reconstruct``: full poses from a few marker tracks (Krüger §2.5.2, after Chai & Hodgins).

    stylemotion-reconstruct markers=tracks.csv data=bandai out=runs/reconstruct/mine
    stylemotion-reconstruct markers=synthetic_walk_normal_000 out=runs/reconstruct/walk

The work and the folder it writes: :mod:`stylemotion.reconstruct.command`. A bad marker file, marker name, gap,
feature set, ``k``, dataset or an existing ``out`` ends in one line naming it.
"""

from __future__ import annotations

import logging
import sys

import hydra
from omegaconf import DictConfig

from stylemotion.cli import reported
from stylemotion.config import CONFIG_PACKAGE, ConfigError
from stylemotion.io.outputs import OutputExistsError
from stylemotion.reconstruct.command import reconstruct_from_config
from stylemotion.reconstruct.markers import MarkerInputError

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    with reported("stylemotion-reconstruct", ConfigError, OutputExistsError, MarkerInputError):
        reconstruct_from_config(cfg, say=log.info, command="stylemotion-reconstruct " + " ".join(sys.argv[1:]))


def main() -> None:
    """Console script ``stylemotion-reconstruct``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="reconstruct", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
