"""The atomicity promise of :mod:`stylemotion.io.atomic`: a file or folder appears complete or not at all.

A crash is simulated at each step (inside the writer's block, in the write itself, at ``os.replace``, at the
folder swap): the old file or folder must be intact afterwards and no temporary file or folder left beside it.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from stylemotion.io import atomic
from stylemotion.io.atomic import atomic_folder, atomic_write_bytes


class Crash(Exception):
    """The simulated crash."""


def leftovers(folder: Path, keep: set[str]) -> list[str]:
    """Names in ``folder`` other than ``keep`` (temporary files and folders the writers would leave)."""
    return sorted(p.name for p in folder.iterdir() if p.name not in keep)


def test_a_write_creates_parents_and_a_normally_readable_file(tmp_path: Path) -> None:
    path = tmp_path / "a" / "b" / "out.json"
    atomic_write_bytes(path, b'{"x": 1}')
    assert path.read_bytes() == b'{"x": 1}'
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~umask  # not mkstemp's private 0o600
    assert leftovers(path.parent, {"out.json"}) == []


def test_a_write_replaces_an_existing_file_whole(tmp_path: Path) -> None:
    path = tmp_path / "out.txt"
    path.write_bytes(b"old content, longer than the new one")
    atomic_write_bytes(path, b"new")
    assert path.read_bytes() == b"new"
    assert leftovers(tmp_path, {"out.txt"}) == []


def test_a_crash_at_the_rename_keeps_the_old_file_and_leaves_no_partial_file(tmp_path: Path, monkeypatch) -> None:
    path = tmp_path / "out.txt"
    path.write_bytes(b"old")

    def crash(src, dst):
        assert Path(src).read_bytes() == b"new data", "the temporary file is complete before the rename"
        raise Crash("power cut at os.replace")

    monkeypatch.setattr(atomic.os, "replace", crash)
    with pytest.raises(Crash):
        atomic_write_bytes(path, b"new data")
    assert path.read_bytes() == b"old"
    assert leftovers(tmp_path, {"out.txt"}) == []


def test_a_crash_while_writing_keeps_the_old_file_and_leaves_no_partial_file(tmp_path: Path) -> None:
    path = tmp_path / "out.txt"
    path.write_bytes(b"old")
    with pytest.raises(TypeError):
        atomic_write_bytes(path, "text, not bytes")  # fails inside the write, after the temporary file exists
    assert path.read_bytes() == b"old"
    assert leftovers(tmp_path, {"out.txt"}) == []


def test_a_crash_before_any_file_existed_leaves_nothing(tmp_path: Path, monkeypatch) -> None:
    def crash(src, dst):
        raise Crash("killed")

    monkeypatch.setattr(atomic.os, "replace", crash)
    with pytest.raises(Crash):
        atomic_write_bytes(tmp_path / "new.txt", b"data")
    assert leftovers(tmp_path, set()) == []


def test_a_folder_appears_whole_with_normal_permissions(tmp_path: Path) -> None:
    out = tmp_path / "result"
    with atomic_folder(out) as tmp:
        assert tmp != out and tmp.parent == tmp_path and not out.exists()  # built beside, invisible meanwhile
        (tmp / "a.txt").write_text("a")
        (tmp / "sub").mkdir()
        (tmp / "sub" / "b.txt").write_text("b")
    assert (out / "a.txt").read_text() == "a" and (out / "sub" / "b.txt").read_text() == "b"
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(out.stat().st_mode) == 0o777 & ~umask  # not mkdtemp's private 0o700
    assert leftovers(tmp_path, {"result"}) == []


def _old_folder(out: Path) -> None:
    out.mkdir()
    (out / "old.txt").write_text("old result")


@pytest.mark.parametrize("existing", [False, True])
def test_a_crash_inside_the_block_keeps_the_old_folder_and_removes_the_partial_one(tmp_path: Path,
                                                                                  existing: bool) -> None:
    out = tmp_path / "result"
    if existing:
        _old_folder(out)
    with pytest.raises(Crash), atomic_folder(out) as tmp:
        (tmp / "half.txt").write_text("half written")
        raise Crash("killed mid-way")
    if existing:
        assert sorted(p.name for p in out.iterdir()) == ["old.txt"] and (out / "old.txt").read_text() == "old result"
    else:
        assert not out.exists()
    assert leftovers(tmp_path, {"result"}) == []


def test_a_refusal_at_swap_time_keeps_the_old_folder(tmp_path: Path) -> None:
    out = tmp_path / "result"
    _old_folder(out)
    calls = []

    def refuse() -> None:
        calls.append(sorted(p.name for p in out.iterdir()))
        raise FileExistsError(f"{out} already exists")

    with pytest.raises(FileExistsError), atomic_folder(out, on_exists=refuse) as tmp:
        (tmp / "new.txt").write_text("new result")
    assert calls == [["old.txt"]]  # asked once, after the work, with the old folder still in place
    assert (out / "old.txt").read_text() == "old result" and not (out / "new.txt").exists()
    assert leftovers(tmp_path, {"result"}) == []


def test_an_accepted_existing_folder_is_replaced_whole(tmp_path: Path) -> None:
    out = tmp_path / "result"
    _old_folder(out)
    with atomic_folder(out, on_exists=lambda: None) as tmp:
        (tmp / "new.txt").write_text("new result")
    assert sorted(p.name for p in out.iterdir()) == ["new.txt"]  # nothing of the old folder mixed in
    assert leftovers(tmp_path, {"result"}) == []


def test_a_crash_during_the_swap_keeps_the_old_folder(tmp_path: Path, monkeypatch) -> None:
    """The swap moves the old folder aside, then the new one in: a crash at the second rename must put the
    old folder back, not leave ``out`` missing."""
    out = tmp_path / "result"
    _old_folder(out)
    real_replace = Path.replace

    def replace(self: Path, target):
        if self.name.startswith(".result.") and Path(target) == out:  # the new folder moving in
            raise Crash("killed during the swap")
        return real_replace(self, target)

    monkeypatch.setattr(Path, "replace", replace)
    with pytest.raises(Crash), atomic_folder(out) as tmp:
        (tmp / "new.txt").write_text("new result")
    monkeypatch.undo()
    assert sorted(p.name for p in out.iterdir()) == ["old.txt"] and (out / "old.txt").read_text() == "old result"
    assert leftovers(tmp_path, {"result"}) == []
