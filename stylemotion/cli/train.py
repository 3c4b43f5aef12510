"""``stylemotion-train``: fit the LightningModule ``cfg.model`` on the DataModule ``cfg.datamodule``.

    stylemotion-train experiment=autoencoder data=bandai           # the thesis' motion autoencoder
    stylemotion-train experiment=smoke                              # seconds, on the synthetic data
    stylemotion-train experiment=smoke -m model.kernel_size=9,15,25 # a sweep (basic launcher)

The work is :func:`stylemotion.training.run`; its module doc describes the run folder.
"""

from __future__ import annotations

import hydra
from omegaconf import DictConfig

from stylemotion.config import CONFIG_PACKAGE
from stylemotion.training import objective, run


def _main(cfg: DictConfig) -> float | None:
    result = run(cfg)
    return objective(result["metrics"], cfg)


def main() -> None:
    """Console script ``stylemotion-train``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="train", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
