"""Retargeting canonical positions to other bone lengths (stylemotion.bones)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from stylemotion.bones import (
    BONE_JOINTS,
    BONE_NAMES,
    NUM_BONES,
    leg_length,
    median_bone_lengths,
    place_bones,
    retarget_positions,
    target_bone_lengths,
)
from stylemotion.datasets.synthetic import generate_take
from stylemotion.primitives.contacts import leg_length as contacts_leg_length
from stylemotion.primitives.contacts import planted_point_speed
from stylemotion.skeleton import (
    CANONICAL_PARENTS,
    FOOT_POINTS,
    JOINT_INDEX,
    NUM_JOINTS,
    bone_lengths,
    forward_kinematics,
)

FEET = list(FOOT_POINTS.ravel())
#: Bones of the hip-to-toe chains (the pelvis bone to each hip joint included).
LEG_BONES = [BONE_NAMES.index(f"{j}_{s}") for s in "LR" for j in ("UpperLeg", "LowerLeg", "Foot", "Toes")]


def rigid_walk(frames: int = 40, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A rigid skeleton (fixed random bones) turning randomly while its root walks forward.

    Returns:
        ``(frames, 21, 3)`` float64 positions, metres, and the ``(20,)`` bone lengths.
    """
    rng = np.random.default_rng(seed)
    offsets = rng.normal(size=(NUM_JOINTS, 3))
    offsets *= rng.uniform(0.05, 0.45, (NUM_JOINTS, 1)) / np.linalg.norm(offsets, axis=1, keepdims=True)
    rotations = Rotation.random(frames * NUM_JOINTS, random_state=seed).as_matrix().reshape(frames, NUM_JOINTS, 3, 3)
    translations = np.repeat(offsets[None], frames, axis=0)
    t = np.arange(frames) / 30.0
    translations[:, 0] = np.stack([0.3 + 0.1 * np.sin(t), 0.95 + 0.03 * np.sin(9 * t), 2.0 + 1.3 * t], axis=-1)
    positions = forward_kinematics(rotations, translations, CANONICAL_PARENTS)
    return positions, np.linalg.norm(offsets, axis=1)[list(BONE_JOINTS)]


def bone_directions(positions: np.ndarray) -> np.ndarray:
    """``(frames, 20, 3)`` unit vector of each bone, parent to child."""
    vectors = positions[:, list(BONE_JOINTS)] - positions[:, [CANONICAL_PARENTS[j] for j in BONE_JOINTS]]
    return vectors / np.linalg.norm(vectors, axis=-1, keepdims=True)


def test_bones_keep_their_directions_and_take_the_target_lengths() -> None:
    positions, lengths = rigid_walk()
    target = lengths * np.random.default_rng(1).uniform(0.7, 1.3, NUM_BONES)
    out = retarget_positions(positions, target)
    assert out.shape == positions.shape and out.dtype == np.float64
    np.testing.assert_allclose(bone_lengths(out)[:, list(BONE_JOINTS)], np.broadcast_to(target, (len(out), NUM_BONES)),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(bone_directions(out), bone_directions(positions), rtol=0, atol=1e-12)
    assert np.abs(out - positions).max() > 0.05  # the bones did change


def test_the_source_lengths_give_the_take_back() -> None:
    positions, lengths = rigid_walk(seed=2)
    np.testing.assert_allclose(median_bone_lengths(positions), lengths, rtol=0, atol=1e-12)
    np.testing.assert_allclose(retarget_positions(positions, lengths), positions, rtol=0, atol=1e-12)
    as_float32 = retarget_positions(positions.astype(np.float32), lengths)
    assert as_float32.dtype == np.float32
    np.testing.assert_allclose(as_float32, positions, rtol=0, atol=1e-5)


@pytest.mark.parametrize("k", [0.8, 1.15])
def test_a_uniform_scale_scales_the_take_about_its_start_and_keeps_its_ground(k: float) -> None:
    """All bones × k: the root's path and height scale by k too (leg ratio k), so the whole take is the
    original scaled by k about the first frame's root on the ground, with the lowest foot height kept."""
    positions, lengths = rigid_walk(seed=3)
    out = retarget_positions(positions, k * lengths)
    start = positions[0, JOINT_INDEX["Hips"]] * [1, 0, 1]
    ground = positions[:, FEET, 1].min()
    expected = start + k * (positions - start)
    expected[..., 1] = ground + k * (positions[..., 1] - ground)
    np.testing.assert_allclose(out, expected, rtol=0, atol=1e-12)
    assert out[:, FEET, 1].min() == pytest.approx(ground, abs=1e-12)
    stride = np.linalg.norm(np.diff(out[:, 0, [0, 2]], axis=0), axis=-1).sum()
    assert stride == pytest.approx(k * np.linalg.norm(np.diff(positions[:, 0, [0, 2]], axis=0), axis=-1).sum())


def test_planted_feet_stay_planted_and_on_the_ground() -> None:
    """Synthetic walk (exact contacts): longer legs, shorter arms and spine; the hip-to-ankle ratio
    scales the root's path, so the planted feet neither skate nor sink."""
    take = generate_take("walk", "normal", 0, duration_s=3.0)
    source = take.positions.astype(np.float64)
    scale = np.full(NUM_BONES, 0.9)
    scale[LEG_BONES] = 1.12
    out = retarget_positions(source, median_bone_lengths(source) * scale)
    assert leg_length(median_bone_lengths(out)) == pytest.approx(1.12 * leg_length(median_bone_lengths(source)))
    planted = take.contacts[1:] & take.contacts[:-1]  # (frames - 1, 2): in contact at both ends of a step

    def planted_speed(positions: np.ndarray) -> np.ndarray:
        """Horizontal speed of heel and ball (frames - 1, 2 feet, 2 points) while planted, m/s."""
        points = positions[:, FOOT_POINTS][..., [0, 2]]
        return (np.linalg.norm(np.diff(points, axis=0), axis=-1) * take.fps)[planted]

    before, after = planted_speed(source), planted_speed(out)
    assert before.max() < 0.02 and after.max() < 0.02 * 1.12 + 1e-3, (before.max(), after.max())
    assert planted_point_speed(out, take.fps).max() > 1.0  # the feet still swing
    assert out[:, FEET, 1].min() == pytest.approx(source[:, FEET, 1].min(), abs=1e-9)
    assert out[:, JOINT_INDEX["Hips"], 1].mean() > source[:, JOINT_INDEX["Hips"], 1].mean() + 0.05  # longer legs


def test_median_lengths_target_of_several_takes_and_leg_length() -> None:
    short, short_lengths = rigid_walk(seed=4)
    takes = [short, 1.1 * short, 1.3 * short]
    np.testing.assert_allclose(median_bone_lengths(np.stack(takes)), np.outer([1, 1.1, 1.3], short_lengths),
                               rtol=1e-12)
    np.testing.assert_allclose(target_bone_lengths(takes), 1.1 * short_lengths, rtol=1e-12)
    np.testing.assert_allclose(target_bone_lengths(iter(takes[:2])), 1.05 * short_lengths, rtol=1e-12)
    assert leg_length(short_lengths) == pytest.approx(float(contacts_leg_length(short)), rel=1e-12)
    with pytest.raises(ValueError, match="at least one take"):
        target_bone_lengths([])


def test_bad_input_is_refused_naming_what_is_wrong() -> None:
    positions, lengths = rigid_walk(frames=5)
    with pytest.raises(ValueError, match=r"positions must have shape \(frames, 21, 3\).*\(5, 20, 3\)"):
        retarget_positions(positions[:, :20], lengths)
    with pytest.raises(ValueError, match=r"target_lengths must be 20 numbers.*shape \(19,\)"):
        retarget_positions(positions, lengths[:19])
    bad = lengths.copy()
    bad[BONE_NAMES.index("Hand_R")] = -0.1
    with pytest.raises(ValueError, match=r"bone 'Hand_R' has -0.1"):
        retarget_positions(positions, bad)
    broken = positions.copy()
    broken[3, JOINT_INDEX["Neck"], 1] = np.nan
    with pytest.raises(ValueError, match=r"NaN or infinite values, first at frame 3, joint 'Neck'"):
        retarget_positions(broken, lengths)
    collapsed = positions.copy()
    collapsed[2:4, JOINT_INDEX["Toes_L"]] = collapsed[2:4, JOINT_INDEX["Foot_L"]]
    with pytest.raises(ValueError, match=r"bone 'Toes_L' has zero length .* in 2 frame\(s\), first at frame 2"):
        retarget_positions(collapsed, lengths)
    zero_target = lengths.copy()
    zero_target[BONE_NAMES.index("Toes_L")] = 0.0  # a bone that stays of zero length has nothing to lose
    out = retarget_positions(collapsed, zero_target)
    np.testing.assert_allclose(out[:, JOINT_INDEX["Toes_L"]], out[:, JOINT_INDEX["Foot_L"]], atol=1e-12)


def test_a_bone_of_zero_length_takes_the_direction_to_its_child() -> None:
    """A skeleton whose clavicle sits on its parent joint (as in CMU-like files mapped to the canonical
    joints) still retargets: the zero-length bone points from its parent to its child joint."""
    positions, lengths = rigid_walk(seed=1)
    shoulder, parent = JOINT_INDEX["Shoulder_L"], CANONICAL_PARENTS[JOINT_INDEX["Shoulder_L"]]
    child = JOINT_INDEX["UpperArm_L"]
    collapsed = positions.copy()
    collapsed[:, shoulder] = collapsed[:, parent]
    out = retarget_positions(collapsed, lengths)
    bone = BONE_NAMES.index("Shoulder_L")
    np.testing.assert_allclose(np.linalg.norm(out[:, shoulder] - out[:, parent], axis=-1), lengths[bone], rtol=1e-9)
    through = collapsed[:, child] - collapsed[:, parent]
    got = out[:, shoulder] - out[:, parent]
    cosine = np.sum(got * through, -1) / np.linalg.norm(got, axis=-1) / np.linalg.norm(through, axis=-1)
    np.testing.assert_allclose(cosine, 1.0, atol=1e-9)
    everywhere = collapsed.copy()
    everywhere[:, child] = everywhere[:, parent]  # the child on the same point too: no direction at all
    with pytest.raises(ValueError, match=r"bone 'Shoulder_L' has zero length"):
        retarget_positions(everywhere, lengths)


def test_place_bones_keeps_the_root_and_directions_and_makes_the_bones_constant() -> None:
    positions, lengths = rigid_walk(seed=3)
    stretched = positions + np.random.default_rng(4).normal(0, 0.02, positions.shape)  # bones that change length
    out = place_bones(stretched, lengths)
    np.testing.assert_allclose(out[:, JOINT_INDEX["Hips"]], stretched[:, JOINT_INDEX["Hips"]], atol=1e-12)
    np.testing.assert_allclose(bone_lengths(out)[:, list(BONE_JOINTS)], np.broadcast_to(lengths, (len(out), NUM_BONES)),
                               atol=1e-12)
    np.testing.assert_allclose(bone_directions(out), bone_directions(stretched), atol=1e-12)
    np.testing.assert_allclose(place_bones(positions, lengths), positions, atol=1e-12)  # a rigid take comes back
