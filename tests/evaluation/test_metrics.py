"""Evaluation metrics and table functions against hand-computed values and known distributions."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from stylemotion.datasets.registry import load_synthetic
from stylemotion.evaluation.metrics import (
    diversity,
    foot_skating,
    frechet_distance,
    nearest_distances,
    pooled_skating,
    pose_sequences,
)
from stylemotion.evaluation.sources import motions_from_clips
from stylemotion.evaluation.tables import (
    across_sample_sd,
    diagonal_minima,
    distance_table,
    mean_motion,
    variance_stats,
)
from stylemotion.models.style import gram
from stylemotion.primitives.segmentation import segment_takes
from stylemotion.representation import frames_to_positions
from stylemotion.skeleton import JOINT_INDEX


def test_frechet_distance_of_known_gaussians() -> None:
    rng = np.random.default_rng(0)
    a = rng.standard_normal((20000, 3))
    assert frechet_distance(a, a) == pytest.approx(0.0, abs=1e-6)
    shifted = a + np.array([1.0, 2.0, 0.0])
    assert frechet_distance(a, shifted) == pytest.approx(5.0, rel=1e-6)  # ‖δ‖², equal covariances
    wide = 2.0 * rng.standard_normal((20000, 3))  # N(0, 4I): 3 · (1 + 4 − 2·2) = 3
    assert frechet_distance(a, wide) == pytest.approx(3.0, rel=0.03)
    assert frechet_distance(a, wide) == pytest.approx(frechet_distance(wide, a), rel=1e-6)
    with pytest.raises(ValueError, match="at least 2 rows"):
        frechet_distance(a[:1], a)
    with pytest.raises(ValueError, match=r"\(n, d\)"):
        frechet_distance(a, a[:, :2])


def test_diversity_is_the_mean_pairwise_distance() -> None:
    triangle = np.array([[0.0, 0.0], [1.0, 0.0], [0.5, np.sqrt(3) / 2]])
    assert diversity(triangle) == pytest.approx(1.0)
    assert diversity(np.ones((5, 4))) == 0.0
    square = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    assert diversity(square) == pytest.approx((4 + 2 * np.sqrt(2)) / 6)
    assert diversity(square, max_items=2) == pytest.approx(1.0)


def test_nearest_distances_are_rms_joint_distances() -> None:
    rng = np.random.default_rng(1)
    reference = rng.standard_normal((6, 4 * 63))  # 4 frames × 21 joints
    query = reference[[2, 5]].copy()
    assert np.allclose(nearest_distances(query, reference), 0.0, atol=1e-6)
    moved = reference[3] + np.tile([0.03, 0.0, 0.04], 4 * 21)  # every joint 5 cm away
    far = reference + 100.0
    assert nearest_distances(moved[None], np.concatenate([far, reference[3:4]]))[0] == pytest.approx(0.05)
    frames = np.zeros((2, 4, 66))
    frames[1, :, :63] = 1.0
    assert pose_sequences(frames).shape == (2, 4 * 63) and pose_sequences(frames)[1].sum() == 4 * 63


def test_distance_table_and_diagonal_by_hand() -> None:
    class Identity:  # "encoder": the frames themselves, channels first
        def encode(self, frames):
            return frames.transpose(-1, -2)

    rng = np.random.default_rng(2)
    samples = [rng.standard_normal((5, 6, 66)).astype(np.float32) for _ in range(2)]
    examples = torch.stack([gram(torch.from_numpy(rng.standard_normal((66, 4)).astype(np.float32)))
                            for _ in range(3)])
    table = distance_table(Identity(), samples, examples, chunk=2)
    g = gram(torch.from_numpy(samples[1]).transpose(-1, -2))
    expected = torch.linalg.matrix_norm(g - examples[2]).mean()
    assert table.shape == (2, 3) and table[1, 2] == pytest.approx(float(expected), rel=1e-5)
    d = diagonal_minima(np.array([[1.0, 2.0, 3.0], [0.5, 1.0, 0.2], [4.0, 4.0, 3.0]]), ["a", "b", "c"])
    assert d["rows"] == ["a", "c"] and d["columns"] == ["b"] and not d["all_rows"] and not d["all_columns"]
    assert d["row_argmin"]["b"] == "c"
    assert mean_motion(np.stack([np.zeros((3, 66)), 2 * np.ones((3, 66))])).tolist() == np.ones((3, 66)).tolist()


def test_variance_stats_of_constructed_motions() -> None:
    """Straight walks at known speeds and durations, with one joint moved by a known amount."""
    fps, speeds, frames_n = 30.0, np.array([1.0, 1.2, 1.4, 1.6]), np.array([11, 11, 16, 16])
    width = frames_n.max()
    frames = np.zeros((4, width, 66))
    frames[..., 1] = 1.0  # the root 1 m up, every other joint at the root
    frames[..., 64] = speeds[:, None]  # forward velocity, m/s
    frames[2:, :, 3 * JOINT_INDEX["Head"] + 1] = 0.02  # two motions hold the head 2 cm higher
    positions = frames_to_positions(frames, fps)
    for i, n in enumerate(frames_n):  # pad by holding the last frame, as MotionSamples does
        frames[i, n:], positions[i, n:] = frames[i, n - 1], positions[i, n - 1]
    stats = variance_stats(frames, positions, frames_n)
    poses = np.concatenate([np.full(n, 0.02 if i >= 2 else 0.0) for i, n in enumerate(frames_n)])
    assert stats["pose_sd"] == pytest.approx(100 * np.sqrt(((poses - poses.mean()) ** 2).sum() / (len(poses) - 1)))
    assert stats["v_sd"] == pytest.approx(speeds.std(ddof=1))  # no turning
    steps = speeds * (frames_n - 1) / fps  # metres from first to last frame
    assert stats["step_sd"] == pytest.approx(100 * steps.std(ddof=1))
    assert stats["step_mean_cm"] == pytest.approx(100 * steps.mean())
    frames[:, :, 65] = np.array([0.0, 0.0, 0.5, -0.5])[:, None]  # yaw rates add to V_SD
    w = np.array([0.0, 0.0, 0.5, -0.5])
    assert variance_stats(frames, positions, frames_n)["v_sd"] == pytest.approx(
        np.sqrt((((speeds - speeds.mean()) ** 2).sum() + ((w - w.mean()) ** 2).sum()) / 3))


def test_across_sample_sd_sees_copies_that_pose_sd_misses() -> None:
    """Copies of one moving motion: pose_SD is high (the motion within the step), pose_across_SD is 0;
    two motions 2 cm apart on every coordinate: sqrt(63 · (0.01 m)²) = 7.94 cm."""
    t = np.linspace(0, 2 * np.pi, 17)
    one = np.zeros((17, 66))
    one[:, :63] = 0.1 * np.sin(t)[:, None] * np.linspace(0.5, 1.5, 63)[None, :]  # every joint moves
    copies = np.repeat(one[None], 50, axis=0)
    positions = frames_to_positions(copies, 30.0)
    stats = variance_stats(copies, positions, np.full(50, 17), copies)
    assert stats["pose_sd"] > 5.0 and stats["pose_across_sd"] == pytest.approx(0.0, abs=1e-9)
    shifted = np.stack([one, one])
    shifted[1, :, :63] += 0.02
    assert across_sample_sd(shifted) == pytest.approx(100 * np.sqrt(63 * 0.01 ** 2))
    with pytest.raises(ValueError, match="normalized frames"):
        across_sample_sd(one[None])


@pytest.fixture(scope="module")
def walk_clips():
    takes = load_synthetic(takes_per_pair=2, duration_s=5.0, styles=["normal"], contents=["walk"]).takes
    clips = [c for c in segment_takes(takes).clips if c.primitive == "leftStance"]
    return clips, np.array([[0.08, 0.02], [0.08, 0.02]])


def test_foot_skating_separates_planted_sliding_and_floating_feet(walk_clips) -> None:
    clips, rest = walk_clips
    real = motions_from_clips(clips, 16)
    args = (real.num_frames.numpy(), real.fps, rest)
    clean = foot_skating(real.positions.numpy(), *args, stance_foot=0)
    assert clean.ratio < 0.1 and clean.no_plant_share == 0.0 and clean.planted_mid_mps < 0.05
    assert 0.4 < clean.contact_share < 0.9
    sliding = real.positions.numpy().copy()  # the planted left foot drifts forward at 0.3 m/s
    drift = np.arange(sliding.shape[1]) * 0.3 / real.fps
    sliding[:, :, [JOINT_INDEX["Foot_L"], JOINT_INDEX["Toes_L"]], 2] += drift[None, :, None]
    slid = foot_skating(sliding, *args, stance_foot=0)
    assert slid.ratio > clean.ratio + 0.2 or slid.no_plant_share > 0.5
    assert slid.planted_mid_mps == pytest.approx(clean.planted_mid_mps + 0.3, abs=0.02)
    floating = real.positions.numpy() + np.array([0.0, 0.25, 0.0])  # 25 cm above the real resting heights
    assert foot_skating(floating, *args, stance_foot=0).contact_share == 0.0
    assert foot_skating(floating, *args, stance_foot=0).no_plant_share == 1.0
    both = pooled_skating([clean, slid])
    assert both.motions == 2 * clean.motions
    assert both.ratio == pytest.approx((clean.skating_frames + slid.skating_frames)
                                       / (clean.contact_frames + slid.contact_frames))
    with pytest.raises(ValueError, match="num_frames"):
        foot_skating(real.positions.numpy(), np.ones(len(real), dtype=int), real.fps, rest)
