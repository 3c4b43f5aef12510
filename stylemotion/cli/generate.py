"""``stylemotion-generate``: a walk along a ground path, neutral or stylized, exported (thesis §5.4.4).

    stylemotion-generate                                          # neutral, 10 m S-curve, synthetic run
    stylemotion-generate run=runs/reproduce/bandai style=elderly seed=3
    stylemotion-generate style=active path.file=path.csv out=runs/generate/active_path
    stylemotion-generate run=runs/style/mine style=mine           # a style made by stylemotion-style

The work and the folder's contents: :mod:`stylemotion.synthesis.generate`. The summary goes to the log
(console and ``generate.log`` in the Hydra run folder); a bad ``threads``, path file, unknown style or existing
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
from stylemotion.synthesis.generate import generate, summary_lines
from stylemotion.synthesis.graph import UnknownStyleError
from stylemotion.synthesis.path import PathError

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    with reported("stylemotion-generate", ConfigError, OutputExistsError, PathError, UnknownStyleError):
        set_torch_threads(cfg.get("threads"))
        summary = generate(cfg, "stylemotion-generate " + " ".join(sys.argv[1:]))
    for line in summary_lines(summary):
        log.info(line)
    log.info("written to %s", cfg.out)


def main() -> None:
    """Console script ``stylemotion-generate``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="generate", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
