"""The one JSON writer and reader of every output and record.

Policy (docs/architecture.md, "Outputs"): a number that is not finite (NaN, ±inf: a metric with no
value, e.g. foot skating of a walk without a planted foot) is written as ``null``, never as the
non-standard ``NaN``/``Infinity`` tokens, so every file parses in any JSON reader; numpy scalars and
arrays (and torch tensors) become plain numbers and lists, tuples and sets lists, paths strings. Anything else is a
``TypeError`` (a bug, never silently ``str()``-ed). Files are written atomically
(:func:`~stylemotion.io.atomic.atomic_write_bytes`), indented one space, with a final newline.
:func:`read_json` names the file (and where it is cut off) when it does not parse.
"""

from __future__ import annotations

import json
import math
import os
import stat
from collections.abc import Mapping
from pathlib import Path, PurePath
from typing import Any

import numpy as np

from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.errors import UserInputError


class JsonFileError(UserInputError, ValueError):
    """A JSON file that is missing, unreadable or not valid JSON; the message names the file."""


def plain(value: Any) -> Any:
    """``value`` with only JSON types: non-finite floats → None, numpy → Python, tuples/sets → lists.

    Raises:
        TypeError: a value of another type (naming it).
    """
    if isinstance(value, Mapping):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, (set, frozenset)):
        return [plain(v) for v in sorted(value, key=str)]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if value is None or isinstance(value, str):
        return value
    if isinstance(value, PurePath):
        return str(value)
    if callable(getattr(value, "tolist", None)):  # a torch tensor (the core does not import torch)
        return plain(value.tolist())
    raise TypeError(f"not JSON serializable: {type(value).__name__}")


def json_text(value: Any, indent: int | None = 1) -> str:
    """``value`` as JSON text under the module's policy, with a final newline."""
    return json.dumps(plain(value), indent=indent, allow_nan=False) + "\n"


def write_json(path: str | os.PathLike, value: Any, indent: int | None = 1) -> Path:
    """Write ``value`` to ``path`` atomically under the module's policy; returns the path."""
    path = Path(path)
    atomic_write_bytes(path, json_text(value, indent).encode())
    return path


def read_json(path: str | os.PathLike, what: str = "JSON file", remedy: str = "rerun the command that wrote it") -> Any:
    """The value in the JSON file ``path``; ``remedy`` ends the message of a damaged one.

    Raises:
        JsonFileError: the file is missing, not a regular file (a FIFO, a folder), unreadable, not UTF-8 or not
            valid JSON (e.g. cut off), naming ``what``, the file and the line and column where parsing stopped.
    """
    path = Path(path)
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):  # a FIFO or device would block or never end
            raise JsonFileError(f"{path}: not a regular file; give the {what} itself")
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise JsonFileError(f"{path}: no such {what}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise JsonFileError(f"{path}: cannot read this {what} ({exc})") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise JsonFileError(f"{path}:{exc.lineno}: not valid JSON at column {exc.colno} ({exc.msg}); the {what} is "
                            f"damaged or cut off — {remedy}") from None


def read_json_object(path: str | os.PathLike, what: str = "JSON file",
                     remedy: str = "rerun the command that wrote it") -> dict[str, Any]:
    """:func:`read_json` for a file that must hold an object (a record, a summary, a report).

    Raises:
        JsonFileError: as :func:`read_json`, or the file holds another JSON value (naming its type).
    """
    value = read_json(path, what, remedy)
    if not isinstance(value, dict):
        raise JsonFileError(f"{path}: the {what} holds a {type(value).__name__}, not an object; {remedy}")
    return value
