"""``stylemotion-view`` with an NPZ whose arrays need pickle (issue 26): one line naming the file, exit status 2, no
traceback, never loaded with ``allow_pickle``, nothing written."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from stylemotion.cli.view import main


class Boom:
    """Unpickling this would run code (it must never happen)."""

    def __reduce__(self):
        return (pytest.fail, ("the NPZ's pickle was loaded",))


@pytest.mark.parametrize("kind", ["object array", "pickle file"])
def test_a_pickled_npz_is_named_in_one_line(kind, tmp_path, capsys):
    bad = tmp_path / "walk.npz"
    if kind == "object array":
        np.savez(bad, positions=np.array([Boom()], dtype=object), fps=np.float32(30))
    else:
        bad.write_bytes(pickle.dumps({"positions": Boom()}))
    assert main([str(bad), "--out", str(tmp_path / "page")]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith(f"stylemotion-view: {bad}: ") and "pickled Python objects, which are never loaded" in line
    assert "allow_pickle" not in line and "Traceback" not in line, line
    assert not (tmp_path / "page").exists()


@pytest.mark.parametrize("spacing", ["nan", "-1", "1e308", "1001"])
def test_a_spacing_out_of_range_is_refused(spacing, tmp_path, capsys):
    assert main(["walk.bvh", "--out", str(tmp_path / "page"), "--spacing", spacing]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert line.startswith(f"stylemotion-view: --spacing {float(spacing)}: expected metres in 0–1000"), line
    assert not (tmp_path / "page").exists()
