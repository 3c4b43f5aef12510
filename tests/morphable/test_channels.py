"""The Morphable Graph's channel representations: quaternion (root translation + 21 continuous unit
quaternions on a fixed-bone skeleton) and frames (the 66-dim frames), their functions, and back to joints."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.synthetic import generate_take
from stylemotion.morphable import channels as channels_module
from stylemotion.morphable.channels import REPRESENTATIONS, Channels
from stylemotion.representation import FRAME_DIM, frames_to_positions, positions_to_frames
from stylemotion.skeleton import CANONICAL_JOINTS, CANONICAL_PARENTS, NUM_JOINTS

FPS = 30.0


@pytest.fixture(scope="module")
def clip() -> tuple[np.ndarray, np.ndarray]:
    """One second of a synthetic walk: ``(30, 21, 3)`` positions and its ``(30, 66)`` frames."""
    positions = generate_take("walk", "elderly", 1, seed=3, fps=FPS, duration_s=1.0).positions.astype(np.float64)
    frames, _, _ = positions_to_frames(positions, FPS)
    return positions, frames


@pytest.fixture(scope="module")
def quaternion(clip) -> Channels:
    return Channels.for_positions("quaternion", [clip[0]])


def test_unknown_kinds_and_a_quaternion_skeleton_without_bones_are_refused() -> None:
    assert REPRESENTATIONS == ("quaternion", "frames")
    with pytest.raises(ValueError, match=r"unknown representation 'euler'; one of \['quaternion', 'frames'\]"):
        Channels("euler")
    with pytest.raises(ValueError, match="needs bone offsets"):
        Channels("quaternion")


@pytest.mark.parametrize("kind, size, count", [("quaternion", 3 + 4 * NUM_JOINTS, 22), ("frames", FRAME_DIM, 23)])
def test_the_functions_partition_the_channels(clip, kind: str, size: int, count: int) -> None:
    channels = Channels.for_positions(kind, [clip[0]])
    assert channels.size == size and len(channels.functions) == count
    covered = np.concatenate([np.arange(size)[s] for _, s in channels.functions])
    np.testing.assert_array_equal(covered, np.arange(size))  # each channel in exactly one function, in order
    names = [name for name, _ in channels.functions]
    assert len(set(names)) == count and set(CANONICAL_JOINTS) <= set(names)
    assert (channels.offsets is None) == (kind == "frames")


def test_frames_are_the_channels_and_decode_like_the_representation(clip) -> None:
    positions, frames = clip
    channels = Channels.for_positions("frames", [positions])
    encoded = channels.encode(positions, frames)
    assert encoded.dtype == np.float64 and encoded.shape == (len(frames), FRAME_DIM)
    np.testing.assert_array_equal(encoded, frames.astype(np.float64))
    np.testing.assert_allclose(channels.positions(encoded, FPS), frames_to_positions(encoded, FPS))
    with pytest.raises(ValueError, match="need the quaternion representation"):
        channels.positions(encoded, FPS, rotations=True)


def test_frames_decode_each_clip_at_its_own_rate(clip) -> None:
    positions, frames = clip
    channels = Channels("frames")
    batch = np.stack([frames, frames]).astype(np.float64)
    decoded = channels.positions(batch, np.array([FPS, 2 * FPS]))
    np.testing.assert_allclose(decoded[0], frames_to_positions(batch[0], FPS))
    np.testing.assert_allclose(decoded[1], frames_to_positions(batch[1], 2 * FPS))
    assert not np.allclose(decoded[0], decoded[1])  # the root travels half as far at twice the rate


def test_quaternions_are_unit_continuous_and_decode_to_the_clip(clip, quaternion: Channels) -> None:
    positions, frames = clip
    encoded = quaternion.encode(positions, frames)
    assert encoded.shape == (len(positions), 3 + 4 * NUM_JOINTS)
    quats = encoded[:, 3:].reshape(len(positions), NUM_JOINTS, 4)
    np.testing.assert_allclose(np.linalg.norm(quats, axis=-1), 1.0, atol=1e-9)
    assert np.all(quats[0, :, 3] >= 0)  # first frame w ≥ 0
    assert np.all((quats[1:] * quats[:-1]).sum(-1) >= 0)  # consecutive frames in one hemisphere
    root = CANONICAL_PARENTS.index(-1)
    np.testing.assert_allclose(encoded[:, :3], positions[:, root], atol=1e-6)  # the root translation
    decoded = quaternion.positions(encoded)
    assert decoded.shape == positions.shape
    assert np.abs(decoded - positions).max() < 0.01  # a fixed-bone fit of a clip: within a centimetre


def test_quaternion_decoding_batches_chunks_and_rotations(clip, quaternion: Channels, monkeypatch) -> None:
    positions, frames = clip
    encoded = quaternion.encode(positions, frames)
    single = quaternion.positions(encoded)
    batch = quaternion.positions(np.stack([encoded, encoded[::-1]]))
    assert batch.shape == (2,) + positions.shape
    np.testing.assert_allclose(batch[0], single)
    np.testing.assert_allclose(batch[1], single[::-1])
    monkeypatch.setattr(channels_module, "DECODE_CHUNK", NUM_JOINTS * 7)  # 7 frames at a time
    pos, rot = quaternion.positions(np.stack([encoded, encoded]), rotations=True)
    np.testing.assert_allclose(pos[0], single, atol=1e-12)
    assert rot.shape == (2, len(positions), NUM_JOINTS, 3, 3)
    eye = np.broadcast_to(np.eye(3), rot.shape)
    np.testing.assert_allclose(rot @ np.swapaxes(rot, -1, -2), eye, atol=1e-9)  # orthonormal
    np.testing.assert_allclose(np.linalg.det(rot), 1.0, atol=1e-9)


def test_a_zero_quaternion_decodes_as_no_rotation(quaternion: Channels) -> None:
    rest = np.zeros((1, 3 + 4 * NUM_JOINTS))
    rest[:, 6::4] = 1.0  # identity quaternions (xyzw)
    zero = rest.copy()
    zero[:, 3 + 4 * 5:3 + 4 * 6] = 0.0  # one joint's quaternion is all zero
    np.testing.assert_allclose(quaternion.positions(zero), quaternion.positions(rest))
    scaled = rest.copy()
    scaled[:, 3:] *= 3.0  # not unit: normalized before use
    np.testing.assert_allclose(quaternion.positions(scaled), quaternion.positions(rest))
