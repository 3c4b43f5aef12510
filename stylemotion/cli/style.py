"""``stylemotion-style``: a new style from the user's own example, added to a finished reproduce run.

    stylemotion-style example=my_walk.bvh run=runs/reproduce/synthetic name=mine
    stylemotion-style example=walk_120fps.bvh:240-960 run=runs/reproduce/bandai name=limp

The work is :func:`stylemotion.style_example.add_style`; progress and the summary go to the log (console
and ``style.log`` in the Hydra run folder). A bad example, frame range, run, name, method or an existing
``out`` ends in one line naming it.
"""

from __future__ import annotations

import logging
import sys

import hydra
from omegaconf import DictConfig

from stylemotion.cli import reported
from stylemotion.config import CONFIG_PACKAGE, ConfigError, set_torch_threads
from stylemotion.io.outputs import OutputExistsError
from stylemotion.style_example import StyleExampleError, add_style_from_config

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    with reported("stylemotion-style", ConfigError, OutputExistsError, StyleExampleError):
        set_torch_threads(cfg.get("threads"))
        add_style_from_config(cfg, say=log.info, command="stylemotion-style " + " ".join(sys.argv[1:]))


def main() -> None:
    """Console script ``stylemotion-style``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="style", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
