"""``stylemotion-annotate``: motion annotation by class motion templates and tensors (Krüger ch. 3, §4.1).

    stylemotion-annotate data=bandai out=runs/annotate/bandai_templates
    stylemotion-annotate document=my_capture.bvh templates=runs/annotate/bandai_templates out=runs/annotate/mine

The work and the folders it writes: :mod:`stylemotion.annotate.command`. A bad document, templates folder,
dataset, threshold or an existing ``out`` ends in one line naming it.
"""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command

log = logging.getLogger(__name__)


def annotate(cfg: DictConfig, command: str) -> None:
    from stylemotion.annotate.command import annotate_from_config

    annotate_from_config(cfg, command=command)


main = hydra_command("stylemotion-annotate", "annotate", annotate, record_in="out")


if __name__ == "__main__":
    main()
