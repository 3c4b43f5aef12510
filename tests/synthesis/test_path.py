"""Path files (``stylemotion-generate path.file=…``) and config points: every value that is not a
finite coordinate in range is an error naming file:line (CSV), the JSON index or the config key."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from stylemotion.synthesis.path import MAX_COORDINATE_M, GroundPath, PathError


def write(tmp_path: Path, name: str, data: str | bytes) -> Path:
    path = tmp_path / name
    path.write_bytes(data if isinstance(data, bytes) else data.encode())
    return path


@pytest.mark.parametrize("text, message", [
    ("x,z\n0,0\n0,1e300\n", r"p.csv:3: z is 1e\+300: coordinates must be within"),
    ("x,z\n0,0\n0,nan\n", "p.csv:3: z is nan: coordinates must be finite"),
    ("x,z\n0,0\n-inf,1\n", "p.csv:3: x is -inf: coordinates must be finite"),
    ("0,0\n,1\n", "p.csv:2: empty x field"),
    ("0,0\n1, \n", "p.csv:2: empty z field"),
    ("0,0\n1,2,\n", "p.csv:2: expected two columns x, z, got 3"),
    ("true,false\n0,1\n", r"p.csv:1: x is 'true' \(a boolean\)"),
    ("x,z\n0,0\n1,TRUE\n", r"p.csv:3: z is 'TRUE' \(a boolean\)"),
    ("x,z\n0,0\n1,one\n", "p.csv:3: not a number: z = 'one'"),
])
def test_bad_csv_values_name_the_line(tmp_path: Path, text: str, message: str) -> None:
    with pytest.raises(PathError, match=message):
        GroundPath.from_file(write(tmp_path, "p.csv", text))


def test_non_utf8_files_name_the_line(tmp_path: Path) -> None:
    with pytest.raises(PathError, match=r"p.csv:3: not UTF-8 text \(byte 0xff\)"):
        GroundPath.from_file(write(tmp_path, "p.csv", b"x,z\n0,0\n\xff,1\n"))
    with pytest.raises(PathError, match=r"p.json:2: not UTF-8 text \(byte 0xe9\)"):
        GroundPath.from_file(write(tmp_path, "p.json", b'{"points":\n [[0, 0], [0, 1]], "caf\xe9": 1}'))


def test_a_byte_order_mark_is_not_taken_for_a_header(tmp_path: Path) -> None:
    """With a UTF-8 BOM the first row ``0,0`` would read ``\\ufeff0,0``: not a number, silently a header."""
    path = GroundPath.from_file(write(tmp_path, "p.csv", "\ufeff0,0\n0,2\n3,6\n"), spline=False)
    assert path.points.tolist() == [[0, 0], [0, 2], [3, 6]]
    assert GroundPath.from_file(write(tmp_path, "p.json", "\ufeff[[0, 0], [0, 2]]")).length == pytest.approx(2.0)


@pytest.mark.parametrize("data, message", [
    ({"points": [[0, 0], [0, True]]}, r"p.json: points\[1\]\[1\] is True \(a boolean\)"),
    ([[0, 0], [False, 1]], r"p.json: \[1\]\[0\] is False \(a boolean\)"),
    ({"points": [[0, 0], ["1", 2]]}, r"p.json: points\[1\]\[0\] is '1', expected a number"),
    ({"points": [[0, 0], [0, None]]}, r"p.json: points\[1\]\[1\] is None, expected a number"),
    ({"points": [[0, 0], [0, 1e300]]}, r"p.json: points\[1\]\[1\] is 1e\+300: coordinates must be within"),
    ({"points": [[0, 0], [10**400, 0]]}, r"p.json: points\[1\]\[0\] is 1000.*: coordinates must be within"),
    ({"points": 5}, "p.json: points: points must be a list of"),
    ({"points": [[0, 0], 3]}, r"p.json: points\[1\] is 3: points must be \(n, 2\)"),
])
def test_bad_json_values_name_the_index(tmp_path: Path, data, message: str) -> None:
    with pytest.raises(PathError, match=message):
        GroundPath.from_file(write(tmp_path, "p.json", json.dumps(data)))


@pytest.mark.parametrize("literal", ["NaN", "Infinity", "-Infinity", "1e400"])
def test_json_non_finite_literals_name_the_index(tmp_path: Path, literal: str) -> None:
    with pytest.raises(PathError, match=r"p.json: points\[2\]\[0\] is .*: coordinates must be finite"):
        GroundPath.from_file(write(tmp_path, "p.json", f'{{"points": [[0, 0], [0, 1], [{literal}, 2]]}}'))


@pytest.mark.parametrize("points, message", [
    ([[0, 0], [0, True]], r"path.points\[1\]\[1\] is True \(a boolean\)"),
    ([[0, 0], [0, "2"]], r"path.points\[1\]\[1\] is '2', expected a number"),
    ([[0, 0], [0, 1e300]], r"path.points: point 1 is \[0.0, 1e\+300\]: coordinates must be within"),
    ([[0, 0], [0, 10**400]], r"path.points\[1\]\[1\] is 1000.*…: coordinates must be within"),
    (np.array([[True, False], [False, True]]), "path.points: points are booleans"),
])
def test_bad_config_points_name_the_key(points, message: str) -> None:
    with pytest.raises(PathError, match=message):
        GroundPath.from_points(points, source="path.points")


def test_good_files_still_load(tmp_path: Path) -> None:
    text = "# a path\nx , z\n\n0,0\n0, 2.5\n-1e3,1e-3\n"
    csv_path = GroundPath.from_file(write(tmp_path, "p.csv", text), spline=False)
    assert csv_path.points.tolist() == [[0, 0], [0, 2.5], [-1000, 0.001]]
    edge = GroundPath.from_points([[0, 0], [MAX_COORDINATE_M, -MAX_COORDINATE_M]])
    assert edge.length == pytest.approx(np.sqrt(2) * MAX_COORDINATE_M)
