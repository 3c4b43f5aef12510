"""Errors and warnings that name where bad input was found."""

from __future__ import annotations


class MotionDataError(ValueError):
    """Bad motion data: names the file (and line, joint or key) and what was expected."""

    def __init__(self, source: str, message: str, line: int | None = None):
        self.source = source
        self.line = line
        self.detail = message
        where = f"{source}:{line}" if line is not None else source
        super().__init__(f"{where}: {message}")


class BvhError(MotionDataError):
    """A malformed BVH file."""


class LimitError(MotionDataError):
    """An input exceeds a configured size limit (the message names the key and its value)."""


class MotionDataWarning(UserWarning):
    """Input that loads but is probably wrong (axes, units of time); the message names the file."""
