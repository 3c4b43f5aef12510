"""``stylemotion-data`` on bad values and files (issue 26): one line naming the key or file, exit status 2, no
traceback, no summary written."""

from __future__ import annotations

import pytest
from cli_runner import run_command


@pytest.mark.parametrize("overrides, message", [
    (["data.contents=[fly]"], "data.contents: unknown content 'fly'; valid contents: walk"),
    (["data.fps=0"], "data.fps must be a positive finite number, got 0"),
    (["data.fps=nan"], "data.fps must be a positive finite number, got nan"),
    (["data.duration_s=-1"], "data.duration_s must be a positive finite number, got -1"),
    (["data.styles=[]"], "data.styles=[] selects no style: give at least one, or null for all"),
    (["data.split.val_fraction=1.5"], "data.split: fractions must be in [0, 1) and sum below 1, got val=1.5"),
    (["data=bvh_folder", "data.root=.", "+data.default_labels={style: ../x}"],
     "data.default_labels: style label '../x' is not a safe file name"),
    (["data=bvh_folder", "data.root=.", "data.pattern='[z-a]'"], "data.pattern '[z-a]' is not a valid regular"),
    (["data=bandai", "data.root=nope.zip"], "nope.zip: no such file or folder: data.root is the Bandai data set's"),
    (["data=bandai", "data.root=junk.zip"], "junk.zip: cannot open zip archive"),
])
def test_bad_data_values_and_files_end_in_one_line(overrides, message, tmp_path, capsys, monkeypatch):
    (tmp_path / "junk.zip").write_bytes(b"PK\x03\x04 cut off")
    out = tmp_path / "run"
    done = run_command("prepare", *overrides, f"hydra.run.dir={out}", capsys=capsys, monkeypatch=monkeypatch,
                       cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-data: ") and message in line, line
    assert not (out / "summary.json").exists()


def test_a_zip_without_bandai_label_tables_is_named_as_data_root(tmp_path, capsys, monkeypatch):
    import zipfile

    with zipfile.ZipFile(tmp_path / "mine.zip", "w") as zf:
        zf.writestr("walk.bvh", "HIERARCHY\n")
    done = run_command("prepare", "data=bandai", f"data.root={tmp_path / 'mine.zip'}", "hydra.run.dir=run",
                       capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith(f"stylemotion-data: {tmp_path / 'mine.zip'}: not the Bandai data set as downloaded"), line
    assert "label tables content_label.txt and style_label.txt not found" in line and "data.label_dir" in line
