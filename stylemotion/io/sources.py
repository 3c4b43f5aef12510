"""Where motion files come from: a file, a folder (recursive), or members of a ``.zip``.

Zip members are read straight from the archive, never unpacked to disk. Each source has a
fingerprint of its content used to key caches: a zip member's CRC-32 and size from the central
directory (no decompression), a file's SHA-256 (memoized within one process while its size,
times and inode stay the same). Sizes are checked before anything is read or inflated.
"""

from __future__ import annotations

import fnmatch
import hashlib
import os
import stat
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import IO

from stylemotion.io.errors import LimitError, MotionDataError

#: (path, pid) → (archive's (size, mtime_ns, ctime_ns, inode, device), open ZipFile).
_OPEN_ZIPS: dict[tuple[str, int], tuple[tuple[int, ...], zipfile.ZipFile]] = {}
#: path → ((size, mtime_ns, ctime_ns, inode, device), hex digest) of files hashed in this process.
_DIGESTS: dict[str, tuple[tuple[int, ...], str]] = {}
_HASH_CHUNK = 1 << 20


def check_file_size(num_bytes: int, max_file_mb: float | None, source: str) -> None:
    """Raise :class:`LimitError` naming ``data.max_file_mb`` if ``num_bytes`` exceeds it (None: no limit)."""
    if max_file_mb is not None and num_bytes > max_file_mb * 1e6:
        raise LimitError(source, f"file is {num_bytes / 1e6:.1f} MB (uncompressed), more than the limit "
                         f"data.max_file_mb={max_file_mb:g} (raise it for larger files)")


def regular_file_stat(path: str | os.PathLike, source: str | None = None) -> os.stat_result:
    """``os.stat`` of ``path`` (links followed) if it is a regular file.

    A FIFO, socket or device would block a reader or never end, a folder is no file: each is refused by name
    before it is opened.

    Raises:
        MotionDataError: no such file, a link that loops or leads nowhere, or not a regular file (naming
            ``source``, default the path, and what it is).
    """
    name = str(source if source is not None else path)
    try:
        st = os.stat(path)
    except OSError as exc:
        if os.path.islink(path):
            raise MotionDataError(name, f"a link that cannot be followed ({exc.strerror or exc}); give the file "
                                  "itself") from None
        raise MotionDataError(name, f"cannot read file ({exc.strerror or exc})") from None
    if not stat.S_ISREG(st.st_mode):
        kind = ("a folder" if stat.S_ISDIR(st.st_mode) else "a FIFO (named pipe)" if stat.S_ISFIFO(st.st_mode)
                else "a socket" if stat.S_ISSOCK(st.st_mode) else "a device" if stat.S_ISCHR(st.st_mode)
                or stat.S_ISBLK(st.st_mode) else "not a regular file")
        raise MotionDataError(name, f"{kind}, not a regular file: give a file (a pipe or device would never end)")
    return st


def _stamp(path: str) -> tuple[int, ...]:
    """What changes when a file is written or replaced: size, mtime, ctime, inode, device."""
    st = os.stat(path)
    return (st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino, st.st_dev)


def _file_digest(path: str, stamp: tuple[int, ...]) -> str:
    """SHA-256 of a file's bytes, memoized while its :func:`_stamp` is ``stamp``.

    ctime is in the stamp because it changes on every write, even one that restores the mtime.
    """
    memo = _DIGESTS.get(path)
    if memo is not None and memo[0] == stamp:
        return memo[1]
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(_HASH_CHUNK):
            digest.update(chunk)
    _DIGESTS[path] = (stamp, digest.hexdigest())
    return _DIGESTS[path][1]


def _zip(path: str, fresh: bool = False) -> zipfile.ZipFile:
    """An open ZipFile per archive and process (reading the central directory once).

    Keyed by process id too: a forked worker must not share its parent's file position. With
    ``fresh`` (listing members, fingerprints) the archive is reopened if it changed on disk since,
    so its CRCs (the cache key) are never stale.
    """
    key = (path, os.getpid())
    cached = _OPEN_ZIPS.get(key)
    if cached is not None and not fresh:
        return cached[1]
    regular_file_stat(path)
    try:
        stamp = _stamp(path)
    except OSError as exc:
        raise MotionDataError(path, f"cannot open zip archive ({exc.strerror or exc})") from None
    if cached is not None and cached[0] == stamp:
        return cached[1]
    try:
        archive = zipfile.ZipFile(path)
    except (OSError, zipfile.BadZipFile, ValueError) as exc:
        raise MotionDataError(path, f"cannot open zip archive ({exc})") from None
    if cached is not None:
        cached[1].close()
    _OPEN_ZIPS[key] = (stamp, archive)
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

    def size(self) -> int:
        """Size in bytes (uncompressed, from the zip's central directory for a member).

        Raises:
            MotionDataError: a missing file, a looping link, or no regular file (a FIFO, a device: refused
                before it is opened, :func:`regular_file_stat`), naming it.
        """
        if self.member is None:
            return regular_file_stat(self.path, self.name).st_size
        try:
            return _zip(self.path).getinfo(self.member).file_size
        except KeyError:
            raise MotionDataError(self.name, "no such member in the archive") from None

    def read_bytes(self, max_file_mb: float | None = None) -> bytes:
        """The content; :class:`LimitError` before reading if it is larger than ``max_file_mb``."""
        size = self.size()
        check_file_size(size, max_file_mb, self.name)
        if self.member is None:
            cap = None if max_file_mb is None else int(max_file_mb * 1e6) + 1
            try:
                with open(self.path, "rb") as fh:
                    data = fh.read(size + 1 if cap is None else min(size + 1, cap))
                    if len(data) > size:  # grew since: read on, bounded
                        data += fh.read() if cap is None else fh.read(cap - len(data))
            except OSError as exc:
                raise MotionDataError(self.name, f"cannot read file ({exc.strerror or exc})") from None
            check_file_size(len(data), max_file_mb, self.name)
            return data
        try:
            return _zip(self.path).read(self.member)
        except KeyError:
            raise MotionDataError(self.name, "no such member in the archive") from None
        except (OSError, zipfile.BadZipFile, zlib.error, EOFError, RuntimeError, ValueError) as exc:
            raise MotionDataError(self.name, f"cannot read zip member ({exc})") from None

    def read_head(self, max_bytes: int, stop: bytes | None = None, chunk: int = 1 << 16) -> bytes:
        """The file's first bytes: up to ``max_bytes`` (all of a shorter file), or fewer once ``stop`` has been read
        (read ``chunk`` bytes at a time), e.g. a BVH file's hierarchy without its frames."""
        def read(fh: IO[bytes]) -> bytes:
            data = b""
            while len(data) < max_bytes:
                part = fh.read(min(chunk, max_bytes - len(data)))
                data += part
                if not part or (stop is not None and stop in data[-len(part) - len(stop):]):
                    break
            return data

        if self.member is None:
            regular_file_stat(self.path, self.name)
            try:
                with open(self.path, "rb") as fh:
                    return read(fh)
            except OSError as exc:
                raise MotionDataError(self.name, f"cannot read file ({exc.strerror or exc})") from None
        try:
            with _zip(self.path).open(self.member) as fh:
                return read(fh)
        except KeyError:
            raise MotionDataError(self.name, "no such member in the archive") from None
        except (OSError, zipfile.BadZipFile, zlib.error, EOFError, RuntimeError, ValueError) as exc:
            raise MotionDataError(self.name, f"cannot read zip member ({exc})") from None

    @classmethod
    def from_name(cls, name: str) -> FileSource:
        """The source a :attr:`name` names: ``archive.zip::member`` or a path."""
        path, sep, member = name.partition("::")
        return cls(path, member) if sep else cls(name)

    def fingerprint(self, max_file_mb: float | None = None) -> str:
        """Changes whenever the content does: CRC-32 and size of a zip member, SHA-256 of a file.

        A file larger than ``max_file_mb`` is not hashed (it is refused by size, whatever it holds).
        """
        if self.member is not None:
            try:
                info = _zip(self.path, fresh=True).getinfo(self.member)
            except KeyError:
                raise MotionDataError(self.name, "no such member in the archive") from None
            return f"{info.CRC:08x}:{info.file_size}"
        try:
            regular_file_stat(self.path, self.name)
            stamp = _stamp(self.path)
            if max_file_mb is not None and stamp[0] > max_file_mb * 1e6:
                return f"{stamp[0]}:over-limit"
            return f"sha256:{_file_digest(self.path, stamp)}"
        except OSError as exc:
            raise MotionDataError(self.name, f"cannot read file ({exc.strerror or exc})") from None

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

    In a folder, every entry matching ``pattern`` that is not a folder is listed, a FIFO or a looping link
    included: reading it then fails by name (:func:`regular_file_stat`), so the data set lists it as broken or
    skipped instead of dropping it silently.

    Raises:
        MotionDataError: if ``root`` does not exist or holds no matching file.
    """
    root = Path(root)
    if not root.exists():
        raise MotionDataError(str(root), "no such file or folder")
    if not root.is_dir():
        regular_file_stat(root)
    if root.is_file() and root.suffix.lower() == ".zip":
        members = sorted(m for m in _zip(str(root), fresh=True).namelist()
                         if not m.endswith("/") and fnmatch.fnmatch(PurePosixPath(m).name, pattern))
        sources = [FileSource(str(root), m) for m in members]
    elif root.is_file():
        sources = [FileSource(str(root))]
    else:
        sources = [FileSource(str(p)) for p in sorted(root.rglob(pattern)) if not p.is_dir()]
    if not sources:
        raise MotionDataError(str(root), f"no files matching {pattern!r}")
    return sources
