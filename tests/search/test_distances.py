"""Frame distance measures of Krüger §2.3.1 against independent references (brute force, scipy, hand values)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import spearmanr

from stylemotion.datasets.registry import load_dataset
from stylemotion.geometry import rotation_y
from stylemotion.search.distances import (
    BODY_PART_WEIGHTS,
    FrameMeasures,
    clip_distances,
    dtw_costs,
    euler_distance,
    fit_pva,
    joint_rotations,
    nearest_label_precision,
    neighbour_correlations,
    point_cloud_distance,
    point_cloud_window,
    point_clouds,
    quaternion_distance,
    spearman_rows,
)
from stylemotion.search.features import fit_features

FPS = 30.0


@pytest.fixture(scope="module")
def takes() -> list[np.ndarray]:
    """Two synthetic takes (a walk and a run), float64 positions at 30 fps."""
    ts = load_dataset("synthetic", takes_per_pair=1, styles=["normal"], contents=["walk", "run"])
    return [t.positions.astype(np.float64) for t in ts.takes]


def _turn(points: np.ndarray, yaw: float, shift: tuple[float, float]) -> np.ndarray:
    """Points ``(..., 3)`` turned by ``yaw`` about +Y and shifted in the ground plane."""
    return points @ rotation_y(np.array(yaw)).T + np.array([shift[0], 0.0, shift[1]])


def _brute_force(a: np.ndarray, b: np.ndarray, steps: int = 20001) -> float:
    """min over a grid of ``steps`` angles about +Y of Σ|a − (R b + t)|², t the best ground shift for each angle
    (the mean offset in x and z); ``a``, ``b``: ``(P, 3)``."""
    theta = np.linspace(-np.pi, np.pi, steps)
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    x = a[:, 0] - (c * b[:, 0] + s * b[:, 2])
    z = a[:, 2] - (-s * b[:, 0] + c * b[:, 2])
    x -= x.mean(axis=1, keepdims=True)
    z -= z.mean(axis=1, keepdims=True)
    return float(np.min(np.sum(x ** 2 + z ** 2, axis=1)) + np.sum((a[:, 1] - b[:, 1]) ** 2))


def test_point_cloud_distance_is_invariant_to_turns_and_ground_shifts() -> None:
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(1, 40, 3)), rng.normal(size=(1, 40, 3))
    moved = _turn(b, 1.1, (3.0, -2.0))
    assert point_cloud_distance(b, moved)[0, 0] == pytest.approx(0.0, abs=1e-9)
    assert point_cloud_distance(a, moved)[0, 0] == pytest.approx(point_cloud_distance(a, b)[0, 0], rel=1e-9)
    lifted = b + np.array([0.0, 0.5, 0.0])  # a vertical shift is not aligned away: 40 points × 0.25 m²
    assert point_cloud_distance(b, lifted)[0, 0] == pytest.approx(40 * 0.25, rel=1e-9)


def test_point_cloud_distance_equals_a_search_over_angles() -> None:
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=(3, 25, 3)), rng.normal(size=(2, 25, 3))
    closed = point_cloud_distance(a, b)
    for i in range(3):
        for j in range(2):
            # the brute force is an upper bound reached to within the grid's resolution (0.02°)
            reference = _brute_force(a[i], b[j])
            assert closed[i, j] <= reference + 1e-9
            assert closed[i, j] == pytest.approx(reference, rel=1e-4)


def test_point_cloud_windows_follow_the_thesis_and_clamp_at_the_ends() -> None:
    assert point_cloud_window(11, 30.0) == 11 and point_cloud_window(11, 60.0) == 21
    assert point_cloud_window(1, 120.0) == 1
    positions = np.arange(5 * 21 * 3, dtype=float).reshape(5, 21, 3)
    clouds = point_clouds(positions, np.array([0, 4]), 3)
    np.testing.assert_array_equal(clouds[0].reshape(3, 21, 3), positions[[0, 0, 1]])
    np.testing.assert_array_equal(clouds[1].reshape(3, 21, 3), positions[[3, 4, 4]])
    with pytest.raises(ValueError, match="odd"):
        point_clouds(positions, np.array([0]), 4)


def test_quaternion_distance_is_zero_for_q_and_minus_q_and_the_angle_otherwise() -> None:
    rng = np.random.default_rng(2)
    q = rng.normal(size=(6, 21, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    np.testing.assert_allclose(quaternion_distance(q, -q), 0.0, atol=1e-6)
    identity = np.tile([0.0, 0.0, 0.0, 1.0], (21, 1))
    turned = identity.copy()
    turned[3] = [np.sin(0.15), 0.0, 0.0, np.cos(0.15)]  # 0.3 rad about X at joint 3
    turned[7] = [0.0, 0.0, -np.sin(0.2), -np.cos(0.2)]  # 0.4 rad about Z, sign flipped, at joint 7
    assert quaternion_distance(identity, turned) == pytest.approx(np.hypot(0.3, 0.4))
    weights = np.zeros(21)
    weights[7] = 2.0
    assert quaternion_distance(identity, turned, weights) == pytest.approx(np.sqrt(2.0) * 0.4)


def test_euler_distance_wraps_each_difference() -> None:
    a = np.zeros((21, 3))
    b = np.zeros((21, 3))
    a[0] = [0.1, 3.1, 0.0]
    b[0] = [0.2, -3.1, 0.0]  # 6.2 rad apart as numbers, 2π − 6.2 as angles
    assert euler_distance(a, b) == pytest.approx(np.hypot(0.1, 2 * np.pi - 6.2))


def test_joint_rotations_ignore_turning_the_motion_about_the_vertical(takes: list[np.ndarray]) -> None:
    positions = takes[0][:40]
    q = joint_rotations(positions, FPS)
    turned = joint_rotations(_turn(positions, 2.0, (1.0, 4.0)), FPS)
    np.testing.assert_allclose(quaternion_distance(q, turned), 0.0, atol=1e-5)
    assert quaternion_distance(q[:1], q[20:21])[0] > 0.05  # a walk's poses differ


def test_frame_measures_agree_with_the_pairwise_functions(takes: list[np.ndarray]) -> None:
    short = [t[:60] for t in takes]
    fitted = {"pca8": fit_features("pca8", short, FPS), "F_pva20": fit_pva(short, FPS)}
    measures = FrameMeasures(short, FPS, ["E15", "pca8"], fitted)
    rows = np.array([3, 70])
    quats = np.concatenate([joint_rotations(t, FPS) for t in short])
    for name, weights in (("D_quat", None), ("D_lee", BODY_PART_WEIGHTS["lee"]), ("D_wb", BODY_PART_WEIGHTS["wb"])):
        np.testing.assert_allclose(measures.distances(name, rows),
                                   quaternion_distance(quats[rows][:, None], quats[None], weights), atol=1e-6)
    window = point_cloud_window(11, FPS)
    clouds = np.concatenate([point_clouds(t, np.arange(len(t)), window) for t in short])
    np.testing.assert_allclose(measures.distances("D_pc11", rows), point_cloud_distance(clouds[rows], clouds),
                               rtol=1e-9, atol=1e-9)
    assert measures.distances("E15", rows)[0, 3] == pytest.approx(0.0, abs=1e-6)


def test_spearman_rows_matches_scipy() -> None:
    rng = np.random.default_rng(3)
    a = rng.normal(size=(4, 50))
    b = a + rng.normal(scale=0.7, size=(4, 50))
    b[0, :10] = b[0, 0]  # ties
    expected = [spearmanr(a[i], b[i]).statistic for i in range(4)]
    np.testing.assert_allclose(spearman_rows(a, b), expected, atol=1e-12)


def test_neighbour_correlations_on_a_planted_case() -> None:
    rng = np.random.default_rng(4)
    a = rng.random(size=(5, 2000))
    near = np.sort(a, axis=1)[:, [100]]
    dist = {"A": a, "monotone": np.exp(3 * a), "reversed": -a, "noise": rng.random(size=(5, 2000)),
            "far_agrees": np.where(a < near, near * rng.random(size=(5, 2000)), a)}
    excluded = np.zeros_like(a, dtype=bool)
    excluded[:, :10] = True
    corr = neighbour_correlations(dist, excluded, [50, 1000], rows=["A"])["A"]
    np.testing.assert_allclose(corr[50]["monotone"], 1.0)
    np.testing.assert_allclose(corr[50]["reversed"], -1.0)
    assert abs(corr[1000]["noise"].mean()) < 0.1
    # "far_agrees" shuffles A's 100 nearest frames among themselves and keeps A beyond: uncorrelated at k = 50,
    # nearly the same ranks at k = 1000
    assert abs(corr[50]["far_agrees"].mean()) < 0.35 and corr[1000]["far_agrees"].mean() > 0.95


def test_nearest_label_precision_counts_labels_of_the_nearest_frames() -> None:
    dist = np.array([[0.0, 1.0, 2.0, 3.0, 4.0]])
    labels = np.array(["x", "x", "y", "x", "y"])
    excluded = np.array([[True, False, False, False, False]])
    assert nearest_label_precision(dist, excluded, labels, np.array(["x"]), n=2)[0] == pytest.approx(0.5)


def _all_paths_min(cost: np.ndarray, i: int = 0, j: int = 0) -> float:
    """Cheapest monotone path from (i, j) to the last cell by enumerating every path (tiny matrices only)."""
    m, n = cost.shape
    here = cost[i, j]
    if (i, j) == (m - 1, n - 1):
        return float(here)
    nexts = [(i + di, j + dj) for di, dj in ((1, 0), (0, 1), (1, 1)) if i + di < m and j + dj < n]
    return float(here + min(_all_paths_min(cost, a, b) for a, b in nexts))


def test_dtw_costs_equal_the_cheapest_of_all_paths() -> None:
    rng = np.random.default_rng(5)
    cost = rng.random(size=(6, 5, 4))
    cost[0] = 1.0  # every path of a constant matrix: the diagonal-heavy one with the fewest cells, 5
    expected = [_all_paths_min(c) for c in cost]
    np.testing.assert_allclose(dtw_costs(cost), expected)
    assert dtw_costs(cost)[0] == pytest.approx(5.0)
    assert dtw_costs(cost[:, :1, :1])[3] == pytest.approx(cost[3, 0, 0])


def test_clip_distances_of_a_clip_with_itself_are_zero(takes: list[np.ndarray]) -> None:
    clips = [takes[0][:20], takes[1][:20], takes[0][:20] + np.array([2.0, 0.0, 1.0])]
    fitted = {"F_pva20": fit_pva(clips, FPS)}
    measures = FrameMeasures(clips, FPS, ["E15"], fitted)
    dist = clip_distances(measures, 20, stride=2, chunk=7)
    for name, d in dist.items():
        assert d.shape == (3, 3)
        assert d[0, 1] > 1e-3, name
        assert d[0, 2] < 1e-4 * d[0, 1], name  # a shifted copy: every measure is blind to the shift
