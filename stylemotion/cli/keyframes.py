"""``stylemotion-keyframes``: a motion through a few keyframes with dynamic motion graphs (Krüger §4.3).

    stylemotion-keyframes keys=keys.json data=bandai out=runs/keyframes/mine

The work and the folder it writes: :mod:`stylemotion.reconstruct.keyframes_command`. A bad key, setting, dataset,
two keys the search cannot join or an existing ``out`` end in one line naming it.
"""

from __future__ import annotations

import logging
import sys

import hydra
from omegaconf import DictConfig

from stylemotion.cli import reported
from stylemotion.config import CONFIG_PACKAGE, ConfigError
from stylemotion.io.outputs import OutputExistsError
from stylemotion.reconstruct.keyframes import KeyframeError, NoConnectionError
from stylemotion.reconstruct.keyframes_command import keyframes_from_config

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    with reported("stylemotion-keyframes", ConfigError, OutputExistsError, KeyframeError, NoConnectionError):
        keyframes_from_config(cfg, say=log.info, command="stylemotion-keyframes " + " ".join(sys.argv[1:]))


def main() -> None:
    """Console script ``stylemotion-keyframes``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="keyframes", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
