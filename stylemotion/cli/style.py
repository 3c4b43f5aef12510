"""``stylemotion-style``: a new style from the user's own example, added to a finished reproduce run.

    stylemotion-style example=my_walk.bvh run=runs/reproduce/synthetic name=mine
    stylemotion-style example=walk_120fps.bvh:240-960 run=runs/reproduce/bandai name=limp
    stylemotion-style 'example=[take1.bvh,take2.bvh:0-900]' run=runs/reproduce/bandai name=limp

The work is :func:`stylemotion.style_example.add_style`; progress and the summary go to the log (console
and ``style.log`` in the Hydra run folder). A bad example (of a list: naming the item), frame range, run, name,
method or an existing ``out`` ends in one line naming it.
"""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command
from stylemotion.config import set_torch_threads

log = logging.getLogger(__name__)


def style(cfg: DictConfig, command: str) -> None:
    from stylemotion.style_example import add_style_from_config

    set_torch_threads(cfg.get("threads"))
    add_style_from_config(cfg, command=command)


main = hydra_command("stylemotion-style", "style", style, record_in="out")


if __name__ == "__main__":
    main()
