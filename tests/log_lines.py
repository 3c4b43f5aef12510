"""What the library logs, as lines: the library reports progress only through :mod:`logging` (no callbacks)."""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def logged_lines(logger: str = "stylemotion", level: int = logging.INFO) -> Iterator[list[str]]:
    """The messages ``logger`` and the loggers below it log at ``level`` or above while the block runs, in order
    (the logger's level is lowered to ``level`` for the block if needed, and restored)."""
    lines: list[str] = []

    class Collect(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            lines.append(record.getMessage())

    target, handler = logging.getLogger(logger), Collect(level)
    before = target.level
    target.addHandler(handler)
    if target.getEffectiveLevel() > level:
        target.setLevel(level)
    try:
        yield lines
    finally:
        target.removeHandler(handler)
        target.setLevel(before)
