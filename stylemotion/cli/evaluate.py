"""``stylemotion-eval``: evaluate trained primitive models and write a report folder.

    stylemotion-eval 'checkpoints=[runs/reproduce/synthetic/vae,runs/reproduce/synthetic/cvae]'
    stylemotion-eval data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right]' \\
        'checkpoints=[runs/train/primitive_vae/multirun/*/*/checkpoints/best.ckpt]' out=reports/eval/bandai

The work is :func:`stylemotion.evaluation.run.run_evaluation`; progress and the summary go to the log
(console and ``eval.log`` in the Hydra run folder).
"""

from __future__ import annotations

import logging
import sys

import hydra
from omegaconf import DictConfig

from stylemotion.cli import reported
from stylemotion.config import CONFIG_PACKAGE, ConfigError, set_torch_threads
from stylemotion.evaluation.run import run_evaluation, summary_lines
from stylemotion.io.outputs import OutputExistsError

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    command = "stylemotion-eval " + " ".join(sys.argv[1:])
    with reported("stylemotion-eval", ConfigError, OutputExistsError):
        set_torch_threads(cfg.get("threads"))
        results = run_evaluation(cfg.data, list(cfg.checkpoints), cfg.evaluation, cfg.out, int(cfg.seed),
                                 cfg.get("autoencoder_ckpt"), bool(cfg.force), command, progress=log.info)
    for line in summary_lines(results):
        log.info(line)
    log.info("report written to %s", cfg.out)


def main() -> None:
    """Console script ``stylemotion-eval``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="eval", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
