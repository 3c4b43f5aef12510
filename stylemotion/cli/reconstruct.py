"""``stylemotion-reconstruct``: full poses from a few marker tracks (Krüger §2.5.2, after Chai & Hodgins).

    stylemotion-reconstruct markers=tracks.csv data=bandai out=runs/reconstruct/mine
    stylemotion-reconstruct markers=synthetic_walk_normal_000 out=runs/reconstruct/walk

The work and the folder it writes: :mod:`stylemotion.reconstruct.command`. A bad marker file, marker name, gap,
feature set, ``k``, dataset or an existing ``out`` ends in one line naming it.
"""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command

log = logging.getLogger(__name__)


def reconstruct(cfg: DictConfig, command: str) -> None:
    from stylemotion.reconstruct.command import reconstruct_from_config

    reconstruct_from_config(cfg, command=command)


main = hydra_command("stylemotion-reconstruct", "reconstruct", reconstruct, record_in="out")


if __name__ == "__main__":
    main()
