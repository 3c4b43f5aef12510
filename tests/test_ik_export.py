"""Rotations fitted to joint positions (stylemotion.ik) and BVH export (stylemotion.io.export)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import BANDAI_MEMBERS
from scipy.spatial.transform import Rotation

from stylemotion.datasets.canonical import detect_unit_scale, resolve_joint_map
from stylemotion.datasets.loading import ConversionSettings, load_canonical_positions
from stylemotion.ik import fit_rotations, rest_offsets
from stylemotion.io.bvh import read_bvh
from stylemotion.io.export import positions_to_motion, write_motion_bvh
from stylemotion.io.sources import FileSource
from stylemotion.skeleton import CANONICAL_JOINTS, CANONICAL_PARENTS, JOINT_INDEX, bone_lengths, forward_kinematics

LEAVES = [j for j in range(len(CANONICAL_PARENTS)) if j not in CANONICAL_PARENTS]


def random_skeleton_positions(
    parents: tuple[int, ...], frames: int = 50, seed: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """FK of random local rotations on a skeleton with random fixed bones: (positions, offsets), metres."""
    rng = np.random.default_rng(seed)
    num_joints = len(parents)
    offsets = rng.normal(size=(num_joints, 3))
    offsets *= rng.uniform(0.05, 0.4, (num_joints, 1)) / np.linalg.norm(offsets, axis=1, keepdims=True)
    rotations = Rotation.random(frames * num_joints, random_state=seed).as_matrix().reshape(frames, num_joints, 3, 3)
    translations = np.repeat(offsets[None], frames, axis=0)
    translations[:, parents.index(-1)] = rng.normal(size=(frames, 3))
    return forward_kinematics(rotations, translations, parents), offsets


def mpjpe(a: np.ndarray, b: np.ndarray) -> float:
    """Mean per-joint position error, metres."""
    return float(np.linalg.norm(a - b, axis=-1).mean())


def reimport(path: Path) -> np.ndarray:
    """The project's own loader, as stylemotion-convert uses it."""
    return load_canonical_positions(FileSource(str(path)), ConversionSettings(fps=30.0))


# ---------------------------------------------------------------------------------------------
# (a) exact fit of a rigid skeleton


def test_fit_reproduces_rigid_skeleton_exactly() -> None:
    positions, _ = random_skeleton_positions(CANONICAL_PARENTS)
    fit = fit_rotations(positions.astype(np.float32))
    assert fit.local_rotations.shape == (50, 21, 3, 3) and fit.root_translation.shape == (50, 3)
    np.testing.assert_allclose(fit.positions(), positions, atol=1e-5)
    np.testing.assert_allclose(fit_rotations(positions).positions(), positions, atol=1e-9)
    # Proper rotations; leaves are the identity.
    np.testing.assert_allclose(np.linalg.det(fit.local_rotations), 1.0, atol=1e-9)
    np.testing.assert_allclose(fit.local_rotations[:, LEAVES], np.broadcast_to(np.eye(3), (50, len(LEAVES), 3, 3)),
                               atol=1e-12)


def test_single_child_joints_get_pure_swings() -> None:
    positions, _ = random_skeleton_positions(CANONICAL_PARENTS, seed=1)
    fit = fit_rotations(positions)
    for joint in range(21):
        kids = [c for c, p in enumerate(CANONICAL_PARENTS) if p == joint]
        if len(kids) != 1:
            continue
        rest = fit.offsets[kids[0]] / np.linalg.norm(fit.offsets[kids[0]])
        rotvec = Rotation.from_matrix(fit.local_rotations[:, joint]).as_rotvec()
        assert np.abs(rotvec @ rest).max() < 1e-9, CANONICAL_JOINTS[joint]  # no twist about the bone


def test_given_offsets_and_any_tree() -> None:
    positions, offsets = random_skeleton_positions(CANONICAL_PARENTS, seed=2)
    np.testing.assert_allclose(fit_rotations(positions, offsets=offsets).positions(), positions, atol=1e-9)
    parents = (-1, 0, 1, 1, 0, 4, 2, 6)  # a root with two children, a joint with two children, chains
    positions, _ = random_skeleton_positions(parents, seed=3)
    np.testing.assert_allclose(fit_rotations(positions, parents).positions(), positions, atol=1e-9)


def test_rest_pose_is_an_upright_t_pose() -> None:
    positions, _ = random_skeleton_positions(CANONICAL_PARENTS, seed=4)
    offsets = rest_offsets(positions)
    np.testing.assert_allclose(np.linalg.norm(offsets, axis=1)[1:], np.median(bone_lengths(positions), axis=0)[1:])
    unit = offsets / np.maximum(np.linalg.norm(offsets, axis=1, keepdims=True), 1e-12)
    for name, axis in [("Spine", 1), ("Neck", 1), ("Head", 1), ("LowerArm_L", 0), ("Toes_R", 2)]:
        assert unit[JOINT_INDEX[name], axis] == pytest.approx(1.0), name
    assert unit[JOINT_INDEX["LowerArm_R"], 0] == pytest.approx(-1.0)
    assert unit[JOINT_INDEX["Foot_L"], 1] == pytest.approx(-1.0)
    assert offsets[JOINT_INDEX["UpperLeg_L"], 0] > 0 > offsets[JOINT_INDEX["UpperLeg_R"], 0]  # left is +X
    assert offsets[JOINT_INDEX["Shoulder_L"], 0] > 0 > offsets[JOINT_INDEX["Shoulder_R"], 0]


# ---------------------------------------------------------------------------------------------
# (b), (c) real data through the project's own loader


@pytest.fixture(scope="module")
def bandai_positions(bandai_zip_path: Path) -> np.ndarray:
    return load_canonical_positions(FileSource(str(bandai_zip_path), BANDAI_MEMBERS[0]), ConversionSettings(fps=30.0))


@pytest.mark.realdata
def test_bandai_take_round_trips_through_the_loader(bandai_positions: np.ndarray, tmp_path: Path) -> None:
    path = tmp_path / "out" / "walk.bvh"
    written = write_motion_bvh(bandai_positions, path, fps=30.0)
    assert written.num_frames == bandai_positions.shape[0]
    motion = read_bvh(path)
    assert motion.skeleton.names == list(CANONICAL_JOINTS) and motion.fps == 30.0
    assert motion.skeleton.channels[JOINT_INDEX["Hips"]] == ["Xposition", "Yposition", "Zposition",
                                                    "Zrotation", "Xrotation", "Yrotation"]
    assert sorted(motion.skeleton.end_sites) == sorted(LEAVES)
    joint_map = resolve_joint_map(None, motion)  # auto-detection picks the identity (Bandai) map, metres
    assert joint_map.name == "bandai" and detect_unit_scale(motion, joint_map) == 1.0
    back = reimport(path)
    assert back.shape == bandai_positions.shape
    error = mpjpe(back, bandai_positions)
    print(f"Bandai {BANDAI_MEMBERS[0]}: export -> re-import MPJPE {error * 1000:.4f} mm")
    assert error <= 0.01


@pytest.mark.realdata
def test_bone_length_jitter_is_absorbed(bandai_positions: np.ndarray, tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    source = bandai_positions.astype(np.float64)
    jittered = source.copy()
    for joint, parent in enumerate(CANONICAL_PARENTS):
        if parent >= 0:  # each bone's length changes by up to ±1 cm, independently per frame
            bone = source[:, joint] - source[:, parent]
            length = np.linalg.norm(bone, axis=-1, keepdims=True)
            jittered[:, joint] = jittered[:, parent] + bone * (1 + rng.uniform(-0.01, 0.01, length.shape) / length)
    assert np.abs(bone_lengths(jittered) - bone_lengths(source)).max() > 0.009
    path = tmp_path / "jitter.bvh"
    write_motion_bvh(jittered.astype(np.float32), path, fps=30.0)
    back = reimport(path)
    error = mpjpe(back, jittered)
    print(f"Bandai {BANDAI_MEMBERS[0]} with ±1 cm bone jitter: re-import MPJPE {error * 1000:.2f} mm")
    assert error <= 0.02
    lengths = bone_lengths(back)
    assert lengths.std(axis=0).max() < 1e-5  # constant bones in the file
    np.testing.assert_allclose(lengths[0, 1:], np.median(bone_lengths(jittered), axis=0)[1:], atol=1e-5)


# ---------------------------------------------------------------------------------------------
# (d) bad input


def test_bad_input_is_named(tmp_path: Path) -> None:
    positions, _ = random_skeleton_positions(CANONICAL_PARENTS, frames=10, seed=5)
    with pytest.raises(ValueError, match=r"shape \(frames, 21, 3\).*\(10, 20, 3\)"):
        fit_rotations(positions[:, :20])
    with pytest.raises(ValueError, match=r"shape \(frames, 21, 3\).*\(21, 3\)"):
        positions_to_motion(positions[0], fps=30.0)
    bad = positions.copy()
    bad[3, JOINT_INDEX["Hand_L"], 1] = np.nan
    with pytest.raises(ValueError, match=r"NaN.*frame 3, joint 'Hand_L'"):
        fit_rotations(bad)
    bad = positions.copy()
    bad[5:7, JOINT_INDEX["Hand_L"]] = bad[5:7, JOINT_INDEX["LowerArm_L"]]
    with pytest.raises(ValueError, match=r"'LowerArm_L'→'Hand_L' has zero length.*2 frame\(s\), first at frame 5"):
        write_motion_bvh(bad, tmp_path / "never-written.bvh", fps=30.0)
    assert not any(tmp_path.iterdir())
    with pytest.raises(ValueError, match="fps"):
        positions_to_motion(positions, fps=0.0)
    with pytest.raises(ValueError, match=r"offsets must have shape \(21, 3\)"):
        fit_rotations(positions, offsets=np.ones((20, 3)))
    zero_bone = rest_offsets(positions)
    zero_bone[JOINT_INDEX["Toes_R"]] = 0.0
    with pytest.raises(ValueError, match=r"offsets: bone 'Foot_R'→'Toes_R' has zero length"):
        fit_rotations(positions, offsets=zero_bone)
