"""Output folders: never over a finished result, never outside the folder.

Every command writes into one output folder. :func:`check_new_output` refuses an existing folder
unless the user forces it; :func:`safe_name` turns a label that came from data (a take name from a
zip member path, a style from a user's CSV) into a single, harmless file-name component; and
:func:`inside` checks that a path built from such names stays inside its folder.
"""

from __future__ import annotations

import os
import re
import unicodedata
from pathlib import Path

from stylemotion.io.errors import OutputWriteError, UserInputError


class OutputExistsError(UserInputError, FileExistsError):
    """An output (folder or file) exists and the command was not told to replace it."""


class UnsafePathError(UserInputError, ValueError):
    """A path built from data would leave its output folder."""


#: Characters kept in a file-name component; everything else becomes ``_``.
_UNSAFE = re.compile(r"[^A-Za-z0-9._+\-]+")
#: Longest file-name component written (bytes on common file systems are 255).
MAX_NAME_LENGTH = 120


def check_new_output(path: str | os.PathLike, force: bool = False, key: str = "out") -> Path:
    """``path`` as a Path; :class:`OutputExistsError` naming ``key`` if it exists and ``force`` is off,
    :class:`~stylemotion.io.errors.OutputWriteError` if it could not be made: the nearest existing folder above it
    is read-only (or a file).

    A link (to a folder, a file or nowhere) is refused with :class:`UnsafePathError`, with or without ``force``:
    nothing is written through a link or over it.

    Call it before any work, and again when the result is swapped into place.
    """
    path = Path(path).expanduser()
    if path.is_symlink():
        raise UnsafePathError(f"{key}={path}: {path} is a link to {Path(os.readlink(path))}; nothing is written "
                              f"through a link or over it: choose another {key}")
    if path.exists() and not force:
        hint = f"another {key} or pass --force" if key.startswith("--") else f"another {key}=… or pass force=true"
        raise OutputExistsError(f"{path} already exists; choose {hint} to replace it")
    ancestor = path.absolute().parent
    while not ancestor.exists() and ancestor != ancestor.parent:
        ancestor = ancestor.parent
    if not ancestor.is_dir() or not os.access(ancestor, os.W_OK | os.X_OK):
        raise OutputWriteError(f"{key}={path}: {ancestor} is " + ("not a folder" if not ancestor.is_dir() else
                               "read-only") + f"; choose another {key}=…")
    return path


def safe_name(label: str, what: str = "name") -> str:
    """``label`` as one file-name component: no separators, no ``..``, no leading dot, printable ASCII.

    Letters, digits and ``._+-`` are kept; runs of anything else (``/``, ``\\``, spaces, control
    characters, non-ASCII after NFKD folding) become one ``_``. Long names are cut to
    :data:`MAX_NAME_LENGTH` characters.

    Raises:
        ValueError: nothing usable is left (naming ``what``).
    """
    folded = unicodedata.normalize("NFKD", str(label)).encode("ascii", "ignore").decode()
    name = _UNSAFE.sub("_", folded).strip("._")
    name = name[:MAX_NAME_LENGTH]
    if not name or set(name) <= {".", "_"}:
        raise ValueError(f"{what} {label!r} has no character usable in a file name")
    return name


def inside(root: str | os.PathLike, *parts: str | os.PathLike) -> Path:
    """``root / parts…``, refused if it resolves outside ``root`` (``..``, absolute parts, links).

    Raises:
        UnsafePathError: naming the path and the folder.
    """
    root_path = Path(root).resolve()
    path = root_path.joinpath(*parts)
    resolved = path.resolve()
    if resolved != root_path and root_path not in resolved.parents:
        raise UnsafePathError(f"output path {path} would be written outside its folder {root_path}")
    return path
