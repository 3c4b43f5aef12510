"""BVH input that used to crash or mislead: deep hierarchies, CR-only lines, byte-order marks,
Frame Time in milliseconds, and motions over the size limits."""

from __future__ import annotations

import sys
import warnings

import numpy as np
import pytest
from conftest import TINY_BVH_FRAMES, line_of, tiny_bvh_text

from stylemotion.io.bvh import format_bvh, parse_bvh, read_bvh
from stylemotion.io.errors import BvhError, LimitError


def deep_chain_text(depth: int, frames: int = 2) -> str:
    """A BVH whose joints form one chain ``depth`` deep, each 1 unit above its parent."""
    lines = ["HIERARCHY", "ROOT J0", "{", "OFFSET 0 0 0", "CHANNELS 6 Xposition Yposition Zposition "
             "Zrotation Xrotation Yrotation"]
    for j in range(1, depth):
        lines += [f"JOINT J{j}", "{", "OFFSET 0 1 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
    lines += ["End Site", "{", "OFFSET 0 1 0", "}"] + ["}"] * depth
    row = " ".join(["0"] * (6 + 3 * (depth - 1)))
    lines += ["MOTION", f"Frames: {frames}", "Frame Time: 0.0333333"] + [row] * frames
    return "\n".join(lines) + "\n"


def test_deep_chain_parses_and_writes_without_recursion():
    depth = 5000
    assert depth > sys.getrecursionlimit()  # a recursive parser fails here (RecursionError)
    motion = parse_bvh(deep_chain_text(depth), "deep.bvh")
    assert motion.skeleton.num_joints == depth
    np.testing.assert_array_equal(motion.skeleton.parents, np.arange(-1, depth - 1))
    positions = motion.global_positions()
    assert positions[0, -1, 1] == depth - 1 and np.all(np.isfinite(positions))
    reread = parse_bvh(format_bvh(motion), "deep2.bvh")
    assert reread.skeleton.names == motion.skeleton.names
    np.testing.assert_array_equal(reread.global_positions(), positions)


def test_format_bvh_keeps_the_nesting_of_branches():
    motion = parse_bvh(tiny_bvh_text(), "tiny")
    text = format_bvh(motion)
    # Spine ⊃ Head, then LeftLeg as Spine's sibling: same order and depth as the source.
    assert [ln.strip() for ln in text.splitlines() if ln.strip().startswith(("ROOT", "JOINT"))] == [
        "ROOT Hips", "JOINT Spine", "JOINT Head", "JOINT LeftLeg"]
    assert "\t\tJOINT Head" in text and "\tJOINT LeftLeg" in text and "\t\tJOINT LeftLeg" not in text
    again = parse_bvh(text, "again")
    assert again.skeleton.end_sites.keys() == motion.skeleton.end_sites.keys()
    np.testing.assert_allclose(again.global_positions(), motion.global_positions(), atol=1e-6)


def test_cr_only_line_endings_read_like_lf(write_text):
    text = tiny_bvh_text()
    lf = read_bvh(write_text(text, "lf.bvh"))
    cr = read_bvh(write_text(text.replace("\n", "\r").encode(), "cr.bvh"))
    np.testing.assert_array_equal(cr.global_positions(), lf.global_positions())
    assert cr.num_frames == len(TINY_BVH_FRAMES)
    # An error in a CR-only file names the right line.
    bad = text.replace("Frame Time: 0.0333333", "Frame Time: x").replace("\n", "\r")
    with pytest.raises(BvhError) as err:
        read_bvh(write_text(bad.encode(), "cr_bad.bvh"))
    assert err.value.line == line_of(text, "Frame Time:") and "'x'" in err.value.detail


@pytest.mark.parametrize("newline", ["\n", "\r\n", "\r"])
def test_utf8_byte_order_mark_is_accepted(write_text, newline):
    text = tiny_bvh_text()
    plain = read_bvh(write_text(text, "plain.bvh"))
    bom = read_bvh(write_text(b"\xef\xbb\xbf" + text.replace("\n", newline).encode(), "bom.bvh"))
    np.testing.assert_array_equal(bom.global_positions(), plain.global_positions())
    assert bom.skeleton.names == plain.skeleton.names


def test_utf16_file_is_a_clear_error(write_text):
    path = write_text(tiny_bvh_text().encode("utf-16"), "wide.bvh")
    with pytest.raises(BvhError) as err:
        read_bvh(path)
    assert str(err.value).startswith(f"{path}:1: ") and "UTF-16" in err.value.detail


def test_non_utf8_hierarchy_names_its_line(write_text):
    text = tiny_bvh_text()
    raw = text.replace("JOINT Head", "JOINT He\xffad").encode("latin-1")
    with pytest.raises(BvhError) as err:
        read_bvh(write_text(raw, "latin.bvh"))
    assert err.value.line == line_of(text, "JOINT Head") and "UTF-8" in err.value.detail


def test_frame_time_in_milliseconds_is_refused_naming_the_file_and_line():
    frames = TINY_BVH_FRAMES * 4  # 12 frames: resampled to 30 fps they would be 12,000 (issue 26)
    text = tiny_bvh_text(frames, frame_time="33.3333")
    with pytest.raises(BvhError, match="milliseconds") as err:
        parse_bvh(text, "ms.bvh")
    assert str(err.value).startswith(f"ms.bvh:{line_of(text, 'Frame Time:')}: ")
    assert "0.0333333" in str(err.value)  # the value meant
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        parse_bvh(tiny_bvh_text(frames), "seconds.bvh")  # 30 fps: no warning
        parse_bvh(tiny_bvh_text(frame_time="2.0"), "three_slow_frames.bvh")  # few frames: a pose file


def test_joint_frames_limit_is_checked_before_the_motion_is_built(monkeypatch):
    import stylemotion.io.bvh as bvh

    def must_not_run(*args, **kwargs):
        raise AssertionError("the motion was built before the limit was checked")

    monkeypatch.setattr(bvh, "_motion_from_channels", must_not_run)
    with pytest.raises(LimitError) as err:
        parse_bvh(tiny_bvh_text(), "big.bvh", max_joint_frames=11)  # 3 frames × 4 joints = 12
    assert "data.max_joint_frames=11" in str(err.value) and str(err.value).startswith("big.bvh: ")


def test_file_size_limit_names_the_key(write_text):
    path = write_text(tiny_bvh_text())
    with pytest.raises(LimitError) as err:
        read_bvh(path, max_file_mb=0.0001)
    assert err.value.source == str(path) and "data.max_file_mb=0.0001" in str(err.value)
    assert read_bvh(path, max_file_mb=1).num_frames == 3
