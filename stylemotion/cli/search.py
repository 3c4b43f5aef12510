"""``stylemotion-search``: the database segments most similar to a query motion (Krüger ch. 2).

    stylemotion-search query=synthetic_walk_normal_000:30-90 out=runs/search/walk
    stylemotion-search data=bandai query=my_walk.bvh:120-480 features=E15 top=10 out=runs/search/mine

The work and the folder it writes: :mod:`stylemotion.search.command`. A bad query, frame range, feature set,
``k``, dataset or an existing ``out`` ends in one line naming it.
"""

from __future__ import annotations

import logging

from omegaconf import DictConfig

from stylemotion.cli.skeleton import hydra_command

log = logging.getLogger(__name__)


def search(cfg: DictConfig, command: str) -> None:
    from stylemotion.search.command import search_from_config

    search_from_config(cfg, command=command)


main = hydra_command("stylemotion-search", "search", search, record_in="out")


if __name__ == "__main__":
    main()
