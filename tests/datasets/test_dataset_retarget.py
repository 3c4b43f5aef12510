"""``data.retarget`` (every take on one style's bones, stylemotion.datasets.retarget); Bandai's bones and rest poses."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from skeleton_takes import two_actors

from stylemotion.bones import BONE_NAMES, median_bone_lengths
from stylemotion.datasets import Take, data_config_key, load_dataset
from stylemotion.datasets.actors import actor_groups
from stylemotion.datasets.retarget import retarget_takeset
from stylemotion.skeleton import JOINT_INDEX

SYNTHETIC = {"takes_per_pair": 2, "duration_s": 2.0, "contents": ["walk"], "styles": ["normal", "elderly", "active"]}


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
