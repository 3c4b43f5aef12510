"""``stylemotion-keyframes``: a motion through a few keyframes with dynamic motion graphs (Krüger §4.3).

    stylemotion-keyframes keys=keys.json data=bandai out=runs/keyframes/mine

The work and the folder it writes: :mod:`stylemotion.reconstruct.keyframes_command`. A bad key, setting, dataset,
two keys the search cannot join or an existing ``out`` end in one line naming it.
"""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command

log = logging.getLogger(__name__)


def keyframes(cfg: DictConfig, command: str) -> None:
    from stylemotion.reconstruct.keyframes_command import keyframes_from_config

    keyframes_from_config(cfg, command=command)


main = hydra_command("stylemotion-keyframes", "keyframes", keyframes, record_in="out")


if __name__ == "__main__":
    main()
