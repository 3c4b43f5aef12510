"""``stylemotion-eval``: evaluate trained primitive models and write a report folder.

    stylemotion-eval 'checkpoints=[runs/reproduce/synthetic/vae,runs/reproduce/synthetic/cvae]'
    stylemotion-eval data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right]' \\
        'checkpoints=[runs/train/primitive_vae/multirun/*/*/checkpoints/best.ckpt]' out=reports/eval/bandai

The work is :func:`stylemotion.evaluation.run.run_evaluation`.
"""

from __future__ import annotations

import sys

import hydra
import torch
from omegaconf import DictConfig

from stylemotion.config import CONFIG_PACKAGE
from stylemotion.evaluation.run import run_evaluation, summary_lines
from stylemotion.io.outputs import OutputExistsError


def _main(cfg: DictConfig) -> None:
    if cfg.get("threads"):
        torch.set_num_threads(int(cfg.threads))
    command = "stylemotion-eval " + " ".join(sys.argv[1:])
    try:
        results = run_evaluation(cfg.data, list(cfg.checkpoints), cfg.evaluation, cfg.out, int(cfg.seed),
                                 cfg.get("autoencoder_ckpt"), bool(cfg.force), command, progress=print)
    except OutputExistsError as exc:
        sys.exit(f"stylemotion-eval: {exc}")
    for line in summary_lines(results):
        print(line)
    print(f"report written to {cfg.out}")


def main() -> None:
    """Console script ``stylemotion-eval``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="eval", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
