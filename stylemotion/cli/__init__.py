"""Console scripts: thin Hydra/argparse entry points. The work they start lives in the library
(:mod:`stylemotion.training`, :mod:`stylemotion.reproduction`, :mod:`stylemotion.evaluation.run`,
:mod:`stylemotion.segmentation_report`, :mod:`stylemotion.synthesis.generate`,
:mod:`stylemotion.datasets.convert`, :mod:`stylemotion.datasets.summary`), so notebooks can call it.

Every command explains itself (``--help``: Hydra help configs in ``stylemotion/configs/hydra/help/``),
reports what it did through :mod:`logging` (Hydra writes it to the console and to ``<job>.log`` in
its run folder), and turns a bad value, path or existing output into one line
``stylemotion-<command>: <message naming the key or file>`` and exit status 1 (:func:`reported`).
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def reported(command: str, *errors: type[BaseException]) -> Iterator[None]:
    """Run the block; one of ``errors`` (the user's input, not a bug) exits with ``<command>: <message>``."""
    try:
        yield
    except errors as exc:
        sys.exit(f"{command}: {exc}")
