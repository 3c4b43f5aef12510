"""``stylemotion-generate``: a walk along a ground path, neutral or stylized, exported (thesis §5.4.4).

    stylemotion-generate                                          # neutral, 10 m S-curve, synthetic run
    stylemotion-generate run=runs/reproduce/bandai style=elderly seed=3
    stylemotion-generate style=active path.file=path.csv out=runs/generate/active_path

The work and the folder's contents: :mod:`stylemotion.synthesis.generate`.
"""

from __future__ import annotations

import sys

import hydra
import torch
from omegaconf import DictConfig

from stylemotion.config import CONFIG_PACKAGE
from stylemotion.io.outputs import OutputExistsError
from stylemotion.synthesis.generate import generate, summary_lines


def _main(cfg: DictConfig) -> None:
    if cfg.get("threads"):
        torch.set_num_threads(int(cfg.threads))
    try:
        summary = generate(cfg, "stylemotion-generate " + " ".join(sys.argv[1:]))
    except OutputExistsError as exc:
        sys.exit(f"stylemotion-generate: {exc}")
    for line in summary_lines(summary):
        print(line)
    print(f"written to {cfg.out}")


def main() -> None:
    """Console script ``stylemotion-generate``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="generate", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
