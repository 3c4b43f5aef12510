"""Errors and warnings that name where bad input was found.

:class:`UserInputError` is the one base of every error that bad input (a value, a file, a folder, a
checkpoint) causes, as opposed to a bug: every command turns it into one line naming the file, line,
key or value, and exit status 2 (:mod:`stylemotion.cli.skeleton`). Each module's own error class
derives from it (and from the builtin it replaces, e.g. ``ValueError``, so older ``except`` clauses
still catch it).
"""

from __future__ import annotations


class UserInputError(Exception):
    """Input the user gave that cannot be used; the message names the file, line, key or value."""


class MotionDataError(UserInputError, ValueError):
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


class OutputWriteError(UserInputError, OSError):
    """An output that cannot be written where the user asked (a read-only or missing folder); names the path."""


class MotionDataWarning(UserWarning):
    """Input that loads but is probably wrong (axes, units of time); the message names the file."""
