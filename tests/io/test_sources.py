"""File sources: sizes checked before reading or inflating, fingerprints that follow the content."""

from __future__ import annotations

import os
import zipfile
from pathlib import Path

import pytest

from stylemotion.io import sources
from stylemotion.io.errors import LimitError, MotionDataError
from stylemotion.io.sources import FileSource, list_sources


def _bomb(path: Path, megabytes: int) -> Path:
    """A zip whose one member inflates from a few KB to ``megabytes`` MB of zeros."""
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("big.bvh", bytes(megabytes * 1_000_000))
    return path


def test_zip_member_size_is_checked_before_inflating(tmp_path, monkeypatch):
    archive = _bomb(tmp_path / "bomb.zip", 3)
    assert archive.stat().st_size < 30_000
    source = list_sources(archive)[0]

    def no_inflating(*args, **kwargs):
        raise AssertionError("the member was inflated before its size was checked")

    monkeypatch.setattr(zipfile.ZipFile, "read", no_inflating)
    monkeypatch.setattr(zipfile.ZipFile, "open", no_inflating)
    with pytest.raises(LimitError) as err:
        source.read_bytes(max_file_mb=1)
    message = str(err.value)
    assert message.startswith(f"{archive}::big.bvh: ") and "3.0 MB" in message and "data.max_file_mb=1" in message
    monkeypatch.undo()
    assert len(source.read_bytes(max_file_mb=4)) == 3_000_000


def test_loose_file_size_limit(tmp_path):
    path = tmp_path / "big.bvh"
    path.write_bytes(bytes(2_000_001))
    with pytest.raises(LimitError, match=r"data\.max_file_mb=2\b"):
        FileSource(str(path)).read_bytes(max_file_mb=2)
    # An over-limit file is not hashed: its fingerprint is its size.
    assert FileSource(str(path)).fingerprint(max_file_mb=2) == "2000001:over-limit"


def test_fingerprint_follows_content_not_size_and_mtime(tmp_path):
    path = tmp_path / "a.bvh"
    path.write_bytes(b"HIERARCHY one")
    stat = path.stat()
    before = FileSource(str(path)).fingerprint()
    path.write_bytes(b"HIERARCHY two")  # same size
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))  # same mtime
    assert path.stat().st_size == stat.st_size and path.stat().st_mtime_ns == stat.st_mtime_ns
    after = FileSource(str(path)).fingerprint()
    assert after != before
    sources._DIGESTS.clear()  # a fresh process computes the same digest
    assert FileSource(str(path)).fingerprint() == after


def test_zip_fingerprint_is_the_central_directory_crc(tmp_path):
    archive = tmp_path / "a.zip"
    with zipfile.ZipFile(archive, "w") as zf:
        zf.writestr("m.bvh", b"one")
    first = FileSource(str(archive), "m.bvh").fingerprint()
    with zipfile.ZipFile(archive, "r") as zf:
        assert first == f"{zf.getinfo('m.bvh').CRC:08x}:3"
    # Rewritten in the same process (same size): the open archive is not reused stale.
    with zipfile.ZipFile(archive, "w") as zf:
        zf.writestr("m.bvh", b"two")
    second = FileSource(str(archive), "m.bvh").fingerprint()
    assert second != first
    assert FileSource(str(archive), "m.bvh").read_bytes() == b"two"


def test_read_head_stops_after_the_marker_and_at_the_bound(tmp_path, monkeypatch):
    text = b"HIERARCHY\n" + b"x" * 300 + b"\nMOTION\n" + b"1 2 3\n" * 10_000
    (tmp_path / "a.bvh").write_bytes(text)
    with zipfile.ZipFile(tmp_path / "d.zip", "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("m/a.bvh", text)
    for source in (FileSource(str(tmp_path / "a.bvh")), FileSource(str(tmp_path / "d.zip"), "m/a.bvh")):
        head = source.read_head(1_000_000, stop=b"MOTION", chunk=64)
        assert b"MOTION" in head and text.startswith(head) and len(head) <= text.index(b"MOTION") + 6 + 64
        assert source.read_head(100) == text[:100]
        assert source.read_head(10 ** 9) == text  # a shorter file: all of it
        assert FileSource.from_name(source.name) == source
    with pytest.raises(MotionDataError, match="no such member"):
        FileSource(str(tmp_path / "d.zip"), "gone.bvh").read_head(10)
    with pytest.raises(MotionDataError, match="gone.bvh"):
        FileSource(str(tmp_path / "gone.bvh")).read_head(10)
