"""The one safe reader of NumPy ``.npz`` files a user hands a command (models, markers, motions).

:func:`load_npz` reads every array at once with ``allow_pickle=False``: a pickled (object) array is refused, never
loaded (unpickling can run code), and a damaged, truncated or wrong-kind file is one :class:`NpzFileError` naming
the file — never a ``BadZipFile``/``zlib.error`` traceback, never a hint to load it with ``allow_pickle``.
"""

from __future__ import annotations

import os
import stat
import zipfile
import zlib
from pathlib import Path

import numpy as np

from stylemotion.io.errors import UserInputError


class NpzFileError(UserInputError, ValueError):
    """An ``.npz`` file that cannot be read safely; ``detail`` is the message without the file's name."""

    def __init__(self, path: str | os.PathLike, detail: str):
        self.path = str(path)
        self.detail = detail
        super().__init__(f"{path}: {detail}")


def load_npz(path: str | os.PathLike, what: str = "NPZ file") -> dict[str, np.ndarray]:
    """Every array in the ``.npz`` file ``path`` (``what`` names it in messages), read without pickle.

    Raises:
        NpzFileError: missing, not a regular file, not an ``.npz`` archive, damaged or cut off, or holding pickled
            Python objects.
    """
    path = Path(path)
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):  # a FIFO would block
            raise NpzFileError(path, f"not a regular file; give the {what} itself")
    except OSError as exc:
        raise NpzFileError(path, f"cannot open this {what} ({exc.strerror or exc})") from None
    pickled = f"the {what} holds pickled Python objects, which are never loaded (they could run code); save plain " \
        "numeric arrays (numpy.savez)"
    damaged = (OSError, EOFError, KeyError, RuntimeError, zipfile.BadZipFile, zlib.error)
    try:
        data = np.load(path, allow_pickle=False)
    except ValueError:  # neither zip nor .npy: numpy takes any other bytes for a pickle
        if _starts_like_pickle(path):
            raise NpzFileError(path, pickled) from None
        raise NpzFileError(path, f"not a NumPy .npz archive (neither a zip nor NumPy data); give the {what} itself "
                                 "(numpy.savez writes one)") from None
    except damaged as exc:
        raise NpzFileError(path, f"damaged or cut off: not a readable {what} ({type(exc).__name__}: {exc})") from None
    if not isinstance(data, np.lib.npyio.NpzFile):  # a lone .npy array
        raise NpzFileError(path, f"a single .npy array, not an .npz archive; the {what} is an .npz")
    try:
        with data:
            return {name: np.asarray(data[name]) for name in data.files}
    except ValueError as exc:
        if "pickle" in str(exc) or "Object arrays" in str(exc):  # an object array inside
            raise NpzFileError(path, pickled) from None
        raise NpzFileError(path, f"damaged: not a readable {what} ({exc})") from None
    except damaged as exc:
        raise NpzFileError(path, f"damaged or cut off: not a readable {what} ({type(exc).__name__}: {exc})") from None

def _starts_like_pickle(path: Path) -> bool:
    """Whether the file begins with a pickle protocol mark (``0x80``): numpy calls every unknown file pickled."""
    try:
        with open(path, "rb") as fh:
            return fh.read(1) == b"\x80"
    except OSError:
        return False
