"""The subject's skeleton: measured on a motion, a database put on it, bones held by two-bone IK onto given ends."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.bones import BONE_JOINTS, median_bone_lengths
from stylemotion.datasets.base import TakeSet
from stylemotion.datasets.registry import load_dataset
from stylemotion.reconstruct.subject import (
    HINGED_BONES,
    RIGID_BONES,
    Subject,
    body_frames,
    database_on_subject,
    hold_bone_lengths,
    subject_from_motion,
)
from stylemotion.search.database import MotionDatabase
from stylemotion.skeleton import CANONICAL_PARENTS, JOINT_INDEX, bone_lengths


@pytest.fixture(scope="module")
def takes():
    return load_dataset("synthetic", takes_per_pair=1).takes[:4]


def _rigid_local(positions, bone, parts=RIGID_BONES):
    frames = body_frames(positions)[parts[bone]]
    child = JOINT_INDEX[bone]
    vector = positions[:, child] - positions[:, CANONICAL_PARENTS[child]]
    local = np.einsum("fij,fi->fj", frames, vector)
    return local / np.linalg.norm(local, axis=-1, keepdims=True)


def test_a_database_on_a_subject_has_its_bones_and_rigid_directions(takes):
    other = np.asarray(takes[0].positions, np.float64).copy()
    other[:, JOINT_INDEX["UpperLeg_L"]] += np.array([0.0, -0.05, 0.0])  # another convention: hip joints lower
    other[:, JOINT_INDEX["UpperLeg_R"]] += np.array([0.0, -0.05, 0.0])
    other = other * 1.1
    subject = subject_from_motion(other)
    np.testing.assert_allclose(subject.lengths, median_bone_lengths(other))
    database = MotionDatabase.from_takeset(TakeSet("s", list(takes[1:]), 30.0))
    moved = database_on_subject(database, subject)
    positions = np.asarray(moved.positions, np.float64)
    lengths = bone_lengths(positions)[:, list(BONE_JOINTS)]
    np.testing.assert_allclose(lengths, np.broadcast_to(subject.lengths, lengths.shape), atol=2e-5)
    for bone in ("UpperLeg_L", "Shoulder_R"):
        expected = np.broadcast_to(subject.rigid[bone], (len(positions), 3))
        np.testing.assert_allclose(_rigid_local(positions, bone), expected, atol=2e-3)
    assert moved.take_start.tolist() == database.take_start.tolist()


def _pitched_feet(positions, degrees):
    """``positions`` with each foot bone turned by ``degrees`` about its shank frame's x axis (toes up for > 0)."""
    out = np.asarray(positions, np.float64).copy()
    frames = body_frames(out)
    angle = np.radians(degrees)
    turn = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(angle), -np.sin(angle)], [0.0, np.sin(angle), np.cos(angle)]])
    for bone, part in HINGED_BONES.items():
        child, parent = JOINT_INDEX[bone], CANONICAL_PARENTS[JOINT_INDEX[bone]]
        local = np.einsum("fji,fj->fi", frames[part], out[:, child] - out[:, parent])
        out[:, child] = out[:, parent] + np.einsum("fij,jk,fk->fi", frames[part], turn, local)
    return out


def test_a_database_on_a_subject_takes_its_foot_convention_and_keeps_the_ankles_flexing(takes):
    database = MotionDatabase.from_takeset(TakeSet("s", list(takes[1:]), 30.0))
    base = np.asarray(database.positions, np.float64)
    subject = subject_from_motion(_pitched_feet(takes[0].positions, 25.0))  # another skeleton's foot convention
    own = subject_from_motion(takes[0].positions)
    for bone in HINGED_BONES:  # the measured convention differs by the turn given
        cos = float(np.dot(subject.hinged[bone], own.hinged[bone]))
        assert np.degrees(np.arccos(np.clip(cos, -1, 1))) == pytest.approx(25.0, abs=0.5)
    moved = np.asarray(database_on_subject(database, subject).positions, np.float64)
    plain = np.asarray(database_on_subject(database, Subject(subject.lengths, subject.rigid)).positions, np.float64)
    for bone in HINGED_BONES:
        got = np.median(_rigid_local(moved, bone, HINGED_BONES), axis=0)
        np.testing.assert_allclose(got / np.linalg.norm(got), subject.hinged[bone], atol=0.02)
        # every frame turned by one constant rotation in the shank's frame (the ankle's flexing kept): the best
        # single rotation (Kabsch) maps each unturned foot onto the turned one, by about 25°
        a, b = _rigid_local(moved, bone, HINGED_BONES), _rigid_local(plain, bone, HINGED_BONES)
        u, _, vt = np.linalg.svd(a.T @ b)
        turn = u @ np.diag([1.0, 1.0, np.linalg.det(u @ vt)]) @ vt
        np.testing.assert_allclose(b @ turn.T, a, atol=1e-4)  # the database stores float32
        assert 20.0 < np.degrees(np.arccos((np.trace(turn) - 1) / 2)) < 30.0
    others = [j for j in range(moved.shape[1]) if j not in (JOINT_INDEX["Toes_L"], JOINT_INDEX["Toes_R"])]
    relative = moved[:, others] - moved[:, :1]  # the rest of the body as it was (a take's ground may shift)
    np.testing.assert_allclose(relative, plain[:, others] - plain[:, :1], atol=1e-6)
    assert base.shape == moved.shape


def test_held_bones_reach_the_given_ends_and_stay_constant(takes):
    truth = np.asarray(takes[1].positions[:60], np.float64)
    lengths = median_bone_lengths(truth)
    rng = np.random.default_rng(0)
    noisy = truth + rng.normal(0, 0.02, truth.shape)  # a model's output: bones that change length
    ends = {"Foot_L": truth[:, JOINT_INDEX["Foot_L"]], "Hand_R": truth[:, JOINT_INDEX["Hand_R"]]}
    held = hold_bone_lengths(noisy, lengths, ends)
    got = bone_lengths(held)[:, list(BONE_JOINTS)]
    np.testing.assert_allclose(got, np.broadcast_to(lengths, got.shape), atol=1e-6)
    for joint, target in ends.items():  # within reach: met (the hip moved by the noise, so a few mm at most)
        assert np.median(np.linalg.norm(held[:, JOINT_INDEX[joint]] - target, axis=-1)) < 0.01
    # a knee pulled off its bones within the leg's plane comes back: the hip and ankle fix it, given the lengths
    pulled = truth.copy()
    hip, knee, ankle = (JOINT_INDEX[j] for j in ("UpperLeg_L", "LowerLeg_L", "Foot_L"))
    pulled[:, knee] += 0.3 * (0.5 * (truth[:, hip] + truth[:, ankle]) - truth[:, knee])
    np.testing.assert_allclose(hold_bone_lengths(pulled, lengths)[:, knee], truth[:, knee], atol=1e-3)


def test_a_subject_without_toes_or_with_a_shoulder_at_the_chest_joint_gives_a_finite_database(takes):
    other = np.asarray(takes[0].positions, np.float64).copy()
    other[:, JOINT_INDEX["Toes_L"]] = other[:, JOINT_INDEX["Foot_L"]]  # a skeleton with no toes
    other[:, JOINT_INDEX["Shoulder_L"]] = other[:, JOINT_INDEX["Chest"]]  # clavicle starting at the chest joint
    subject = subject_from_motion(other)
    assert not np.any(subject.hinged["Toes_L"]) and not np.any(subject.rigid["Shoulder_L"])
    database = MotionDatabase.from_takeset(TakeSet("s", list(takes[1:]), 30.0))
    positions = np.asarray(database_on_subject(database, subject).positions, np.float64)
    assert np.isfinite(positions).all()
    toes = np.linalg.norm(positions[:, JOINT_INDEX["Toes_L"]] - positions[:, JOINT_INDEX["Foot_L"]], axis=-1)
    assert toes.max() < 1e-6
