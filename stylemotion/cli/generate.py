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

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command
from stylemotion.config import set_torch_threads

log = logging.getLogger(__name__)


def generate(cfg: DictConfig, command: str) -> None:
    from stylemotion.synthesis.generate import generate, summary_lines

    set_torch_threads(cfg.get("threads"))
    summary = generate(cfg, command)
    for line in summary_lines(summary):
        log.info(line)
    log.info("written to %s", cfg.out)


main = hydra_command("stylemotion-generate", "generate", generate, record_in="out")


if __name__ == "__main__":
    main()
