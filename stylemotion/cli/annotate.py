"""``stylemotion-annotate``: motion annotation by class motion templates and tensors (Krüger ch. 3, §4.1).

    stylemotion-annotate data=bandai out=runs/annotate/bandai_templates
    stylemotion-annotate document=my_capture.bvh templates=runs/annotate/bandai_templates out=runs/annotate/mine

The work and the folders it writes: :mod:`stylemotion.annotate.command`. A bad document, templates folder,
dataset, threshold or an existing ``out`` ends in one line naming it.
"""

from __future__ import annotations

import logging
import sys

import hydra
from omegaconf import DictConfig

from stylemotion.annotate.command import AnnotateInputError, annotate_from_config
from stylemotion.cli import reported
from stylemotion.config import CONFIG_PACKAGE, ConfigError
from stylemotion.io.outputs import OutputExistsError

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    with reported("stylemotion-annotate", ConfigError, OutputExistsError, AnnotateInputError):
        annotate_from_config(cfg, say=log.info, command="stylemotion-annotate " + " ".join(sys.argv[1:]))


def main() -> None:
    """Console script ``stylemotion-annotate``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="annotate", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
