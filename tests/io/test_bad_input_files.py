"""Readers of a user's file refuse what is not a regular file by name instead of blocking on it (issue 26): a FIFO
given to ``stylemotion-convert`` or a JSON reader, and a FIFO or self-looping link among a folder's ``*.bvh``
files, which the data set lists as broken (or skipped) instead of dropping it."""

from __future__ import annotations

import os
import signal

import pytest

from stylemotion.cli.convert import main as convert_main
from stylemotion.datasets.bvh_folder import load_bvh_folder
from stylemotion.datasets.loading import DatasetBuildError
from stylemotion.io.bvh import read_bvh
from stylemotion.io.errors import MotionDataError
from stylemotion.io.jsonfile import JsonFileError, read_json
from stylemotion.io.sources import FileSource, list_sources


@pytest.fixture(autouse=True)
def _no_hang():
    """A reader that blocks on a FIFO fails the test instead of hanging the run."""
    def stop(*_):
        raise TimeoutError("blocked on a non-regular file")

    old = signal.signal(signal.SIGALRM, stop)
    signal.alarm(60)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, old)


@pytest.fixture
def fifo(tmp_path):
    path = tmp_path / "pipe.bvh"
    os.mkfifo(path)
    return path


def test_convert_refuses_a_fifo_by_name_instead_of_waiting(fifo, tmp_path, capsys):
    assert convert_main([str(fifo), str(tmp_path / "out.npz")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.splitlines() == [err] and err.startswith(f"stylemotion-convert: {fifo}: a FIFO (named pipe)")
    assert not (tmp_path / "out.npz").exists()


def test_readers_refuse_non_regular_files(fifo, tmp_path):
    with pytest.raises(MotionDataError, match=f"{fifo}: a FIFO"):
        read_bvh(fifo)
    with pytest.raises(MotionDataError, match=f"{fifo}: a FIFO"):
        FileSource(str(fifo)).read_bytes()
    with pytest.raises(MotionDataError, match=f"{fifo}: a FIFO"):
        list_sources(fifo)
    json_fifo = tmp_path / "done.json"
    os.mkfifo(json_fifo)
    with pytest.raises(JsonFileError, match=f"{json_fifo}: not a regular file"):
        read_json(json_fifo, "stage record")


def test_a_fifo_and_a_looping_link_in_a_folder_are_listed_and_refused_by_name(fifo, tmp_path):
    loop = tmp_path / "loop.bvh"
    loop.symlink_to(loop)
    (tmp_path / "sub").mkdir()
    names = [s.path for s in list_sources(tmp_path)]
    assert names == [str(loop), str(fifo)]  # listed, not dropped (the folder sub/ is not)
    with pytest.raises(MotionDataError, match=f"{loop}: a link that cannot be followed"):
        FileSource(str(loop)).read_bytes()


def test_the_data_set_names_the_fifo_and_the_loop_among_its_broken_files(fifo, tmp_path):
    (tmp_path / "loop.bvh").symlink_to(tmp_path / "loop.bvh")
    with pytest.raises(DatasetBuildError) as refused:
        load_bvh_folder(tmp_path, cache_dir=tmp_path / "cache", use_cache=False)
    assert f"{fifo}: a FIFO" in str(refused.value) and f"{tmp_path / 'loop.bvh'}: a link that cannot" in str(
        refused.value)
    skipped = load_bvh_folder(tmp_path, skip_broken=True, cache_dir=tmp_path / "cache", use_cache=False).skipped
    assert [name for name, _ in skipped] == [str(tmp_path / "loop.bvh"), str(fifo)]


def test_convert_refuses_an_existing_or_linked_dst_unless_forced(tmp_path, capsys, tiny_bvh):
    src = tmp_path / "walk.bvh"
    src.write_text(tiny_bvh)
    mine = tmp_path / "mine.npz"
    mine.write_bytes(b"my own file")
    (tmp_path / "linked.npz").symlink_to(mine)
    for dst, message in [(mine, "already exists; give another DST or pass --force"), (tmp_path / "linked.npz",
                                                                                      "is a link; nothing is written")]:
        assert convert_main([str(src), str(dst), "--joint-map", "bandai"]) == 2
        (line,) = capsys.readouterr().err.strip().splitlines()
        assert line.startswith(f"stylemotion-convert: {dst} ") and message in line, line
    assert mine.read_bytes() == b"my own file" and (tmp_path / "linked.npz").is_symlink()
