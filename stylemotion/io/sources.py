"""Where motion files come from: a file, a folder (recursive), or members of a ``.zip``.

Zip members are read straight from the archive, never unpacked to disk. Each source has a cheap
fingerprint (zip CRC-32 and size; file size and modification time) used to key caches.
"""

from __future__ import annotations

import fnmatch
import os
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from stylemotion.io.errors import MotionDataError

_OPEN_ZIPS: dict[tuple[str, int], zipfile.ZipFile] = {}


def _zip(path: str) -> zipfile.ZipFile:
    """An open ZipFile per archive and process (reading the central directory once).

    Keyed by process id too: a forked worker must not share its parent's file position.
    """
    key = (path, os.getpid())
    archive = _OPEN_ZIPS.get(key)
    if archive is None:
        try:
            archive = zipfile.ZipFile(path)
        except (OSError, zipfile.BadZipFile) as exc:
            raise MotionDataError(path, f"cannot open zip archive ({exc})") from None
        _OPEN_ZIPS[key] = archive
    return archive


@dataclass(frozen=True)
class FileSource:
    """A file on disk (``member is None``) or a member of the zip archive at ``path``."""

    path: str
    member: str | None = None

    @property
    def name(self) -> str:
        """What error messages call it: the path, or ``archive.zip::member``."""
        return self.path if self.member is None else f"{self.path}::{self.member}"

    @property
    def stem(self) -> str:
        return PurePosixPath(self.member).stem if self.member is not None else Path(self.path).stem

    def read_bytes(self) -> bytes:
        if self.member is None:
            try:
                return Path(self.path).read_bytes()
            except OSError as exc:
                raise MotionDataError(self.name, f"cannot read file ({exc.strerror or exc})") from None
        try:
            return _zip(self.path).read(self.member)
        except KeyError:
            raise MotionDataError(self.name, "no such member in the archive") from None
        except (OSError, zipfile.BadZipFile, zlib.error, EOFError, RuntimeError, ValueError) as exc:
            raise MotionDataError(self.name, f"cannot read zip member ({exc})") from None

    def fingerprint(self) -> str:
        """Changes whenever the content does (CRC-32+size in a zip; size+mtime on disk)."""
        if self.member is None:
            st = os.stat(self.path)
            return f"{st.st_size}:{st.st_mtime_ns}"
        info = _zip(self.path).getinfo(self.member)
        return f"{info.CRC:08x}:{info.file_size}"

    def sibling(self, suffix: str) -> FileSource:
        """The source with the same stem and another suffix (e.g. the ``.json`` label file)."""
        if self.member is None:
            return FileSource(str(Path(self.path).with_suffix(suffix)))
        return FileSource(self.path, str(PurePosixPath(self.member).with_suffix(suffix)))

    def exists(self) -> bool:
        if self.member is None:
            return Path(self.path).is_file()
        try:
            _zip(self.path).getinfo(self.member)
            return True
        except KeyError:
            return False


def list_sources(root: str | os.PathLike, pattern: str = "*.bvh") -> list[FileSource]:
    """All files matching ``pattern`` under ``root`` (a file, a folder or a ``.zip``), sorted.

    Raises:
        MotionDataError: if ``root`` does not exist or holds no matching file.
    """
    root = Path(root)
    if not root.exists():
        raise MotionDataError(str(root), "no such file or folder")
    if root.is_file() and root.suffix.lower() == ".zip":
        members = sorted(m for m in _zip(str(root)).namelist()
                         if not m.endswith("/") and fnmatch.fnmatch(PurePosixPath(m).name, pattern))
        sources = [FileSource(str(root), m) for m in members]
    elif root.is_file():
        sources = [FileSource(str(root))]
    else:
        sources = [FileSource(str(p)) for p in sorted(root.rglob(pattern)) if p.is_file()]
    if not sources:
        raise MotionDataError(str(root), f"no files matching {pattern!r}")
    return sources
