"""``stylemotion-train``: fit the LightningModule ``cfg.model`` on the DataModule ``cfg.datamodule``.

    stylemotion-train experiment=autoencoder data=bandai           # the thesis' motion autoencoder
    stylemotion-train experiment=smoke                              # seconds, on the synthetic data
    stylemotion-train experiment=smoke -m model.kernel_size=9,15,25 # a sweep (basic launcher)
    stylemotion-train --help                                        # main keys and examples

The work is :func:`stylemotion.training.run`; its module doc describes the run folder, resuming
(``ckpt_path=last|auto|<file>``) and ``force=true``. A bad value (``threads``, ``trainer.*``), a missing
checkpoint or a folder holding another run's results ends in one line naming the key or folder.
"""

from __future__ import annotations

import importlib

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command


def train(cfg: DictConfig, command: str) -> float | None:
    """One training run; returns the sweep objective (a validation metric, see ``objective``)."""
    if cfg.get("runner"):  # a model family fitted without Lightning (e.g. experiment=morphable_graph)
        runner = importlib.import_module(str(cfg.runner))
        return runner.objective(runner.run(cfg)["metrics"])
    from stylemotion.training.fit import objective, run

    result = run(cfg)
    return objective(result["metrics"], cfg)


main = hydra_command("stylemotion-train", "train", train, finished="metrics.json")


if __name__ == "__main__":
    main()
