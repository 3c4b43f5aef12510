"""Canonical positions ⇄ 66-dim frames (thesis §5.2): exact inverse, invariances, units, autograd."""

from __future__ import annotations

import re

import numpy as np
import pytest
import torch
from conftest import BANDAI_MEMBERS

from stylemotion.datasets.canonical import to_canonical_positions
from stylemotion.geometry import rotation_y
from stylemotion.io.bvh import parse_bvh, read_bvh
from stylemotion.representation import (
    FRAME_DIM,
    VELOCITY_DIMS,
    YAW_RATE_DIM,
    facing_yaw,
    frames_to_positions,
    positions_to_frames,
)
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX

ROUND_TRIP_TOL_M = 1e-3
FPS = 30.0


def static_pose() -> np.ndarray:
    """A hand-made canonical standing pose ``(21, 3)``, metres, Hips over the origin, facing +Z.

    The body's left is +X (left joints have x > 0); toes point to +Z.
    """
    left = {
        "Shoulder": (0.05, 1.45, 0.0), "UpperArm": (0.20, 1.45, 0.0), "LowerArm": (0.22, 1.18, 0.0),
        "Hand": (0.23, 0.93, 0.04), "UpperLeg": (0.10, 0.95, 0.0), "LowerLeg": (0.11, 0.52, 0.02),
        "Foot": (0.11, 0.08, -0.02), "Toes": (0.11, 0.02, 0.14),
    }  # fmt: skip
    pose = {"Hips": (0.0, 1.0, 0.0), "Spine": (0.0, 1.1, 0.0), "Chest": (0.0, 1.3, 0.01),
            "Neck": (0.0, 1.5, 0.0), "Head": (0.0, 1.62, 0.02)}  # fmt: skip
    for part, (x, y, z) in left.items():
        pose[f"{part}_L"] = (x, y, z)
        pose[f"{part}_R"] = (-x, y, z)
    return np.array([pose[name] for name in CANONICAL_JOINTS], dtype=np.float64)


# ---------------------------------------------------------------------------------------------
# Real takes


@pytest.fixture(scope="module")
def takes(other_skeleton_paths):
    """name → canonical positions at 30 fps (metres)."""
    return {name: to_canonical_positions(read_bvh(path)) for name, path in other_skeleton_paths.items()}


@pytest.fixture(scope="module")
def longest_bandai_walk(bandai_zip):
    """(member, positions) of the Bandai walk (content 'walk') with the most frames."""
    frames = {}
    for info in bandai_zip.infolist():
        if re.fullmatch(r"dataset-2_walk_[a-z]+_\d+\.bvh", info.filename):
            with bandai_zip.open(info) as fh:
                head = fh.read(16384).decode("utf-8", "replace")
            frames[info.filename] = int(re.search(r"Frames:\s*(\d+)", head).group(1))
    assert frames, "no walk takes in the Bandai zip"
    member = max(frames, key=frames.get)
    motion = parse_bvh(bandai_zip.read(member), f"{bandai_zip.filename}::{member}")
    assert motion.num_frames == frames[member]
    return member, to_canonical_positions(motion)


def _round_trip_error(positions: np.ndarray, fps: float = FPS) -> float:
    frames, start_xz, start_yaw = positions_to_frames(positions, fps)
    assert frames.shape == (positions.shape[0], FRAME_DIM) and frames.dtype == np.float32
    back = frames_to_positions(frames, fps, start_xz, start_yaw)
    assert isinstance(back, np.ndarray) and back.shape == positions.shape
    return float(np.abs(back - positions).max())


@pytest.mark.realdata
@pytest.mark.parametrize("name", ["cmu21_walk", "cmu21_female_walk", "xia_cmu31"])
def test_round_trip_other_conventions(takes, name):
    positions = takes[name]
    err = _round_trip_error(positions)
    assert err <= ROUND_TRIP_TOL_M, f"{name}: round trip error {err:.3g} m"
    # Without the start placement the take comes back shifted: the placement matters.
    frames, _, _ = positions_to_frames(positions, FPS)
    assert np.abs(frames_to_positions(frames, FPS) - positions).max() > 10 * ROUND_TRIP_TOL_M


@pytest.mark.realdata
def test_round_trip_long_bandai_walk(longest_bandai_walk):
    member, positions = longest_bandai_walk
    if positions.shape[0] < 10 * FPS:
        pytest.skip(f"longest Bandai walk {member} is only {positions.shape[0] / FPS:.1f} s")
    travelled = np.linalg.norm(positions[-1, JOINT_INDEX["Hips"], [0, 2]] - positions[0, JOINT_INDEX["Hips"], [0, 2]])
    assert travelled > 2.0  # a real walk: the root integration is exercised over metres
    err = _round_trip_error(positions)
    assert err <= ROUND_TRIP_TOL_M, f"{member}: round trip error {err:.3g} m"


@pytest.mark.realdata
@pytest.mark.parametrize("name", ["cmu21_walk", "bandai"])
def test_frames_invariant_to_ground_rigid_motion(takes, bandai_zip, name):
    if name == "bandai":
        member = BANDAI_MEMBERS[0]
        positions = to_canonical_positions(parse_bvh(bandai_zip.read(member), member))
    else:
        positions = takes[name]
    positions = positions.astype(np.float64)
    frames, xz, yaw = positions_to_frames(positions, FPS)
    for angle, shift in [(0.7, (3.0, -2.0)), (-2.9, (-10.0, 25.0)), (np.pi, (0.5, 0.5))]:
        moved = positions @ rotation_y(angle).T + np.array([shift[0], 0.0, shift[1]])
        frames2, xz2, yaw2 = positions_to_frames(moved, FPS)
        # Every frame, the smoothing boundary included: the facing filter is linear.
        np.testing.assert_allclose(frames2, frames, rtol=0, atol=2e-5)
        np.testing.assert_allclose(xz2, rotation_y(angle)[[0, 2]][:, [0, 2]] @ xz + shift, atol=1e-9)
        assert abs(np.angle(np.exp(1j * (yaw2 - yaw - angle)))) < 1e-9
        np.testing.assert_allclose(frames_to_positions(frames2, FPS, xz2, yaw2), moved, atol=ROUND_TRIP_TOL_M)
    # The frames do see a change of pose (not a constant output).
    mirrored = positions * np.array([-1.0, 1.0, 1.0])
    assert np.abs(positions_to_frames(mirrored, FPS)[0] - frames).max() > 0.05


# ---------------------------------------------------------------------------------------------
# Synthetic motions with known answers


def _translate(pose: np.ndarray, velocity_xz, fps: float, n: int = 40) -> np.ndarray:
    t = np.arange(n) / fps
    step = np.stack([velocity_xz[0] * t, np.zeros(n), velocity_xz[1] * t], axis=-1)
    return pose[None] + step[:, None, :]


@pytest.mark.parametrize("fps", [30.0, 60.0])
@pytest.mark.parametrize("heading", [0.0, np.pi / 2, -2.3])
def test_velocity_in_metres_per_second(fps, heading):
    """A static pose carried forward at 1.3 m/s gives vz = 1.3, vx = 0, whatever the heading."""
    pose = static_pose() @ rotation_y(heading).T
    forward = np.array([np.sin(heading), np.cos(heading)])
    frames, _, start_yaw = positions_to_frames(_translate(pose, 1.3 * forward, fps), fps)
    np.testing.assert_allclose(frames[:, VELOCITY_DIMS], np.broadcast_to([0.0, 1.3], (len(frames), 2)),
                               atol=1e-5)
    np.testing.assert_allclose(frames[:, YAW_RATE_DIM], 0.0, atol=1e-6)
    assert abs(np.angle(np.exp(1j * (start_yaw - heading)))) < 1e-9
    # Facing-normalized joints are the un-rotated pose, whatever the heading.
    local = frames[:, :63].reshape(-1, 21, 3)
    np.testing.assert_allclose(local, np.broadcast_to(static_pose(), local.shape), atol=1e-6)


def test_sideways_velocity_sign():
    """Stepping towards the body's left (+X when facing +Z) is +vx."""
    frames, _, _ = positions_to_frames(_translate(static_pose(), (0.5, 0.0), FPS), FPS)
    velocity = frames[:, VELOCITY_DIMS]
    np.testing.assert_allclose(velocity, np.broadcast_to([0.5, 0.0], velocity.shape), atol=1e-6)


def test_yaw_rate_in_radians_per_second():
    """Turning in place at 0.8 rad/s (+Z towards +X) gives yaw rate +0.8 away from the ends."""
    omega, n = 0.8, 90
    pose = static_pose()
    positions = np.stack([pose @ rotation_y(omega * k / FPS).T for k in range(n)])
    frames, _, _ = positions_to_frames(positions, FPS)
    margin = int(np.ceil(4 * 0.15 * FPS)) + 1  # reach of scipy's Gaussian (4 standard deviations)
    np.testing.assert_allclose(frames[margin:-margin, YAW_RATE_DIM], omega, atol=1e-4)
    np.testing.assert_allclose(facing_yaw(positions, FPS, smooth_seconds=0.0), omega * np.arange(n) / FPS,
                               atol=1e-9)
    # The smoothed start heading lags a little at the boundary; with it the take comes back exactly.
    _, start_xz, start_yaw = positions_to_frames(positions, FPS)
    assert 0 < start_yaw < 0.05
    np.testing.assert_allclose(frames_to_positions(frames, FPS, start_xz, start_yaw), positions, atol=1e-5)


def test_too_short_or_wrong_shape():
    with pytest.raises(ValueError, match="at least 2 frames"):
        positions_to_frames(static_pose()[None], FPS)
    with pytest.raises(ValueError, match=r"\(frames, 21, 3\)"):
        positions_to_frames(np.zeros((5, 22, 3)), FPS)
    with pytest.raises(ValueError, match="66"):
        frames_to_positions(np.zeros((5, 65)), FPS)


# ---------------------------------------------------------------------------------------------
# Torch path


def _synthetic_walk(n: int = 24) -> np.ndarray:
    """A pose turning slowly while moving forward, with a little bob: ``(n, 21, 3)``."""
    out = []
    xz = np.zeros(2)
    for k in range(n):
        heading = 0.3 + 0.05 * k
        pose = static_pose() + np.array([0.0, 0.02 * np.sin(k / 3.0), 0.0])
        xz = xz + 1.2 / FPS * np.array([np.sin(heading), np.cos(heading)])
        out.append(pose @ rotation_y(heading).T + np.array([xz[0], 0.0, xz[1]]))
    return np.stack(out)


def test_torch_path_is_differentiable():
    positions = _synthetic_walk()
    frames_np, xz, yaw = positions_to_frames(positions, FPS)
    frames = torch.tensor(frames_np, dtype=torch.float64, requires_grad=True)
    start_xz = torch.tensor(xz, dtype=torch.float64, requires_grad=True)
    start_yaw = torch.tensor(yaw, dtype=torch.float64, requires_grad=True)
    out = frames_to_positions(frames, FPS, start_xz, start_yaw)
    assert isinstance(out, torch.Tensor) and out.dtype == torch.float64
    np.testing.assert_allclose(out.detach().numpy(), frames_to_positions(frames_np, FPS, xz, yaw), atol=1e-12)
    np.testing.assert_allclose(out.detach().numpy(), positions, atol=1e-5)
    # Where the last frame's hand is depends on every earlier velocity and yaw rate.
    out[-1, JOINT_INDEX["Hand_L"]].sum().backward()
    grad = frames.grad
    assert grad is not None and torch.isfinite(grad).all()
    assert torch.all(grad[:-1, VELOCITY_DIMS].abs().sum(dim=-1) > 0)
    assert torch.all(grad[:-1, YAW_RATE_DIM].abs() > 0)
    assert grad[-1, 3 * JOINT_INDEX["Hand_L"] : 3 * JOINT_INDEX["Hand_L"] + 3].abs().sum() > 0
    assert grad[-1, VELOCITY_DIMS].abs().sum() == 0  # the last frame's velocity is not integrated
    assert start_xz.grad.abs().sum() > 0 and start_yaw.grad.abs() > 0


def test_torch_path_gradcheck_and_batch():
    positions = _synthetic_walk(6)
    frames_np, _, _ = positions_to_frames(positions, FPS)
    frames = torch.tensor(frames_np, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(lambda f: frames_to_positions(f, FPS, start_yaw=0.4), (frames,))
    # Leading batch dims: each item with its own start placement.
    batch = torch.stack([frames.detach(), frames.detach().flip(0)])
    starts = torch.tensor([[1.0, 2.0], [-3.0, 0.5]], dtype=torch.float64)
    yaws = torch.tensor([0.1, -1.0], dtype=torch.float64)
    out = frames_to_positions(batch, FPS, starts, yaws)
    assert out.shape == (2, 6, 21, 3)
    for i in range(2):
        single = frames_to_positions(batch[i], FPS, starts[i], yaws[i])
        torch.testing.assert_close(out[i], single, rtol=0, atol=1e-12)
    # float32 torch input stays float32 (training path).
    assert frames_to_positions(batch.float(), FPS).dtype == torch.float32
