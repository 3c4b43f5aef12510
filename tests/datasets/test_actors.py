"""Actor groups by bones and by the files' rest poses, and the actor split (stylemotion.datasets.actors,
``data.split.test_actor``)."""

from __future__ import annotations

import zipfile
from dataclasses import replace
from pathlib import Path

import pytest
from conftest import tiny_bvh_text
from skeleton_takes import skeleton_take, two_actors

from stylemotion.bones import BONE_NAMES
from stylemotion.config import ConfigError
from stylemotion.datasets import TakeSet
from stylemotion.datasets.actors import actor_groups, rest_pose
from stylemotion.io.errors import MotionDataError


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
