"""The subject's skeleton: measured on a motion, a database put on it, bones held by two-bone IK onto given ends."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.bones import BONE_JOINTS, median_bone_lengths
from stylemotion.datasets.base import TakeSet
from stylemotion.datasets.registry import load_dataset
from stylemotion.reconstruct.subject import (
    RIGID_BONES,
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


def _rigid_local(positions, bone):
    frames = body_frames(positions)[RIGID_BONES[bone]]
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
