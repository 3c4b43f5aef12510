"""Search feature sets (Krüger §2.3.2, §2.6.1): dimensions, invariances, windows, PCA and physics."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.registry import load_dataset
from stylemotion.geometry import rotation_x, rotation_y, rotation_z
from stylemotion.representation import positions_to_frames
from stylemotion.search.features import (
    E15_JOINTS,
    FEATURE_SETS,
    PHYSICS_BODY_MASS_KG,
    PHYSICS_INTERVAL_S,
    SEGMENT_MASSES,
    SEGMENTS,
    body_frame_positions,
    centre_of_mass,
    compute_features,
    feature_names,
    fit_features,
    fit_pca,
    physics_terms,
    segment_centres,
    window_offsets,
)
from stylemotion.skeleton import JOINT_INDEX

FPS = 30.0
G = 9.81


@pytest.fixture(scope="module")
def takes() -> list[np.ndarray]:
    """Four synthetic takes (walk and run, two styles), float64 positions at 30 fps."""
    ts = load_dataset("synthetic", takes_per_pair=1, styles=["normal", "elderly"], contents=["walk", "run"])
    return [t.positions.astype(np.float64) for t in ts.takes]


@pytest.fixture(scope="module")
def pose(takes) -> np.ndarray:
    """One standing-ish pose (21, 3) with the root above the origin."""
    p = takes[0][0].copy()
    return p - p[JOINT_INDEX["Hips"]] * np.array([1.0, 0.0, 1.0])


def _rigid(positions: np.ndarray, rotation: np.ndarray, shift: np.ndarray) -> np.ndarray:
    return positions @ rotation.T + shift


def test_every_set_has_its_dimension(takes):
    fitted = {n: fit_features(n, takes, FPS) for n in feature_names()}
    for name, spec in FEATURE_SETS.items():
        f = compute_features(name, takes[0], FPS, fitted[name])
        assert f.shape == (takes[0].shape[0], spec.dim) and f.dtype == np.float32, name
        assert np.all(np.isfinite(f)), name
    dims = {n: FEATURE_SETS[n].dim for n in ("E15", "E30", "E39", "E15x3", "E15x5", "E30x3", "pca8", "pca16",
                                             "pca25", "EP17", "EP19")}
    assert dims == {"E15": 15, "E30": 30, "E39": 39, "E15x3": 45, "E15x5": 75, "E30x3": 90, "pca8": 8,
                    "pca16": 16, "pca25": 25, "EP17": 17, "EP19": 19}


@pytest.mark.parametrize("normalization", ["3d", "2d"])
def test_e15_invariant_to_yaw_and_translation(takes, normalization):
    base = compute_features("E15", takes[1], FPS, normalization=normalization)
    for angle, shift in [(0.7, (3.0, 0.0, -2.0)), (-2.9, (-10.0, 0.0, 25.0)), (np.pi, (0.5, 0.0, 0.5))]:
        moved = _rigid(takes[1], rotation_y(np.array(angle)), np.array(shift))
        np.testing.assert_allclose(compute_features("E15", moved, FPS, normalization=normalization), base, atol=1e-5)


def test_3d_normalization_also_invariant_to_pitch_and_roll(takes):
    rotation = rotation_z(np.array(0.4)) @ rotation_x(np.array(-0.8)) @ rotation_y(np.array(2.0))
    moved = _rigid(takes[2], rotation, np.array([1.0, 2.0, -3.0]))
    for name in ("E15", "E39", "E15x5"):
        np.testing.assert_allclose(compute_features(name, moved, FPS), compute_features(name, takes[2], FPS),
                                   atol=1e-5, err_msg=name)
    # 2D normalization keeps the height and the tilt: a pitched motion looks different there.
    assert not np.allclose(compute_features("E15", moved, FPS, normalization="2d"),
                           compute_features("E15", takes[2], FPS, normalization="2d"), atol=1e-2)


def test_body_frame_axes(takes):
    local = body_frame_positions(takes[0], FPS)
    assert np.all(local[:, JOINT_INDEX["UpperLeg_L"], 0] > 0) and np.all(local[:, JOINT_INDEX["UpperLeg_R"], 0] < 0)
    assert np.all(local[:, JOINT_INDEX["Head"], 1] > 0.3)
    np.testing.assert_allclose(local[:, JOINT_INDEX["Hips"]], 0.0, atol=1e-9)
    # The 2D body frame is the one of the 66-dim representation (unsmoothed facing).
    frames, _, _ = positions_to_frames(takes[0], FPS, smooth_seconds=0.0)
    flat = body_frame_positions(takes[0], FPS, "2d").reshape(len(frames), -1)
    np.testing.assert_allclose(flat, frames[:, :63], atol=1e-5)
    e15 = compute_features("E15", takes[0], FPS)
    np.testing.assert_allclose(e15[:, 6:9], local[:, JOINT_INDEX[E15_JOINTS[2]]], atol=1e-6)


def test_window_offsets():
    assert window_offsets(3, 30.0).tolist() == [-9, -4, 0]
    assert window_offsets(5, 30.0).tolist() == [-9, -7, -4, -2, 0]
    assert window_offsets(3, 60.0).tolist() == [-18, -9, 0]


@pytest.mark.parametrize("name,base,samples", [("E15x3", "E15", 3), ("E15x5", "E15", 5), ("E30x3", "E30", 3)])
def test_windowed_set_is_stacked_shifted_frames(takes, name, base, samples):
    frame = compute_features(base, takes[3], FPS)
    windowed = compute_features(name, takes[3], FPS)
    offsets = window_offsets(samples, FPS)
    d = frame.shape[1]
    for s, off in enumerate(offsets):
        rows = np.clip(np.arange(len(frame)) + off, 0, len(frame) - 1)  # before the start: the first frame
        np.testing.assert_array_equal(windowed[:, s * d:(s + 1) * d], frame[rows])
    np.testing.assert_array_equal(windowed[0], np.tile(frame[0], samples))


def test_short_query_and_unknown_names_are_refused(takes):
    with pytest.raises(ValueError, match=r"E15x3 needs at least 10 frames .* the query has 6"):
        compute_features("E15x3", takes[0][:6], FPS)
    assert compute_features("E15x3", takes[0][:6], FPS, allow_short=True).shape == (6, 45)
    assert compute_features("E15", takes[0][:1], FPS).shape == (1, 15)
    with pytest.raises(ValueError, match=r"unknown feature set 'E16'.*'E15'.*'EP19'"):
        compute_features("E16", takes[0], FPS)
    with pytest.raises(ValueError, match="normalization '4d'"):
        compute_features("E15", takes[0], FPS, normalization="4d")
    with pytest.raises(ValueError, match=r"must have shape \(frames, 21, 3\) with at least 1 frame"):
        compute_features("E15", takes[0][:, :20], FPS)
    with pytest.raises(ValueError, match="fps"):
        compute_features("E15", takes[0], 0.0)
    with pytest.raises(ValueError, match="needs a PCA"):
        compute_features("pca8", takes[0], FPS)


def test_pca_reconstructs(takes):
    full = fit_pca(takes, FPS, 60)  # the root is always 0 in the body frame: 60 dimensions carry everything
    flat = body_frame_positions(takes[1], FPS).reshape(len(takes[1]), -1)
    np.testing.assert_allclose(full.inverse_transform(full.transform(flat)), flat, atol=1e-6)
    pca = fit_features("pca25", takes, FPS)
    assert pca.components.shape == (25, 63)
    np.testing.assert_allclose(pca.components @ pca.components.T, np.eye(25), atol=1e-9)
    assert np.all(np.diff(pca.explained_variance) <= 0)
    error = np.linalg.norm((pca.inverse_transform(pca.transform(flat)) - flat).reshape(-1, 21, 3), axis=-1)
    assert error.mean() < 0.01  # metres per joint
    scores = compute_features("pca25", takes[1], FPS, pca)
    np.testing.assert_allclose(scores, pca.transform(flat), atol=1e-5)
    again = type(pca).from_arrays(pca.to_arrays())
    np.testing.assert_array_equal(again.components, pca.components)
    with pytest.raises(ValueError, match="needs a 8-component PCA, got 25"):
        compute_features("pca8", takes[1], FPS, pca)


# ---------------------------------------------------------------------------------------------
# Physics


def test_segment_table():
    assert SEGMENT_MASSES.sum() == pytest.approx(1.0, abs=1e-9)
    assert len(SEGMENTS) == 14
    assert {s.name for s in SEGMENTS} >= {"head", "trunk", "thigh_L", "hand_R", "foot_L"}


def test_body_at_rest_has_no_acceleration_or_momentum(pose):
    still = np.repeat(pose[None], 20, axis=0)
    np.testing.assert_allclose(physics_terms(still, FPS), 0.0, atol=1e-12)
    ep = compute_features("EP19", still, FPS)
    np.testing.assert_allclose(ep[:, 15:], 0.0, atol=1e-7)


def test_free_fall_accelerates_the_com_by_minus_g(pose):
    dt = 1.0 / FPS
    t = np.arange(25) * dt
    height = 0.5 + 2.0 * t - 0.5 * G * t**2
    moving = pose[None] + np.stack([0.8 * t, height, 0.3 * t], axis=-1)[:, None, :]
    terms = physics_terms(moving, FPS, interval_s=dt, body_mass_kg=1.0)
    np.testing.assert_allclose(terms[:, 0], -G * dt**2, rtol=1e-9)  # along +Y, scaled by Δt²
    np.testing.assert_allclose(terms[:, 2], 0.0, atol=1e-12)  # no horizontal acceleration
    np.testing.assert_allclose(terms[:, [1, 3]], 0.0, atol=1e-12)  # translation only: no momentum
    com = centre_of_mass(moving)
    np.testing.assert_allclose(np.diff(com[:, 1], 2), -G * dt**2, rtol=1e-9)


def test_physics_terms_scale_with_the_interval_and_the_body_mass(pose):
    dt = 1.0 / FPS
    t = np.arange(25) * dt
    falling = pose[None] + np.stack([0.4 * t, 1.0 - 0.5 * G * t**2, 0.0 * t], axis=-1)[:, None, :]
    default = physics_terms(falling, FPS)
    np.testing.assert_allclose(default[:, 0], -G * PHYSICS_INTERVAL_S**2, rtol=1e-9)  # a·Δt², Δt = 0.3 s
    spinning = _spin(pose, rotation_y, 2.0, 20, np.array([0.3, 0.0, -0.2]))
    per_frame = physics_terms(spinning, FPS, interval_s=dt, body_mass_kg=1.0)
    np.testing.assert_allclose(physics_terms(spinning, FPS)[:, 1],
                               per_frame[:, 1] * (PHYSICS_INTERVAL_S / dt) * PHYSICS_BODY_MASS_KG, rtol=1e-9)
    for key, bad in (("interval_s", 0.0), ("body_mass_kg", -1.0), ("interval_s", float("nan"))):
        with pytest.raises(ValueError, match=key):
            physics_terms(spinning, FPS, **{key: bad})


def _spin(pose: np.ndarray, axis_rotation, omega: float, frames: int, pivot: np.ndarray) -> np.ndarray:
    angles = omega * np.arange(frames) / FPS
    return np.stack([(pose - pivot) @ axis_rotation(np.array(a)).T + pivot for a in angles])


@pytest.mark.parametrize("omega", [2.0, -3.0])
def test_spin_about_the_vertical_gives_the_momentum(pose, omega):
    moving = _spin(pose, rotation_y, omega, 20, np.array([0.3, 0.0, -0.2]))
    terms = physics_terms(moving, FPS, interval_s=1.0 / FPS, body_mass_kg=1.0)
    rel = segment_centres(pose) - centre_of_mass(pose)
    inertia = np.sum(SEGMENT_MASSES * (rel[:, 0] ** 2 + rel[:, 2] ** 2))  # per unit mass, m²
    expected = np.sin(omega / FPS) * inertia  # L·Δt with central differences, exact for a rigid spin
    np.testing.assert_allclose(terms[1:-1, 1], expected, rtol=1e-9)
    assert np.sign(terms[5, 1]) == np.sign(omega)  # positive = left turn (+Z towards +X)
    assert expected == pytest.approx(omega / FPS * inertia, rel=2e-3)  # ≈ ω·Δt·I for small ω·Δt


def test_forward_pitch_while_moving_gives_positive_side_momentum(pose):
    # Move along +Z and rotate about +X (the left of a body moving along +Z): head goes forwards.
    pitched = _spin(pose, rotation_x, 1.5, 20, centre_of_mass(pose))
    moving = pitched + (1.2 * np.arange(20) / FPS)[:, None, None] * np.array([0.0, 0.0, 1.0])
    terms = physics_terms(moving, FPS, interval_s=1.0 / FPS, body_mass_kg=1.0)
    rel = segment_centres(pose) - centre_of_mass(pose)
    inertia = np.sum(SEGMENT_MASSES * (rel[:, 1] ** 2 + rel[:, 2] ** 2))
    np.testing.assert_allclose(terms[1:-1, 3], np.sin(1.5 / FPS) * inertia, rtol=1e-9)
    rel_t = segment_centres(moving) - centre_of_mass(moving)[:, None, :]
    product = np.sum(SEGMENT_MASSES * rel_t[..., 0] * rel_t[..., 1], axis=-1)  # L_y = −ω·Σ m x y about X
    np.testing.assert_allclose(terms[1:-1, 1], -np.sin(1.5 / FPS) * product[1:-1], rtol=1e-9)


def test_physics_sets_invariant_to_yaw_and_translation(takes):
    base = compute_features("EP19", takes[0], FPS)
    moved = _rigid(takes[0], rotation_y(np.array(1.1)), np.array([4.0, 0.0, -1.0]))
    np.testing.assert_allclose(compute_features("EP19", moved, FPS), base, atol=1e-5)
