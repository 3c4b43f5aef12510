"""``stylemotion-eval``: evaluate trained primitive models and write a report folder.

    stylemotion-eval 'checkpoints=[runs/reproduce/synthetic/vae,runs/reproduce/synthetic/cvae]'
    stylemotion-eval data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right]' \\
        'checkpoints=[runs/train/primitive_vae/multirun/*/*/checkpoints/best.ckpt]' out=reports/eval/bandai
    stylemotion-eval 'checkpoints=[runs/reproduce/synthetic/vae,runs/reproduce/synthetic/cvae,<zero-shot best.ckpt>]'
    stylemotion-eval 'checkpoints=[<zero-shot best.ckpt>]' example=angry_walk.bvh:120-480 example_style=angry

The work is :func:`stylemotion.evaluation.run.run_evaluation`; progress and the summary go to the log
(console and ``eval.log`` in the Hydra run folder).
"""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command
from stylemotion.config import set_torch_threads

log = logging.getLogger(__name__)


def evaluate(cfg: DictConfig, command: str) -> None:
    from stylemotion.datasets.user_motion import conversion_keys
    from stylemotion.evaluation.run import run_evaluation, summary_lines

    set_torch_threads(cfg.get("threads"))
    results = run_evaluation(cfg.data, list(cfg.checkpoints), cfg.evaluation, cfg.out, int(cfg.seed),
                             cfg.get("autoencoder_ckpt"), bool(cfg.force), command, example=cfg.get("example"),
                             example_style=cfg.get("example_style"),
                             example_conversion=conversion_keys(cfg))
    for line in summary_lines(results):
        log.info(line)
    log.info("report written to %s", cfg.out)


main = hydra_command("stylemotion-eval", "eval", evaluate, record_in="out")


if __name__ == "__main__":
    main()
