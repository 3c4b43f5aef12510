"""The one JSON writer: non-finite numbers as null, numpy as plain values, atomic, readable errors."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from stylemotion.io.errors import UserInputError
from stylemotion.io.jsonfile import JsonFileError, json_text, plain, read_json, write_json


def test_non_finite_numbers_are_written_as_null_and_numpy_as_plain_values(tmp_path: Path) -> None:
    value = {"nan": float("nan"), "inf": np.float32("inf"), "ninf": -math.inf, "ok": np.float64(0.25),
             "n": np.int64(3), "flag": np.bool_(True), "array": np.array([[1.5, np.nan]]), "tuple": (1, 2),
             "path": Path("a/b"), 7: "key made a string"}
    path = write_json(tmp_path / "out.json", value)
    text = path.read_text()
    assert text.endswith("\n") and "NaN" not in text and "Infinity" not in text
    assert json.loads(text) == {"nan": None, "inf": None, "ninf": None, "ok": 0.25, "n": 3, "flag": True,
                                "array": [[1.5, None]], "tuple": [1, 2], "path": "a/b", "7": "key made a string"}
    assert read_json(path) == json.loads(text)


def test_unknown_types_are_a_type_error_not_a_silent_string() -> None:
    with pytest.raises(TypeError, match="object"):
        plain({"x": object()})


def test_tensor_like_values_become_lists() -> None:
    class TensorLike:
        def tolist(self) -> list[float]:
            return [1.0, float("nan")]

    assert json_text(TensorLike(), indent=None) == "[1.0, null]\n"


def test_a_cut_off_file_names_the_file_and_line(tmp_path: Path) -> None:
    path = tmp_path / "report.json"
    path.write_text('{\n "a": 1,\n "b": [1, 2')
    with pytest.raises(JsonFileError) as caught:
        read_json(path, "report")
    message = str(caught.value)
    assert message.startswith(f"{path}:3: not valid JSON") and "cut off" in message
    assert isinstance(caught.value, UserInputError)
    with pytest.raises(JsonFileError, match="no such report"):
        read_json(tmp_path / "missing.json", "report")


def test_a_failed_write_leaves_the_old_file_intact(tmp_path: Path) -> None:
    path = write_json(tmp_path / "out.json", {"old": 1})
    with pytest.raises(TypeError):
        write_json(path, {"new": object()})
    assert read_json(path) == {"old": 1}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.json"]
