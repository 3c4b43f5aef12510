"""The user's example of ``stylemotion-style``: ``<BVH>[:start-end]``, its conversion (the datasets' own),
its frame range in the file's frames, and its primitives — on synthetic BVH files and the shared
other-skeleton walks (CMU 21-joint at 60 fps, Xia's CMU 31-joint at 120 fps)."""

from __future__ import annotations

import hashlib
import zipfile
from pathlib import Path

import numpy as np
import pytest
from conftest import tiny_bvh_text
from style_fixtures import example_bvh

from stylemotion.bones import BONE_NAMES, median_bone_lengths, target_bone_lengths
from stylemotion.datasets.loading import ConversionSettings, load_canonical_positions
from stylemotion.datasets.registry import load_synthetic
from stylemotion.datasets.retarget import retarget_takeset
from stylemotion.io.sources import FileSource
from stylemotion.style_example.example import (
    MAX_EXAMPLES,
    ExampleSpec,
    StyleExampleError,
    convert_example,
    cut_example,
    cut_examples,
    on_run_skeleton,
    parse_example,
    parse_examples,
)

PRIMITIVES = ["walk_leftStance", "walk_rightStance"]


@pytest.mark.parametrize("text, spec", [
    ("walk.bvh", ExampleSpec("walk.bvh")),
    ("walk.bvh:120-480", ExampleSpec("walk.bvh", 120, 480)),
    (" dir/walk.bvh:0-2 ", ExampleSpec("dir/walk.bvh", 0, 2)),
    ("data.zip::sub/walk-fast.bvh", ExampleSpec("data.zip::sub/walk-fast.bvh")),
    ("data.zip::walk.bvh:3-9", ExampleSpec("data.zip::walk.bvh", 3, 9)),
    ("my-walk.bvh", ExampleSpec("my-walk.bvh")),
])
def test_an_example_names_a_file_and_optionally_a_frame_range(text: str, spec: ExampleSpec) -> None:
    assert parse_example(text) == spec


@pytest.mark.parametrize("text, message", [
    ("walk.bvh:5-3", "the frame range 5-3 is empty"),
    ("walk.bvh:4-4", "the frame range 4-4 is empty"),
    ("walk.bvh:a-b", "'a-b' must be START-END, two whole numbers"),
    ("walk.bvh:1.5-3", "'1.5-3' must be START-END"),
    ("walk.bvh:-1-5", "'-1-5' must be START-END"),
    ("walk.bvh:1-2-3", "'1-2-3' must be START-END"),
    ("walk.bvh:²-3", "must be START-END"),
    ("", "example= is empty"),
])
def test_a_bad_frame_range_is_refused_naming_it(text: str, message: str) -> None:
    with pytest.raises(StyleExampleError, match=message.replace("(", r"\(").replace(".", r"\.")):
        parse_example(text)


def test_a_file_whose_name_looks_like_a_range_is_that_file(tmp_path: Path) -> None:
    path = tmp_path / "take:1-2"
    path.write_text("x")
    assert parse_example(str(path)) == ExampleSpec(str(path))


def test_the_example_is_converted_like_the_datasets_convert_their_files(tmp_path: Path) -> None:
    """Whole file: exactly the datasets' conversion (60 → 30 fps here); with a range: the same as cutting a
    30 fps file's positions, at the file's own frames; the sha256 is the file's."""
    bvh = example_bvh(tmp_path, fps=60.0, duration_s=2.0)
    settings = ConversionSettings(fps=30.0)
    whole = convert_example(parse_example(str(bvh)), settings)
    np.testing.assert_array_equal(whole.positions, load_canonical_positions(FileSource(str(bvh)), settings))
    assert (whole.file_fps, whole.file_frames, whole.start, whole.end, whole.fps) == (60.0, 120, 0, 120, 30.0)
    assert whole.sha256 == hashlib.sha256(bvh.read_bytes()).hexdigest()
    at30 = example_bvh(tmp_path, fps=30.0, duration_s=2.0)
    full = load_canonical_positions(FileSource(str(at30)), settings)
    part = convert_example(parse_example(f"{at30}:10-50"), settings)
    np.testing.assert_allclose(part.positions, full[10:50], atol=1e-6)
    assert (part.start, part.end, part.file_frames) == (10, 50, 60)


def test_a_zip_member_is_an_example_too(tmp_path: Path) -> None:
    bvh = example_bvh(tmp_path, fps=30.0, duration_s=2.0)
    with zipfile.ZipFile(tmp_path / "takes.zip", "w") as zf:
        zf.write(bvh, "sub/walk-a.bvh")
    example = convert_example(parse_example(f"{tmp_path / 'takes.zip'}::sub/walk-a.bvh:0-30"), ConversionSettings())
    assert example.name == f"{tmp_path / 'takes.zip'}::sub/walk-a.bvh" and len(example.positions) == 30
    assert example.take("mine", "walk").name == "walk-a"


def test_a_range_past_the_files_end_names_the_files_frames(tmp_path: Path) -> None:
    bvh = example_bvh(tmp_path, fps=60.0, duration_s=2.0)
    with pytest.raises(StyleExampleError, match=r"ends after the file's last frame: .* has 120 frames \(0-120\) at "
                                                r"60 fps"):
        convert_example(parse_example(f"{bvh}:100-121"), ConversionSettings())


def test_a_skeleton_no_joint_map_names_is_refused_with_the_key_that_helps(tmp_path: Path) -> None:
    path = tmp_path / "four_joints.bvh"
    path.write_text(tiny_bvh_text())
    with pytest.raises(StyleExampleError, match=r"no built-in joint map fits this skeleton.*joint_map=<map\.yaml>"):
        convert_example(parse_example(str(path)), ConversionSettings())


def test_a_missing_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(StyleExampleError, match=r"example=.*nowhere\.bvh: .*cannot read file"):
        convert_example(parse_example(str(tmp_path / "nowhere.bvh")), ConversionSettings())


def test_the_example_is_put_on_the_runs_skeleton(tmp_path: Path) -> None:
    """``data.retarget=normal`` puts every take on one skeleton and the example goes onto it; on data
    without ``retarget`` the example goes onto the median bones of the neutral takes (its own bones
    differ: an exhausted walker of another size)."""
    data = load_synthetic(takes_per_pair=2, styles=["normal", "elderly"], contents=["walk"], duration_s=2.0)
    example = convert_example(parse_example(str(example_bvh(tmp_path, fps=30.0))), ConversionSettings())
    neutral = target_bone_lengths(t.positions for t in data.filter(style="normal"))
    assert np.abs(median_bone_lengths(example.positions) - neutral).max() > 0.003  # 1 % of a shin
    plain = on_run_skeleton(example, data, "normal")
    np.testing.assert_allclose(median_bone_lengths(plain.positions), neutral, atol=1e-5)
    assert plain.retarget["style"] == "normal" and plain.retarget["takes"] == 2
    retargeted = retarget_takeset(data, "elderly")
    target = np.array([retargeted.retarget["bone_lengths_m"][b] for b in BONE_NAMES])
    assert np.abs(target - neutral).max() > 0.003
    moved = on_run_skeleton(example, retargeted, "normal")
    np.testing.assert_allclose(median_bone_lengths(moved.positions), target, atol=1e-5)
    assert moved.retarget["style"] == "elderly" and moved.positions.dtype == np.float32
    assert moved.sha256 == example.sha256 and moved.positions.shape == example.positions.shape


def test_a_walk_is_cut_into_both_stances_and_records_its_frames_in_the_file(tmp_path: Path) -> None:
    example = convert_example(parse_example(str(example_bvh(tmp_path, fps=60.0))), ConversionSettings())
    cut = cut_example(example, "tired", "walk", [*PRIMITIVES, "run_leftStance"], {})
    assert all(cut.clips[p] for p in PRIMITIVES) and cut.used == {p: cut.clips[p] for p in PRIMITIVES}
    assert cut.skipped == ["run_leftStance"] and not cut.borrowed
    clip = cut.clips["walk_leftStance"][0]
    assert (clip.style, clip.content, clip.take) == ("tired", "walk", example.take("tired", "walk").name)
    record = example.record(clip)
    assert record["file_frames"] == [2 * clip.start, 2 * (clip.stop - 1) + 1]  # 60 fps file, 30 fps clip
    assert record["sha256"] == example.sha256 and record["file"] == example.name


def test_an_example_without_a_complete_step_says_why(tmp_path: Path) -> None:
    example = convert_example(parse_example(f"{example_bvh(tmp_path, fps=60.0)}:0-20"), ConversionSettings())
    with pytest.raises(StyleExampleError, match=r"no complete step of the run's primitives .* can be cut from it "
                                                r"\(10 frames at 30 fps .*Why: right stance cut by the take's start"):
        cut_example(example, "tired", "walk", PRIMITIVES, {})


def test_a_walk_given_for_an_arm_primitive_says_what_an_arm_example_needs(tmp_path: Path) -> None:
    example = convert_example(parse_example(str(example_bvh(tmp_path, fps=60.0))), ConversionSettings())
    with pytest.raises(StyleExampleError, match=r"primitives \['raise-up-right-hand_raise'\] .*Why: .*no hand "
                                                r".*Give a raise-up-right-hand take whose hand rises from rest"):
        cut_example(example, "tired", "raise-up-right-hand", ["raise-up-right-hand_raise"], {})


@pytest.mark.realdata
@pytest.mark.parametrize("name, fps, cut", [("cmu21_walk", 60.0, {"walk_leftStance": 1, "walk_rightStance": 1}),
                                           ("cmu21_female_walk", 60.0, {"walk_leftStance": 1, "walk_rightStance": 0}),
                                           ("xia_cmu31", 120.0, {"walk_leftStance": 1, "walk_rightStance": 1})])
def test_the_shared_walks_of_other_skeletons_are_cut_into_the_runs_primitives(other_skeleton_paths, name, fps,
                                                                              cut) -> None:
    """Auto-detected joint maps, 60 and 120 fps files; a primitive the example lacks takes its other steps."""
    example = convert_example(parse_example(str(other_skeleton_paths[name])), ConversionSettings())
    assert example.file_fps == fps
    result = cut_example(example, "mine", "walk", PRIMITIVES, {})
    assert {p: len(c) for p, c in result.clips.items()} == cut
    assert result.borrowed == [p for p, n in cut.items() if n == 0]
    assert all(result.used[p] for p in PRIMITIVES)
    # a range that starts later cuts the same steps: the records name the same frames of the file
    later = convert_example(parse_example(f"{other_skeleton_paths[name]}:{int(fps) // 6}-{example.file_frames}"),
                            ConversionSettings())
    cut_later = cut_example(later, "mine", "walk", PRIMITIVES, {})
    for p in PRIMITIVES:
        assert [later.record(c)["file_frames"] for c in cut_later.clips[p]] == \
            [example.record(c)["file_frames"] for c in result.clips[p]]


# -- several examples (issue 27): example=[…]


def test_a_single_value_or_a_list_of_one_is_exactly_the_single_example_path(tmp_path: Path) -> None:
    text = f"{example_bvh(tmp_path, fps=60.0)}:0-200"
    assert parse_examples(text) == [parse_example(text)] == parse_examples([text])
    assert parse_examples([text])[0].key == "example[1]" and parse_examples(text)[0].key == "example"
    example = convert_example(parse_example(text), ConversionSettings())
    one, pooled = cut_example(example, "tired", "walk", PRIMITIVES, {}), cut_examples([example], "tired", "walk",
                                                                                        PRIMITIVES, {})
    assert pooled.used.keys() == one.used.keys()
    for p in PRIMITIVES:
        assert [(c.take, c.primitive, c.start, c.stop) for c in pooled.used[p]] == \
            [(c.take, c.primitive, c.start, c.stop) for c in one.used[p]]
        assert all(np.array_equal(a.frames, b.frames) for a, b in zip(pooled.used[p], one.used[p], strict=True))
    assert pooled.records == one.records and pooled.borrowed == one.borrowed
    assert pooled.origin == {p: [0] * len(one.used[p]) for p in PRIMITIVES}


def test_the_clips_of_several_examples_are_pooled_in_order_with_their_origin(tmp_path: Path) -> None:
    first = convert_example(parse_example(str(example_bvh(tmp_path, fps=60.0))), ConversionSettings())
    second = convert_example(parse_example(f"{example_bvh(tmp_path, 'elderly', fps=30.0)}:0-90"),
                             ConversionSettings())
    cuts = [cut_example(e, "tired", "walk", PRIMITIVES, {}) for e in (first, second)]
    pooled = cut_examples([first, second], "tired", "walk", PRIMITIVES, {})
    for p in PRIMITIVES:
        own = [i for i, cut in enumerate(cuts) for _ in cut.clips[p]]
        if own:  # each example's own clips of p, in order, recorded against its own file
            assert [(c.start, c.stop) for c in pooled.used[p]] == [(c.start, c.stop) for cut in cuts
                                                                 for c in cut.clips[p]]
            assert pooled.origin[p] == own
            assert pooled.records[p] == [e.record(c) for e, cut in zip((first, second), cuts) for c in cut.clips[p]]
    assert [s.rejections for s in pooled.segmentations] == [cut.segmentation.rejections for cut in cuts]
    assert {r["file"] for p in PRIMITIVES for r in pooled.records[p]} == {first.name, second.name}


@pytest.mark.parametrize("items, message", [
    ([], r"example=\[\] is empty"),
    (["a.bvh", "b.bvh:9-3"], r"^example\[2\]=b.bvh:9-3: the frame range 9-3 is empty"),
    (["a.bvh", ""], r"^example\[2\]= is empty"),
    (["a.bvh", 5], r"^example\[2\]=5: each example must be a BVH file"),
    (["a.bvh:0-9", "a.bvh:0-9"], r"^example\[2\]=a.bvh:0-9 is example\[1\] again"),
    ([f"w{i}.bvh" for i in range(MAX_EXAMPLES + 1)], f"lists {MAX_EXAMPLES + 1} examples; at most {MAX_EXAMPLES}"),
])
def test_a_bad_item_of_a_list_is_refused_in_one_line_naming_it(items, message: str) -> None:
    with pytest.raises(StyleExampleError, match=message) as caught:
        parse_examples(items)
    assert "\n" not in str(caught.value)


def test_an_item_whose_file_is_bad_is_named_by_its_place(tmp_path: Path) -> None:
    good = str(example_bvh(tmp_path, fps=60.0))
    [_, missing] = parse_examples([good, str(tmp_path / "nope.bvh")])
    with pytest.raises(StyleExampleError, match=r"^example\[2\]=.*nope.bvh"):
        convert_example(missing, ConversionSettings())
    with pytest.raises(StyleExampleError, match=r"^example\[2\]=.*:0-20: no complete step"):
        cut_examples([convert_example(s, ConversionSettings()) for s in parse_examples([good, f"{good}:0-20"])],
                     "tired", "walk", PRIMITIVES, {})
