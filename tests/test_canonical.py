"""Any skeleton → canonical 21-joint positions in metres, Y up, at 30 fps."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import yaml
from conftest import BANDAI_MEMBERS, OTHER_SKELETONS

from stylemotion.datasets.canonical import (
    UNIT_SCALES,
    JointMap,
    builtin_joint_maps,
    detect_unit_scale,
    resolve_joint_map,
    source_indices,
    to_canonical_positions,
)
from stylemotion.io.bvh import parse_bvh, read_bvh
from stylemotion.io.errors import MotionDataError
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX, bone_lengths

pytestmark = pytest.mark.realdata

EXPECTED = {
    # name → (joint map, unit)
    "bandai": ("bandai", "cm"),
    "cmu21_walk": ("cmu21", "cm"),
    "cmu21_female_walk": ("cmu21", "cm"),
    "xia_cmu31": ("cmu31", "cmu"),
}
FEET = [JOINT_INDEX[n] for n in ("Foot_L", "Foot_R", "Toes_L", "Toes_R")]


@pytest.fixture(scope="module")
def motions(other_skeleton_paths, bandai_zip):
    out = {name: read_bvh(path) for name, path in other_skeleton_paths.items()}
    member = BANDAI_MEMBERS[0]
    out["bandai"] = parse_bvh(bandai_zip.read(member), f"{bandai_zip.filename}::{member}")
    return out


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_auto_detected_joint_map_and_unit(motions, name):
    motion = motions[name]
    map_name, unit = EXPECTED[name]
    jm = resolve_joint_map(None, motion)
    assert jm.name == map_name
    assert detect_unit_scale(motion, jm) == UNIT_SCALES[unit]


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_plausible_heights(motions, name):
    pos = to_canonical_positions(motions[name])
    assert pos.dtype == np.float32 and pos.shape[1:] == (21, 3)
    head = pos[:, JOINT_INDEX["Head"], 1]
    assert 1.2 <= head.min() and head.max() <= 1.9, (head.min(), head.max())
    lowest_foot = pos[:, FEET, 1].min()
    assert abs(lowest_foot) <= 0.15, lowest_foot
    # Hips between feet and head in every frame: the up axis is right.
    assert np.all(pos[:, JOINT_INDEX["Hips"], 1] > pos[:, FEET, 1].max(axis=1))
    assert np.all(pos[:, JOINT_INDEX["Hips"], 1] < head)


def test_xia_maps_neck_not_neck1(motions):
    motion = motions["xia_cmu31"]
    jm = resolve_joint_map(None, motion)
    idx = source_indices(motion, jm)
    assert motion.skeleton.names[idx[JOINT_INDEX["Neck"]]] == "Neck"
    assert [motion.skeleton.names[i] for i in idx] == [jm.joints[c] for c in CANONICAL_JOINTS]


@pytest.mark.parametrize(
    ("scale", "unit"), [(0.01, "m"), (10.0, "mm"), (1 / 2.54, "inch")]
)
def test_unit_detection_follows_the_skeleton_size(motions, scale, unit):
    """The same cm skeleton rescaled to other units is detected as those units."""
    motion = motions["bandai"]
    scaled = replace(
        motion,
        skeleton=replace(motion.skeleton, offsets=motion.skeleton.offsets * scale),
        translations=motion.translations * scale,
    )
    jm = resolve_joint_map(None, scaled)
    assert detect_unit_scale(scaled, jm) == UNIT_SCALES[unit]
    np.testing.assert_allclose(to_canonical_positions(scaled), to_canonical_positions(motion), atol=1e-5)


@pytest.mark.parametrize(("name", "step"), [("cmu21_walk", 2), ("cmu21_female_walk", 2), ("xia_cmu31", 4)])
def test_resampled_to_30_fps(motions, name, step):
    motion = motions[name]
    assert motion.fps == OTHER_SKELETONS[name][2]
    pos30 = to_canonical_positions(motion, fps=30.0)
    # 30 fps samples fall on every `step`-th original frame, the last at or before the end.
    expected_frames = len(range(0, motion.num_frames, step))
    assert pos30.shape[0] == expected_frames
    native = to_canonical_positions(motion, fps=None)
    assert native.shape[0] == motion.num_frames
    err = np.abs(pos30 - native[::step]).max()
    assert err <= 1e-3, f"{name}: 30 fps positions differ from the originals by {err} m"
    resampled = motion.resample(30.0)
    assert resampled.fps == 30.0 and resampled.num_frames == expected_frames


@pytest.mark.parametrize("name", ["cmu21_walk", "xia_cmu31"])
def test_slerp_resampling_keeps_bones_rigid(motions, name):
    """Between samples, slerp keeps every bone length; naive position blending does not."""
    motion = motions[name]
    fps = motion.fps * 0.4  # 60 → 24, 120 → 48: new samples fall half-way between originals
    assert not any(c.endswith("position") for ch in motion.skeleton.channels[1:] for c in ch)
    scale = detect_unit_scale(motion, resolve_joint_map(None, motion))
    resampled_motion = motion.resample(fps)
    assert resampled_motion.num_frames == len(np.arange(0, motion.duration + 1e-9, 1 / fps))
    resampled = resampled_motion.global_positions() * scale  # all joints, metres
    native = motion.global_positions() * scale
    parents = tuple(int(p) for p in motion.skeleton.parents)
    ref_lengths = bone_lengths(native[0], parents)
    np.testing.assert_allclose(bone_lengths(resampled, parents), np.broadcast_to(
        ref_lengths, resampled.shape[:2]), atol=1e-9)
    # Sample k sits at original frame 2.5 k: odd k are half-way between frames.
    k = np.arange(1, resampled.shape[0], 2)
    lo = (k * 5) // 2
    naive = 0.5 * (native[lo] + native[lo + 1])
    naive_lengths = bone_lengths(naive, parents)
    assert (ref_lengths - naive_lengths).max() > 1e-4  # blending positions shortens bones
    # ...but the slerped pose is close to it (the right neighbouring frames were used).
    assert np.abs(resampled[k] - naive).max() < 0.01
    # Even samples land on original frames exactly.
    np.testing.assert_allclose(resampled[::2], native[::5][: len(resampled[::2])], atol=1e-9)
    # The canonical pipeline uses the same resampling.
    canonical = to_canonical_positions(motion, fps=fps)
    idx = source_indices(motion, resolve_joint_map(None, motion))
    np.testing.assert_allclose(canonical, resampled[:, idx], atol=1e-5)


def test_one_frame_motion_resamples(motions):
    motion = motions["xia_cmu31"]
    single = replace(motion, rotations=motion.rotations[:1], translations=motion.translations[:1])
    out = single.resample(30.0)
    assert out.fps == 30.0 and out.num_frames == 1


def _rename_joint(text: str, old: str, new: str) -> str:
    return text.replace(f"JOINT {old}\n", f"JOINT {new}\n").replace(f"JOINT {old}\r\n", f"JOINT {new}\r\n")


def test_missing_canonical_joint_is_named(bandai_zip):
    member = BANDAI_MEMBERS[2]
    text = _rename_joint(bandai_zip.read(member).decode(), "Toes_L", "ToeTip_L")
    motion = parse_bvh(text, "renamed.bvh")
    with pytest.raises(MotionDataError, match="Toes_L") as err:
        to_canonical_positions(motion, joint_map="bandai")
    assert "renamed.bvh" in str(err.value)
    # Auto-detection reports, per built-in map, what is missing.
    with pytest.raises(MotionDataError, match="no built-in joint map fits") as err:
        to_canonical_positions(motion)
    assert "bandai: missing ['Toes_L']" in str(err.value)


def test_custom_joint_map_yaml(motions, tmp_path):
    motion = motions["xia_cmu31"]
    joints = dict(builtin_joint_maps()["cmu31"].joints)
    joints.update({"Neck": "Neck1", "Chest": "Spine", "Spine": "LowerBack"})
    path = tmp_path / "my_xia.yaml"
    path.write_text(yaml.safe_dump({"name": "my_xia", "joints": joints}))
    jm = JointMap.from_yaml(path)
    assert jm.name == "my_xia"
    pos = to_canonical_positions(motion, joint_map=str(path), fps=None, unit_scale="cmu")
    fk = motion.global_positions() * UNIT_SCALES["cmu"]
    names = motion.skeleton.names
    for canonical in ("Neck", "Chest", "Spine", "Head"):
        np.testing.assert_allclose(pos[:, JOINT_INDEX[canonical]], fk[:, names.index(joints[canonical])], atol=1e-5)
    builtin = to_canonical_positions(motion, fps=None)
    assert np.abs(pos[:, JOINT_INDEX["Neck"]] - builtin[:, JOINT_INDEX["Neck"]]).max() > 0.01
    # A mapping works the same as its YAML file.
    np.testing.assert_array_equal(to_canonical_positions(motion, joint_map=joints, fps=None), pos)


def test_custom_joint_map_yaml_errors(motions, tmp_path):
    joints = dict(builtin_joint_maps()["cmu31"].joints)
    del joints["Hand_R"]
    path = tmp_path / "incomplete.yaml"
    path.write_text(yaml.safe_dump({"name": "incomplete", "joints": joints}))
    with pytest.raises(MotionDataError, match="Hand_R"):
        JointMap.from_yaml(path)
    joints["Hand_R"] = "RightHand"
    joints["Tail"] = "Hips"
    path.write_text(yaml.safe_dump({"joints": joints}))
    with pytest.raises(MotionDataError, match="Tail"):
        JointMap.from_yaml(path)
    bad = tmp_path / "broken.yaml"
    bad.write_text("joints: [Hips")
    with pytest.raises(MotionDataError, match="broken.yaml"):
        JointMap.from_yaml(bad)
    # A YAML whose source names are not in the skeleton names them.
    joints.pop("Tail")
    joints["Head"] = "Skull"
    path.write_text(yaml.safe_dump({"name": "skull", "joints": joints}))
    with pytest.raises(MotionDataError, match="Skull"):
        to_canonical_positions(motions["xia_cmu31"], joint_map=str(path))


def test_unknown_joint_map_name(motions):
    with pytest.raises(MotionDataError, match="unknown joint map"):
        to_canonical_positions(motions["bandai"], joint_map="lafan")


def test_unit_names(motions):
    motion = motions["bandai"]
    with pytest.raises(MotionDataError, match="furlong") as err:
        to_canonical_positions(motion, unit_scale="furlong")
    assert "cm" in str(err.value)  # lists the known units
    for bad in (0.0, -0.01, float("nan")):
        with pytest.raises(MotionDataError, match="unit_scale"):
            to_canonical_positions(motion, unit_scale=bad)
    cm = to_canonical_positions(motion, unit_scale="cm")
    np.testing.assert_array_equal(cm, to_canonical_positions(motion))
    np.testing.assert_allclose(
        to_canonical_positions(motion, unit_scale=0.02, fps=None),
        2 * to_canonical_positions(motion, unit_scale="cm", fps=None), rtol=1e-6,
    )


def test_z_up_input(motions):
    """The same motion stored Z up gives the same canonical positions with up_axis='z'."""
    motion = motions["cmu21_walk"]
    to_z_up = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])  # (x, y, z) → (x, -z, y)
    from scipy.spatial.transform import Rotation

    rot = motion.rotations.copy()
    rot[:, 0] = (Rotation.from_matrix(to_z_up) * Rotation.from_quat(rot[:, 0])).as_quat()
    trans = motion.translations.copy()
    trans[:, 0] = trans[:, 0] @ to_z_up.T
    z_up = replace(motion, rotations=rot, translations=trans)
    assert np.abs(z_up.global_positions()[:, :, 2] - motion.global_positions()[:, :, 1]).max() < 1e-9
    np.testing.assert_allclose(to_canonical_positions(z_up, up_axis="z"), to_canonical_positions(motion),
                               atol=1e-5)
    with pytest.raises(MotionDataError, match="up_axis"):
        to_canonical_positions(motion, up_axis="x")


def _z_up(motion):
    """``motion`` turned so that its body stands along +Z (a Z-up file)."""
    to_z_up = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])
    from scipy.spatial.transform import Rotation

    rot = motion.rotations.copy()
    rot[:, 0] = (Rotation.from_matrix(to_z_up) * Rotation.from_quat(rot[:, 0])).as_quat()
    trans = motion.translations.copy()
    trans[:, 0] = trans[:, 0] @ to_z_up.T
    return replace(motion, rotations=rot, translations=trans)


def test_z_up_file_read_as_y_up_warns_naming_it(motions):
    import warnings

    from stylemotion.io.errors import MotionDataWarning

    with warnings.catch_warnings():
        warnings.simplefilter("error", MotionDataWarning)
        for motion in motions.values():  # upright real files, declared right: quiet
            to_canonical_positions(motion)
        to_canonical_positions(_z_up(motions["cmu21_walk"]), up_axis="z")
    z_up = _z_up(motions["cmu21_walk"])
    with pytest.warns(MotionDataWarning) as record:
        lying = to_canonical_positions(z_up)
    (message,) = [str(w.message) for w in record if issubclass(w.category, MotionDataWarning)]
    assert message.startswith(f"{z_up.source}: read as Y-up") and "set data.up_axis=z" in message
    head_over_feet = lying[:, JOINT_INDEX["Head"]] - lying[:, FEET[:2]].mean(axis=1)
    assert np.median(head_over_feet[:, 2]) > 1.0  # the warning is right: the body lies along Z


def test_positions_that_overflow_are_an_error_naming_the_file(motions):
    motion = motions["cmu21_walk"]
    huge = replace(motion, translations=motion.translations * 1e306)
    with pytest.raises(MotionDataError) as err:
        to_canonical_positions(huge, unit_scale=1000.0)
    assert str(err.value).startswith(f"{motion.source}: joint positions overflow to inf/NaN (frame 0")
    with pytest.raises(MotionDataError, match="overflow to inf/NaN .* in float32"):
        to_canonical_positions(replace(motion, translations=motion.translations * 1e38), unit_scale=1.0)


def test_resampled_length_is_limited_before_resampling(motions, monkeypatch):
    from stylemotion.io.errors import LimitError
    from stylemotion.motion import Motion

    slow = replace(motions["cmu21_walk"], fps=1e-4)  # a Frame Time of 10000 s
    expected = slow.resampled_length(30.0)
    monkeypatch.setattr(Motion, "resample", lambda self, fps: pytest.fail("resampled before the check"))
    with pytest.raises(LimitError) as err:
        to_canonical_positions(slow)
    assert f"would be {expected} frames, more than the limit data.max_frames=324000" in str(err.value)
    assert str(err.value).startswith(f"{slow.source}: ")
    endless = replace(motions["cmu21_walk"], fps=1e-308)  # Frame Time 1e308 s: an infinite duration
    with pytest.raises(LimitError, match="would be infinitely many frames"):
        to_canonical_positions(endless)
    with pytest.raises(LimitError, match=r"data\.max_joint_frames=1000 "):
        to_canonical_positions(motions["cmu21_walk"], max_joint_frames=1000)
    monkeypatch.undo()
    assert to_canonical_positions(motions["cmu21_walk"], fps=30.0).shape[0] == \
        motions["cmu21_walk"].resampled_length(30.0)
