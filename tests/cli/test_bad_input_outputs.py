"""Output folders that cannot be written and report values read the wrong way (issue 26): ``stylemotion-segment``
and ``stylemotion-search`` with an ``out`` below a file or a read-only folder, ``timeline=bogus`` and
``plot_takes=-3`` end in one line naming the key or folder, exit status 2, nothing written."""

from __future__ import annotations

import os

import pytest
from cli_runner import run_command

from stylemotion.io.atomic import atomic_folder, atomic_write_bytes
from stylemotion.io.errors import OutputWriteError
from stylemotion.io.outputs import check_new_output


@pytest.mark.parametrize("overrides, message", [
    (["timeline=bogus"], "timeline='bogus' is not a statistic of clip lengths; one of ['median'"),
    (["plot_takes=-3"], "plot_takes must be a whole number ≥ 0, got -3"),
    (["sheet_clips=-1"], "sheet_clips must be a whole number ≥ 0, got -1"),
    (["out=afile/report"], "afile is not a folder; choose another out="),
])
def test_segment_refuses_bad_values_and_unwritable_outputs(overrides, message, tmp_path, capsys, monkeypatch):
    (tmp_path / "afile").write_text("x")
    done = run_command("segment", "out=report", *overrides, "hydra.run.dir=hydra", capsys=capsys,
                       monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-segment: ") and message in line, line
    assert not (tmp_path / "report").exists()


def test_search_refuses_an_out_below_a_file(tmp_path, capsys, monkeypatch):
    (tmp_path / "afile").write_text("x")
    done = run_command("search", "query=synthetic_walk_normal_000:0-30", "out=afile/hits", "hydra.run.dir=hydra",
                       capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-search: out=afile/hits: ") and "afile is not a folder" in line, line


def test_a_read_only_folder_is_refused_before_any_work(tmp_path, monkeypatch):
    monkeypatch.setattr(os, "access", lambda path, mode: False)  # root may write anywhere: pretend it may not
    with pytest.raises(OutputWriteError, match=f"out={tmp_path / 'ro' / 'x'}: {tmp_path} is read-only"):
        check_new_output(tmp_path / "ro" / "x")


def test_atomic_writes_below_a_file_name_the_path(tmp_path):
    (tmp_path / "afile").write_text("x")
    with pytest.raises(OutputWriteError, match=f"cannot write {tmp_path / 'afile' / 'out'}"):
        with atomic_folder(tmp_path / "afile" / "out"):
            pass
    with pytest.raises(OutputWriteError, match=f"cannot write {tmp_path / 'afile' / 'x.json'}"):
        atomic_write_bytes(tmp_path / "afile" / "x.json", b"{}")
    assert (tmp_path / "afile").read_text() == "x"
