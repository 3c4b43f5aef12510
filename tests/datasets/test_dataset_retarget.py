"""``data.retarget`` (every take on one style's bones) and actor groups (stylemotion.datasets.retarget)."""

from __future__ import annotations

import zipfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from conftest import tiny_bvh_text

from stylemotion.bones import BONE_NAMES, NUM_BONES, median_bone_lengths
from stylemotion.config import ConfigError
from stylemotion.datasets import Take, TakeSet, data_config_key, load_dataset
from stylemotion.datasets.actors import actor_groups, rest_pose
from stylemotion.datasets.retarget import retarget_takeset
from stylemotion.io.errors import MotionDataError
from stylemotion.skeleton import CANONICAL_PARENTS, JOINT_INDEX, NUM_JOINTS, forward_kinematics

SYNTHETIC = {"takes_per_pair": 2, "duration_s": 2.0, "contents": ["walk"], "styles": ["normal", "elderly", "active"]}


def skeleton_take(name: str, style: str, scale: np.ndarray | float = 1.0, frames: int = 12) -> Take:
    """A take of a fixed pose drifting forward, on a rest skeleton whose bones are multiplied by ``scale``."""
    rng = np.random.default_rng(0)
    offsets = rng.normal(size=(NUM_JOINTS, 3)) * 0.1
    offsets[1:] *= np.broadcast_to(scale, (NUM_BONES,))[:, None]
    translations = np.repeat(offsets[None], frames, axis=0)
    translations[:, 0] = np.stack([np.zeros(frames), np.full(frames, 1.0), 0.04 * np.arange(frames)], axis=-1)
    rotations = np.broadcast_to(np.eye(3), (frames, NUM_JOINTS, 3, 3))
    positions = forward_kinematics(rotations, translations, CANONICAL_PARENTS).astype(np.float32)
    return Take(name, positions, 30.0, {"content": "walk", "style": style}, source=f"<memory:{name}>")


def two_actors() -> TakeSet:
    """Styles normal and masculine on skeleton A (one take 0.4 mm off), feminine on B (one bone 5 % longer)."""
    b = np.ones(NUM_BONES)
    b[BONE_NAMES.index("LowerLeg_L")] = 1.05
    jitter = np.ones(NUM_BONES)
    jitter[BONE_NAMES.index("Spine")] += 0.0004 / float(median_bone_lengths(skeleton_take("x", "x").positions)[0])
    takes = [skeleton_take("a_normal_0", "normal"), skeleton_take("a_normal_1", "normal", jitter),
             skeleton_take("a_masculine_0", "masculine"), skeleton_take("b_feminine_0", "feminine", b),
             skeleton_take("b_feminine_1", "feminine", b)]
    return TakeSet("two_actors", sorted(takes, key=lambda t: t.name), 30.0)


def spread_mm(takes: list[Take]) -> float:
    """Largest range over takes of any bone's median length, millimetres."""
    return float(np.ptp(np.stack([median_bone_lengths(t.positions) for t in takes]), axis=0).max() * 1000)


def test_two_skeletons_become_the_target_styles_skeleton() -> None:
    original = two_actors()
    assert spread_mm(original.takes) > 5
    retargeted = retarget_takeset(original, "feminine")
    target = median_bone_lengths(original.filter(style="feminine")[0].positions)
    for take in retargeted.takes:
        np.testing.assert_allclose(median_bone_lengths(take.positions), target, atol=1e-6)
    assert spread_mm(retargeted.takes) < 1e-3
    assert [(t.name, t.labels, t.source) for t in retargeted.takes] == \
        [(t.name, t.labels, t.source) for t in original.takes]
    assert retargeted.retarget["style"] == "feminine" and retargeted.retarget["takes"] == 2
    assert list(retargeted.retarget["bone_lengths_m"]) == list(BONE_NAMES)
    assert retargeted.retarget["bone_lengths_m"]["LowerLeg_L"] == pytest.approx(target[BONE_NAMES.index("LowerLeg_L")],
                                                                               abs=1e-6)
    assert original.retarget is None and retarget_takeset(original, None) is original


def test_every_dataset_kind_is_retargeted_by_load_dataset() -> None:
    """Synthetic takes vary body size per take; ``retarget=normal`` puts them all on normal's median bones."""
    original = load_dataset("synthetic", **SYNTHETIC)
    assert spread_mm(original.takes) > 10
    retargeted = load_dataset("synthetic", retarget="normal", **SYNTHETIC)
    assert spread_mm(retargeted.takes) < 1e-3
    normal = np.median([median_bone_lengths(t.positions) for t in original.filter(style="normal")], axis=0)
    np.testing.assert_allclose(median_bone_lengths(retargeted.takes[0].positions), normal, atol=1e-6)
    assert len(actor_groups(original.takes).styles) > 1  # body size varies per synthetic take
    assert list(actor_groups(retargeted.takes).styles.values()) == [["active", "elderly", "normal"]]
    assert retargeted.retarget["style"] == "normal" and retargeted.retarget["takes"] == 2


def test_null_retarget_is_the_original_data_and_hashes_as_before() -> None:
    original = load_dataset("synthetic", **SYNTHETIC)
    same = load_dataset("synthetic", retarget=None, **SYNTHETIC)
    assert all(np.array_equal(a.positions, b.positions) for a, b in zip(original.takes, same.takes))
    assert same.retarget is None
    before = {"name": "bandai", "root": "data.zip", "max_frames": 10}
    assert data_config_key({**before, "retarget": None}) == before
    assert data_config_key({**before, "retarget": "normal"}) == {**before, "retarget": "normal"}


@pytest.mark.parametrize("value, message", [
    ("sleepy", r"data.retarget='sleepy' is not a style of dataset 'synthetic'; its styles are "
               r"\['active', 'elderly', 'normal'\]"),
    ("", "data.retarget must be a style name"),
    (3, "data.retarget must be a style name .* got 3"),
])
def test_a_bad_target_is_refused_naming_the_styles(value, message) -> None:
    with pytest.raises(ValueError, match=message):
        load_dataset("synthetic", retarget=value, **SYNTHETIC)


def test_retarget_is_a_valid_option_of_every_dataset() -> None:
    with pytest.raises(KeyError, match=r"valid options: \[.*'retarget'.*\]"):
        load_dataset("synthetic", colour="red")
    with pytest.raises(KeyError, match=r"valid options: \[.*'retarget'.*\]"):
        load_dataset("bvh_folder", root=".", colour="red")


def test_actor_groups_by_bone_lengths() -> None:
    groups = actor_groups(two_actors().takes)
    assert groups.styles == {0: ["masculine", "normal"], 1: ["feminine"]}
    assert groups.takes == {"a_masculine_0": 0, "a_normal_0": 0, "a_normal_1": 0, "b_feminine_0": 1, "b_feminine_1": 1}
    legs = {g: lengths[BONE_NAMES.index("LowerLeg_L")] for g, lengths in groups.bone_lengths.items()}
    assert legs[1] == pytest.approx(1.05 * legs[0], rel=1e-5)
    strict = actor_groups(list(reversed(two_actors().takes)), tolerance_m=0.0001)  # order does not matter
    assert strict.styles == {0: ["masculine", "normal"], 1: ["normal"], 2: ["feminine"]}
    assert strict.takes["a_normal_1"] == 1 and strict.takes["a_normal_0"] == 0
    assert actor_groups([]).styles == {} and actor_groups(two_actors().takes[:1]).takes == {"a_masculine_0": 0}
    with pytest.raises(ValueError, match="tolerance_m must be a number of metres ≥ 0, got -1"):
        actor_groups(two_actors().takes, tolerance_m=-1)


def test_actor_groups_split_one_set_of_bones_by_the_files_rest_poses(tmp_path: Path) -> None:
    """Bandai's case: equal bones in every file, one rest offset per actor (here the root's), read from the files
    (a loose file and a zip member) without their frames."""
    moved = tiny_bvh_text().replace("OFFSET 0.0 0.0 0.0", "OFFSET 4.5 91.5 -427.2", 1)
    (tmp_path / "a.bvh").write_text(tiny_bvh_text())
    with zipfile.ZipFile(tmp_path / "data.zip", "w") as archive:
        archive.writestr("b.bvh", moved)
        archive.writestr("c.bvh", tiny_bvh_text())
    sources = {"a_normal_0": str(tmp_path / "a.bvh"), "b_feminine_0": f"{tmp_path / 'data.zip'}::b.bvh",
               "c_masculine_0": f"{tmp_path / 'data.zip'}::c.bvh", "d_elderly_0": "<memory:d>"}
    takes = [replace(skeleton_take(name, name.split("_")[1]), source=source) for name, source in sources.items()]
    assert rest_pose(takes[0]) == rest_pose(takes[2]) != rest_pose(takes[1]) and rest_pose(takes[3]) is None
    assert rest_pose(takes[1])[:3] == (4.5, 91.5, -427.2)
    # "MOTION" in a joint's name, in a hierarchy longer than one read: the read stops early, then reads on
    chain = "".join(f"JOINT J{i}{'MOTION' if i == 1 else ''}\n{{\nOFFSET 0 {i % 7} 1\nCHANNELS 3 Zrotation Xrotation "
                    f"Yrotation\n" for i in range(3000))
    long = (f"HIERARCHY\nROOT R\n{{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n{chain}"
            f"End Site\n{{\nOFFSET 0 1 0\n}}\n" + "}\n" * 3001 + f"MOTION\nFrames: 1\nFrame Time: 0.1\n{'0 ' * 9003}\n")
    assert len(long.split("MOTION\nFrames")[0]) > 1 << 16
    (tmp_path / "long.bvh").write_text(long)
    pose = rest_pose(replace(takes[0], source=str(tmp_path / "long.bvh")))
    assert len(pose) == 3 * 3001 and pose[3 * 5:3 * 6] == (0.0, 4.0, 1.0)
    groups = actor_groups(takes)
    assert groups.styles == {0: ["masculine", "normal"], 1: ["feminine"], 2: ["elderly"]}
    assert groups.rest_poses[1] == rest_pose(takes[1]) and groups.rest_poses[2] is None
    assert actor_groups(takes, rest_poses=False).styles == {0: ["elderly", "feminine", "masculine", "normal"]}
    (tmp_path / "a.bvh").unlink()
    with pytest.raises(MotionDataError, match="a.bvh"):
        actor_groups(takes)


def test_the_actor_split_tests_on_every_take_of_the_named_styles_actor(tmp_path: Path) -> None:
    """``data.split.test_actor``: the actor who performed the style (by rest pose) is the test split, all of their
    styles; the other actor's takes split into train and val; a style that is not there, or an actor who is every
    take, is refused naming the key."""
    moved = tiny_bvh_text().replace("OFFSET 0.0 0.0 0.0", "OFFSET 4.5 91.5 -427.2", 1)
    (tmp_path / "a.bvh").write_text(tiny_bvh_text())
    (tmp_path / "b.bvh").write_text(moved)
    names = [f"{style}_{i}" for style in ("normal", "masculine", "feminine", "youthful") for i in range(4)]
    takes = [replace(skeleton_take(n, n.split("_")[0]),
                     source=str(tmp_path / ("b.bvh" if n.startswith(("feminine", "youthful")) else "a.bvh")))
             for n in names]
    data = TakeSet("actors", sorted(takes, key=lambda t: t.name), 30.0)
    parts = data.split(seed=3, val_fraction=0.25, test_fraction=0.5, test_actor="youthful")
    assert {t.style for t in parts["test"]} == {"feminine", "youthful"} and len(parts["test"]) == 8
    assert {t.style for t in parts["train"] + parts["val"]} == {"masculine", "normal"}
    assert sorted(t.name for p in parts.values() for t in p) == sorted(names)
    assert len(parts["val"]) == 2 and parts == data.split(seed=3, val_fraction=0.25, test_actor="youthful")
    with pytest.raises(ConfigError, match=r"data.split.test_actor must name a style .* got 'sleepy'.*'youthful'"):
        data.split(test_actor="sleepy")
    alone = TakeSet("one", [t for t in data.takes if t.style in ("feminine", "youthful")], 30.0)
    with pytest.raises(ConfigError, match="every take of dataset 'one' is that actor's"):
        alone.split(test_actor="feminine")


@pytest.mark.realdata
def test_bandai_walks_share_one_set_of_bones_and_three_rest_poses(bandai_zip_path: Path, tmp_path: Path) -> None:
    """Bandai dataset-2's three actors (active/elderly/exhausted, feminine/youthful, masculine/normal): the bone
    lengths are the same in all files (``retarget`` moves no joint by more than float32 rounding here), and each
    actor's files name their own rest position of the Hips (overridden by its position channels): actor groups
    come from the rest poses."""
    walks = load_dataset("bandai", root=bandai_zip_path, contents=["walk"], cache_dir=tmp_path, workers=1)
    assert actor_groups(walks.takes).styles == {0: ["active", "elderly", "exhausted"], 1: ["feminine", "youthful"],
                                                2: ["masculine", "normal"]}
    groups = actor_groups(walks.takes, rest_poses=False)
    assert groups.styles == {0: ["active", "elderly", "exhausted", "feminine", "masculine", "normal", "youthful"]}
    assert spread_mm(walks.takes) < 0.001
    assert median_bone_lengths(walks.takes[0].positions)[BONE_NAMES.index("LowerLeg_L")] == pytest.approx(0.3908,
                                                                                                         abs=1e-4)
    retargeted = retarget_takeset(walks, "normal")
    moved = max(float(np.abs(a.positions - b.positions).max()) for a, b in zip(walks.takes, retargeted.takes))
    assert moved < 1e-5
    assert retargeted.takes[0].positions[:, JOINT_INDEX["Hips"], 1].mean() > 0.8


@pytest.mark.realdata
def test_the_cache_key_does_not_depend_on_retarget(bandai_zip_path: Path, tmp_path: Path) -> None:
    """The cache holds the converted takes; retargeting happens after it, so null, absent and a style
    all use the one entry."""
    options = {"root": bandai_zip_path, "contents": ["walk"], "styles": ["normal", "elderly"], "cache_dir": tmp_path,
               "workers": 1}
    first = load_dataset("bandai", **options)
    entries = sorted(tmp_path.iterdir())
    assert len(entries) == 1
    same = load_dataset("bandai", retarget=None, **options)
    load_dataset("bandai", retarget="elderly", **options)
    assert sorted(tmp_path.iterdir()) == entries
    assert all(np.array_equal(a.positions, b.positions) for a, b in zip(first.takes, same.takes))
