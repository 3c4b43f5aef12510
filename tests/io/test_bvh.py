"""BVH reading and writing: real files of three conventions, round trips, and malformed input."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import BANDAI_MEMBERS, OTHER_SKELETONS, line_of, tiny_bvh_text

from stylemotion.datasets.canonical import detect_unit_scale, resolve_joint_map
from stylemotion.io.bvh import format_bvh, parse_bvh, parse_bvh_skeleton, read_bvh, snap_fps, write_bvh
from stylemotion.io.errors import BvhError

ROUND_TRIP_TOL_M = 1e-5


def _assert_same_motion_in_metres(original, reread, tol_m: float = ROUND_TRIP_TOL_M) -> float:
    """Same skeleton, frame count and fps, and FK positions equal within ``tol_m`` metres."""
    assert reread.skeleton.names == original.skeleton.names
    np.testing.assert_array_equal(reread.skeleton.parents, original.skeleton.parents)
    assert reread.skeleton.channels == original.skeleton.channels
    assert reread.num_frames == original.num_frames
    assert reread.fps == original.fps
    scale = detect_unit_scale(original, resolve_joint_map(None, original))
    err = np.abs(reread.global_positions() - original.global_positions()).max() * scale
    assert err <= tol_m, f"{original.source}: round-trip FK error {err:.3g} m > {tol_m} m"
    return err


# ---------------------------------------------------------------------------------------------
# Real files


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(OTHER_SKELETONS))
def test_read_other_conventions(name, other_skeleton_paths):
    filename, _, fps = OTHER_SKELETONS[name]
    path = other_skeleton_paths[name]
    motion = read_bvh(path)
    text = path.read_text()
    declared_frames = int(text.split("Frames:")[1].split()[0])
    joint_count = text.count("ROOT ") + text.count("JOINT ")
    assert motion.num_frames == declared_frames
    assert motion.skeleton.num_joints == joint_count
    assert motion.fps == fps  # 0.016667 → 60 and 0.008333 → 120 exactly (snapped)
    assert motion.source == str(path)
    # First row, first values: the root position channels (Xposition Yposition Zposition).
    first_row = [float(v) for v in text.split("Frame Time:")[1].split("\n")[1].split()]
    assert len(first_row) == sum(len(c) for c in motion.skeleton.channels)
    np.testing.assert_allclose(motion.translations[0, 0], first_row[:3])
    q = motion.rotations
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-12)
    assert np.all(np.isfinite(motion.global_positions()))


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(OTHER_SKELETONS))
def test_round_trip_other_conventions(name, other_skeleton_paths, tmp_path):
    original = read_bvh(other_skeleton_paths[name])
    out = tmp_path / f"{name}.bvh"
    write_bvh(original, out)
    reread = read_bvh(out)
    _assert_same_motion_in_metres(original, reread)
    # format_bvh (in memory) gives the same text as write_bvh (atomic file write).
    assert out.read_text() == format_bvh(original)
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


@pytest.mark.realdata
@pytest.mark.parametrize("member", BANDAI_MEMBERS)
def test_bandai_from_zip_round_trip(member, bandai_zip):
    source = f"{bandai_zip.filename}::{member}"
    original = parse_bvh(bandai_zip.read(member), source)
    assert original.source == source
    assert original.skeleton.num_joints == 22
    assert original.skeleton.names[0] == "joint_Root"
    assert all(ch[3:] == ["Zrotation", "Xrotation", "Yrotation"] for ch in original.skeleton.channels)
    assert original.fps == 30.0  # "Frame Time: 0.0333333"
    # Bandai's position channels replace the OFFSET: frame 0 of the Hips differs from its OFFSET.
    assert not np.allclose(original.translations[:, 1], original.skeleton.offsets[1])
    reread = parse_bvh(format_bvh(original), "reread")
    _assert_same_motion_in_metres(original, reread)


def test_snap_fps():
    assert snap_fps(1 / 0.016667) == 60.0
    assert snap_fps(1 / 0.0333333) == 30.0
    assert snap_fps(1 / 0.008333) == 120.0
    assert snap_fps(1 / 0.0123) == pytest.approx(81.30081)  # not near an integer: kept
    assert snap_fps(1 / 0.0123) != round(1 / 0.0123)


def test_frame_time_snaps_on_read_and_survives_write(tmp_path):
    motion = parse_bvh(tiny_bvh_text(frame_time="0.016667"), "tiny")
    assert motion.fps == 60.0
    path = tmp_path / "tiny.bvh"
    write_bvh(motion, path)
    assert read_bvh(path).fps == 60.0
    odd = parse_bvh(tiny_bvh_text(frame_time="0.0123"), "odd")
    assert odd.fps == pytest.approx(1 / 0.0123)


def test_tiny_round_trip_and_values():
    text = tiny_bvh_text()
    motion = parse_bvh(text, "tiny")
    assert motion.skeleton.names == ["Hips", "Spine", "Head", "LeftLeg"]
    assert list(motion.skeleton.parents) == [-1, 0, 1, 0]
    np.testing.assert_allclose(motion.skeleton.end_sites[2], [0, 15, 0])
    np.testing.assert_allclose(motion.translations[2, 0], [2.0, 91.0, 0.0])
    np.testing.assert_allclose(motion.translations[:, 1], np.broadcast_to([0, 20, 1], (3, 3)))
    reread = parse_bvh(format_bvh(motion), "tiny2")
    np.testing.assert_allclose(reread.global_positions(), motion.global_positions(), atol=1e-6)
    np.testing.assert_allclose(reread.skeleton.end_sites[3], motion.skeleton.end_sites[3])


def test_read_missing_file_names_it(tmp_path):
    path = tmp_path / "nope.bvh"
    with pytest.raises(BvhError) as err:
        read_bvh(path)
    assert err.value.source == str(path)
    assert str(path) in str(err.value)


# ---------------------------------------------------------------------------------------------
# Malformed input: each error names the file, the line and what was expected.


def _expect_error(path, line: int, *words: str) -> BvhError:
    with pytest.raises(BvhError) as info:
        read_bvh(path)
    err = info.value
    assert err.source == str(path), str(err)
    assert err.line == line, f"expected line {line}: {err}"
    assert str(err).startswith(f"{path}:{line}: "), str(err)
    for word in words:
        assert word in err.detail, f"{word!r} not in {err.detail!r}"
    return err


def _lines(text: str) -> list[str]:
    return text.split("\n")


def test_truncated_rows(write_text):
    text = tiny_bvh_text()
    lines = _lines(text)
    last_row = line_of(text, "Frame Time:") + 2  # two of three rows kept
    path = write_text("\n".join(lines[:last_row]) + "\n")
    _expect_error(path, last_row + 1, "truncated", "3 frames", "found 2 frame rows")
    # Without the final newline the error still points at the line after the last row.
    path = write_text("\n".join(lines[:last_row]), "no_newline.bvh")
    _expect_error(path, last_row + 1, "truncated", "3 frames")


@pytest.mark.parametrize("row_index", [2, 3])
def test_truncated_inside_a_row(write_text, row_index):
    text = tiny_bvh_text()
    row = line_of(text, "Frame Time:") + row_index
    start = sum(len(line) + 1 for line in _lines(text)[: row - 1])
    cut = text[: start + 20]  # mid row: 3 values and a bit
    path = write_text(cut)
    _expect_error(path, row, "truncated", "3 values, expected 15")


@pytest.mark.realdata
def test_truncated_real_file(write_text, bandai_zip):
    text = bandai_zip.read(BANDAI_MEMBERS[2]).decode()
    lines = _lines(text)
    frames_line = line_of(text, "Frames:")
    declared = int(lines[frames_line - 1].split()[1])
    keep = frames_line + 1 + declared // 2  # half of the rows
    path = write_text("\n".join(lines[:keep]) + "\n", "bandai_truncated.bvh")
    _expect_error(path, keep + 1, "truncated", f"{declared} frames", f"found {declared // 2} frame rows")


@pytest.mark.parametrize(
    ("cut_after", "expected"),
    [
        ("\t\tOFFSET 0.0 20.0 1.0", "JOINT, End Site or '}' closing joint 'Spine'"),
        ("\t\t\tEnd Site", "'{'"),
        ("JOINT LeftLeg", "'{'"),
    ],
)
def test_cut_inside_hierarchy(write_text, cut_after, expected):
    text = tiny_bvh_text()
    # Keep the CHANNELS line after Spine's OFFSET so that the file ends right after it.
    end = text.index(cut_after) + len(cut_after)
    if "OFFSET 0.0 20.0" in cut_after:
        end = text.index("\n", text.index("CHANNELS", end)) + 1
    cut = text[:end]
    path = write_text(cut)
    last_line = len(cut.rstrip("\n").split("\n"))
    _expect_error(path, last_line, "ends inside the hierarchy", expected)


def test_cut_inside_offset(write_text):
    text = tiny_bvh_text()
    cut = text[: text.index("OFFSET 0.0 45.0") + len("OFFSET 0.0 45.0")]
    path = write_text(cut)
    _expect_error(path, line_of(text, "OFFSET 0.0 45.0"), "ends inside the hierarchy", "'Head' OFFSET z")


@pytest.mark.realdata
def test_cut_inside_hierarchy_real_file(write_text, bandai_zip):
    text = bandai_zip.read(BANDAI_MEMBERS[1]).decode()
    lines = _lines(text)
    cut_line = line_of(text, "JOINT LowerArm_R")
    path = write_text("\n".join(lines[:cut_line]) + "\n", "bandai_cut.bvh")
    _expect_error(path, cut_line, "ends inside the hierarchy", "'{'")


def test_hierarchy_unclosed_before_motion(write_text):
    text = tiny_bvh_text()
    lines = _lines(text)
    motion = line_of(text, "MOTION")
    del lines[motion - 2]  # the root's closing brace
    path = write_text("\n".join(lines))
    _expect_error(path, motion - 1, "found 'MOTION'", "closing joint 'Hips'")


def test_channel_count_larger_than_list(write_text):
    text = tiny_bvh_text().replace("CHANNELS 3 Zrotation X", "CHANNELS 4 Zrotation X")
    path = write_text(text)
    _expect_error(path, line_of(text, "CHANNELS 4"), "'Spine'", "declares 4 channels but lists 3")


def test_channel_count_7(write_text):
    text = tiny_bvh_text().replace("CHANNELS 6", "CHANNELS 7")
    path = write_text(text)
    _expect_error(path, line_of(text, "CHANNELS 7"), "'Hips'", "declares 7 channels but lists 6")


def test_channel_count_smaller_than_list(write_text):
    text = tiny_bvh_text().replace("CHANNELS 6", "CHANNELS 5")
    path = write_text(text)
    _expect_error(path, line_of(text, "CHANNELS 5"), "'Hips'", "declares 5 channels but lists more",
                  "'Yrotation' is extra")


def test_unknown_channel_name(write_text):
    text = tiny_bvh_text().replace("Zrotation Yrotation Xrotation", "Zrotation Wrotation Xrotation")
    path = write_text(text)
    err = _expect_error(path, line_of(text, "Wrotation"), "'Head'", "'Wrotation'", "Xrotation")
    assert "Yposition" in err.detail  # lists what was expected


def test_repeated_rotation_axis(write_text):
    text = tiny_bvh_text().replace("Xrotation Yrotation Zrotation", "Xrotation Yrotation Xrotation")
    path = write_text(text)
    _expect_error(path, line_of(text, "Xrotation Yrotation Xrotation"), "'LeftLeg'", "exactly one each")


@pytest.mark.parametrize("bad", ["abc", "1.0.5", "--3", "1,5"])
def test_non_numeric_value(write_text, bad):
    text = tiny_bvh_text()
    lines = _lines(text)
    row = line_of(text, "Frame Time:") + 2
    values = lines[row - 1].split()
    values[7] = bad
    lines[row - 1] = " ".join(values)
    path = write_text("\n".join(lines))
    _expect_error(path, row, repr(bad), "column 8", "finite number")


@pytest.mark.parametrize("bad", ["nan", "NaN", "inf", "-Infinity"])
def test_nan_value(write_text, bad):
    text = tiny_bvh_text()
    lines = _lines(text)
    row = line_of(text, "Frame Time:") + 3
    values = lines[row - 1].split()
    values[14] = bad
    lines[row - 1] = " ".join(values)
    path = write_text("\n".join(lines))
    _expect_error(path, row, repr(bad), "column 15", "finite number")


@pytest.mark.realdata
def test_nan_in_real_file(write_text, other_skeleton_paths):
    text = other_skeleton_paths["xia_cmu31"].read_text()
    lines = _lines(text)
    row = line_of(text, "Frame Time:") + 200
    values = lines[row - 1].split()
    values[40] = "nan"
    lines[row - 1] = " ".join(values)
    path = write_text("\n".join(lines), "xia_nan.bvh")
    _expect_error(path, row, "'nan'", "column 41")


def test_nan_in_offset(write_text):
    text = tiny_bvh_text().replace("OFFSET 0.0 45.0 0.0", "OFFSET 0.0 nan 0.0")
    path = write_text(text)
    _expect_error(path, line_of(text, "OFFSET 0.0 nan"), "'Head' OFFSET y", "finite number")


def test_zero_frames(write_text):
    text = tiny_bvh_text(frames=())
    assert "Frames: 0" in text
    path = write_text(text)
    _expect_error(path, line_of(text, "Frames:"), "0 frames", "at least one")


def test_bad_frame_count(write_text):
    text = tiny_bvh_text().replace("Frames: 3", "Frames: three")
    path = write_text(text)
    _expect_error(path, line_of(text, "Frames:"), "'three'", "integer")


def test_row_of_wrong_length(write_text):
    text = tiny_bvh_text()
    lines = _lines(text)
    row = line_of(text, "Frame Time:") + 2
    lines[row - 1] += " 1.0"
    path = write_text("\n".join(lines))
    _expect_error(path, row, "16 values", "expected 15")
    lines = _lines(text)
    lines[row - 1] = " ".join(lines[row - 1].split()[:-2])
    path = write_text("\n".join(lines), "short.bvh")
    _expect_error(path, row, "13 values", "expected 15")


def test_extra_rows(write_text):
    text = tiny_bvh_text()
    first_row = line_of(text, "Frame Time:") + 1
    row = _lines(text)[first_row - 1]
    path = write_text(text + row + "\n")
    _expect_error(path, first_row + 3, "found 4 frame rows", "header says 3")


def test_missing_motion(write_text):
    text = tiny_bvh_text()
    lines = _lines(text)
    motion = line_of(text, "MOTION")
    del lines[motion - 1]
    path = write_text("\n".join(lines))
    # The line that now holds "Frames:" is where MOTION was expected.
    _expect_error(path, motion, "expected 'MOTION'", "'Frames:'")


def test_file_ends_after_hierarchy(write_text):
    text = tiny_bvh_text()
    cut = text[: text.index("MOTION")]
    path = write_text(cut)
    _expect_error(path, line_of(text, "MOTION"), "expected 'MOTION'")


@pytest.mark.parametrize("bad", ["abc", "0", "-0.0333", "nan"])
def test_bad_frame_time(write_text, bad):
    text = tiny_bvh_text(frame_time=bad)
    path = write_text(text)
    _expect_error(path, line_of(text, "Frame Time:"), repr(bad), "positive number of seconds")


def test_missing_frame_time(write_text):
    text = tiny_bvh_text().replace("Frame Time: 0.0333333\n", "")
    path = write_text(text)
    _expect_error(path, line_of(text, "Frames:") + 1, "expected 'Frame Time: <seconds>'")


def test_duplicate_joint_name(write_text):
    text = tiny_bvh_text().replace("JOINT LeftLeg", "JOINT Spine")
    path = write_text(text)
    _expect_error(path, line_of(text, "JOINT Spine", 1), "'Spine'", "twice")


def test_crlf_file_reads_like_lf(write_text):
    text = tiny_bvh_text()
    lf = read_bvh(write_text(text, "lf.bvh"))
    crlf = read_bvh(write_text(text.replace("\n", "\r\n").encode(), "crlf.bvh"))
    np.testing.assert_array_equal(crlf.global_positions(), lf.global_positions())
    # Errors in a CRLF file still point at the right line.
    bad = text.replace("Frame Time: 0.0333333", "Frame Time: x").replace("\n", "\r\n")
    _expect_error(write_text(bad.encode(), "crlf_bad.bvh"), line_of(text, "Frame Time:"), "'x'")


def test_skeleton_from_the_head_of_a_file_equals_the_full_parse() -> None:
    text = tiny_bvh_text().replace("\n", "\r\n").encode()
    full = parse_bvh(text, "walk.bvh").skeleton
    for cut in (text.index(b"MOTION") + 6, text.index(b"Frame Time") + 3, len(text)):
        head = parse_bvh_skeleton(text[:cut], "walk.bvh")
        assert head.names == full.names and head.channels == full.channels
        np.testing.assert_array_equal(head.offsets, full.offsets)
        np.testing.assert_array_equal(head.parents, full.parents)
    with pytest.raises(BvhError, match=r"walk.bvh.*line \d+.*expected 'MOTION'|walk.bvh.*MOTION"):
        parse_bvh_skeleton(text[: text.index(b"MOTION") - 1], "walk.bvh")
    with pytest.raises(BvhError, match="walk.bvh"):
        parse_bvh_skeleton(text[:40], "walk.bvh")
