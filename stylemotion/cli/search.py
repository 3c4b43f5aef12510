"""``stylemotion-search``: the database segments most similar to a query motion (Krüger ch. 2).

    stylemotion-search query=synthetic_walk_normal_000:30-90 out=runs/search/walk
    stylemotion-search data=bandai query=my_walk.bvh:120-480 features=E15 top=10 out=runs/search/mine

The work and the folder it writes: :mod:`stylemotion.search.command`. A bad query, frame range, feature set,
``k``, dataset or an existing ``out`` ends in one line naming it.
"""

from __future__ import annotations

import logging
import sys

import hydra
from omegaconf import DictConfig

from stylemotion.cli import reported
from stylemotion.config import CONFIG_PACKAGE, ConfigError
from stylemotion.io.outputs import OutputExistsError
from stylemotion.search.command import SearchInputError, search_from_config

log = logging.getLogger(__name__)


def _main(cfg: DictConfig) -> None:
    with reported("stylemotion-search", ConfigError, OutputExistsError, SearchInputError):
        search_from_config(cfg, say=log.info, command="stylemotion-search " + " ".join(sys.argv[1:]))


def main() -> None:
    """Console script ``stylemotion-search``."""
    hydra.main(config_path=CONFIG_PACKAGE, config_name="search", version_base="1.3")(_main)()


if __name__ == "__main__":
    main()
