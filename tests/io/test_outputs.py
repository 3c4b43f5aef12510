"""Output folders: existing results refused, data-derived names made safe, paths kept inside."""

from __future__ import annotations

import os

import pytest

from stylemotion.io.outputs import (
    MAX_NAME_LENGTH,
    OutputExistsError,
    UnsafePathError,
    check_new_output,
    inside,
    safe_name,
)


@pytest.mark.parametrize(("label", "expected"), [
    ("walk_normal_001", "walk_normal_001"),
    ("../../etc/passwd", "etc_passwd"),
    ("/abs/path/take", "abs_path_take"),
    ("C:\\mocap\\take 01", "C_mocap_take_01"),
    (".hidden", "hidden"),
    ("élan vital", "elan_vital"),
    ("a\x00b\nc", "a_b_c"),
    ("run-fast+1.5", "run-fast+1.5"),
])
def test_safe_name(label, expected):
    assert safe_name(label) == expected
    assert os.sep not in safe_name(label) and safe_name(label) not in (".", "..")


@pytest.mark.parametrize("label", ["", "..", "/", "___", "日本"])
def test_safe_name_refuses_labels_with_nothing_usable(label):
    with pytest.raises(ValueError, match="style"):
        safe_name(label, "style")


def test_safe_name_cuts_long_names():
    assert len(safe_name("x" * 1000)) == MAX_NAME_LENGTH


def test_inside_accepts_paths_within_and_refuses_escapes(tmp_path):
    assert inside(tmp_path, "takes", "a.png") == tmp_path.resolve() / "takes" / "a.png"
    for parts in (("..", "x.png"), ("/etc/x.png",), ("takes/../../x.png",)):
        with pytest.raises(UnsafePathError, match="outside its folder"):
            inside(tmp_path, *parts)
    (tmp_path / "link").symlink_to(tmp_path.parent)
    with pytest.raises(UnsafePathError):
        inside(tmp_path, "link", "x.png")


def test_check_new_output(tmp_path):
    target = tmp_path / "run"
    assert check_new_output(target) == target
    target.mkdir()
    with pytest.raises(OutputExistsError, match=r"out=.*force=true"):
        check_new_output(target)
    with pytest.raises(OutputExistsError, match="report="):
        check_new_output(target, key="report")
    assert check_new_output(target, force=True) == target


@pytest.mark.parametrize("force", [False, True])
@pytest.mark.parametrize("target", ["folder", "file", "nowhere"])
def test_an_output_that_is_a_link_is_refused_with_or_without_force(tmp_path, force, target):
    (tmp_path / "folder").mkdir()
    (tmp_path / "file").write_text("mine")
    (tmp_path / "out").symlink_to(tmp_path / target)
    with pytest.raises(UnsafePathError, match=f"--out={tmp_path / 'out'}: .* is a link to {tmp_path / target}"):
        check_new_output(tmp_path / "out", force, key="--out")
    assert (tmp_path / "file").read_text() == "mine" and not any((tmp_path / "folder").iterdir())
