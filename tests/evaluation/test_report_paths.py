"""Report files are named after primitives, which come from checkpoints: none may leave the folder."""

from __future__ import annotations

import pytest

from stylemotion.evaluation.report import write_csvs
from stylemotion.io.outputs import UnsafePathError


def test_a_primitive_name_that_climbs_out_is_refused(tmp_path):
    folder = tmp_path / "report"
    folder.mkdir()
    evil = "a/../../../escaped"
    results = {"table_5_1": {evil: {"examples": ["x"], "models": ["x"], "distance": [[1.0]]}}}
    with pytest.raises(UnsafePathError, match="outside its folder"):
        write_csvs(results, folder)
    assert not list(tmp_path.rglob("*escaped*"))


def test_ordinary_primitive_names_are_written_inside(tmp_path):
    results = {"table_5_1": {"walk_leftStance": {"examples": ["x"], "models": ["x"], "distance": [[1.0]]}}}
    assert write_csvs(results, tmp_path) == ["table_5_1_walk_leftStance.csv"]
    assert (tmp_path / "table_5_1_walk_leftStance.csv").read_text().startswith("model \\ example,x")
