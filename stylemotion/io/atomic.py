"""Atomic writes: a file or a whole folder appears complete or not at all."""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from stylemotion.io.errors import OutputWriteError


def _make_parent(path: Path) -> None:
    """Create ``path``'s folder; :class:`OutputWriteError` naming it when it cannot be (read-only, a file)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputWriteError(f"cannot write {path}: its folder {path.parent} cannot be created "
                               f"({exc.strerror or exc}); choose another output") from None


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` via a temporary file in the same folder and ``os.replace`` (with the
    permissions of a normally created file: mkstemp's are private)."""
    _make_parent(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise OutputWriteError(f"cannot write {path} ({exc.strerror or exc}); choose another output") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


@contextmanager
def atomic_folder(out: Path, on_exists: Callable[[], None] | None = None) -> Iterator[Path]:
    """Build a folder in a temporary sibling and swap it into ``out`` when the block succeeds.

    Yields the temporary folder (with the permissions of a normal ``mkdir``). On an exception the
    temporary folder is removed and ``out`` is untouched. If ``out`` exists at swap time,
    ``on_exists`` is called first (it may raise to refuse) and the old folder is then replaced.
    """
    _make_parent(out)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.", dir=out.parent))
    except OSError as exc:
        raise OutputWriteError(f"cannot write {out}: no folder can be made in {out.parent} "
                               f"({exc.strerror or exc}); choose another output") from None
    os.chmod(tmp, 0o777 & ~_umask())  # mkdtemp makes it private; a result folder is not
    try:
        yield tmp
        if out.exists():
            if on_exists is not None:
                on_exists()
            trash = Path(tempfile.mkdtemp(prefix=f".{out.name}.old.", dir=out.parent))
            out.replace(trash / out.name)
            try:
                tmp.replace(out)
            except BaseException:  # the new folder did not move in: put the old one back
                (trash / out.name).replace(out)
                trash.rmdir()
                raise
            shutil.rmtree(trash, ignore_errors=True)
        else:
            tmp.replace(out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
