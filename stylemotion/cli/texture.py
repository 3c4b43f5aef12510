"""``stylemotion-texture``: motion completion or texturing with a motion database (Krüger §4.2).

    stylemotion-texture motion=legs.npz mode=complete data=bandai out=runs/texture/mine
    stylemotion-texture motion=synthetic_walk_normal_000 mode=complete 'data.styles=[elderly]'

The work and the folder it writes: :mod:`stylemotion.reconstruct.texture_command`. A bad motion, joint, mode,
setting, dataset or an existing ``out`` ends in one line naming it.
"""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command

log = logging.getLogger(__name__)


def texture(cfg: DictConfig, command: str) -> None:
    from stylemotion.reconstruct.texture_command import texture_from_config

    texture_from_config(cfg, command=command)


main = hydra_command("stylemotion-texture", "texture", texture, record_in="out")


if __name__ == "__main__":
    main()
