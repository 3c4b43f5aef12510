"""stylemotion.geometry: the conventions of each transform, and every numpy function against its torch twin."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from stylemotion import geometry as g
from stylemotion.skeleton import CANONICAL_PARENTS, NUM_JOINTS, forward_kinematics, forward_kinematics_torch

RNG = np.random.default_rng(11)
#: Angles at and within one float step of the wrap points, and far multiples of 2π.
EDGE_ANGLES = np.array([
    np.pi, -np.pi, np.nextafter(np.pi, 0.0), np.nextafter(np.pi, 4.0), np.nextafter(-np.pi, 0.0),
    np.nextafter(-np.pi, -4.0), 3 * np.pi, -3 * np.pi, 2 * np.pi, 0.0, -0.0, 1e-300, -1e-300, 1e6, -1e6,
])


def random_rotations(shape: tuple[int, ...]) -> np.ndarray:
    """Proper rotation matrices ``shape + (3, 3)`` (QR of Gaussian matrices, sign-fixed)."""
    q, r = np.linalg.qr(RNG.standard_normal(shape + (3, 3)))
    q = q * np.sign(np.diagonal(r, axis1=-2, axis2=-1))[..., None, :]
    return q * np.where(np.linalg.det(q) < 0, -1.0, 1.0)[..., None, None]


def torch_of(*arrays: np.ndarray, dtype: torch.dtype = torch.float64) -> list[torch.Tensor]:
    return [torch.as_tensor(a, dtype=dtype) for a in arrays]


# ---------------------------------------------------------------------------------------------
# Twins: same result from numpy and torch (float64 to rounding, float32 to its precision)

ANGLE_SHAPE = (4, 5)
TWINS = {
    "wrap_angle": (lambda: [RNG.uniform(-40, 40, ANGLE_SHAPE)], g.wrap_angle, g.wrap_angle_torch),
    "direction_yaw": (lambda: [RNG.standard_normal(ANGLE_SHAPE + (2,))], g.direction_yaw, g.direction_yaw_torch),
    "facing_direction": (lambda: [RNG.uniform(-7, 7, ANGLE_SHAPE)], g.facing_direction, g.facing_direction_torch),
    "left_direction": (lambda: [RNG.uniform(-7, 7, ANGLE_SHAPE)], g.left_direction, g.left_direction_torch),
    "rotate_yaw": (lambda: [RNG.standard_normal(ANGLE_SHAPE + (3,)), RNG.uniform(-7, 7, ANGLE_SHAPE)],
                   g.rotate_yaw, g.rotate_yaw_torch),
    "rotate_yaw (one yaw per row)": (lambda: [RNG.standard_normal((6, NUM_JOINTS, 3)), RNG.uniform(-7, 7, (6, 1))],
                                     g.rotate_yaw, g.rotate_yaw_torch),
    "rotate_yaw_xz": (lambda: [RNG.standard_normal(ANGLE_SHAPE + (2,)), RNG.uniform(-7, 7, ANGLE_SHAPE)],
                      g.rotate_yaw_xz, g.rotate_yaw_xz_torch),
    "rotation_x": (lambda: [RNG.uniform(-7, 7, ANGLE_SHAPE)], g.rotation_x, g.rotation_x_torch),
    "rotation_y": (lambda: [RNG.uniform(-7, 7, ANGLE_SHAPE)], g.rotation_y, g.rotation_y_torch),
    "rotation_z": (lambda: [RNG.uniform(-7, 7, ANGLE_SHAPE)], g.rotation_z, g.rotation_z_torch),
    "relative_rotation": (lambda: [random_rotations(ANGLE_SHAPE), random_rotations(ANGLE_SHAPE)],
                          g.relative_rotation, g.relative_rotation_torch),
}


@pytest.mark.parametrize("name", list(TWINS))
def test_numpy_and_torch_twins_agree(name: str) -> None:
    make, numpy_fn, torch_fn = TWINS[name]
    inputs = make()
    expected = numpy_fn(*inputs)
    np.testing.assert_allclose(torch_fn(*torch_of(*inputs)).numpy(), expected, rtol=1e-12, atol=1e-12)
    single = torch_fn(*torch_of(*inputs, dtype=torch.float32))
    assert single.dtype == torch.float32
    np.testing.assert_allclose(single.numpy(), expected, rtol=1e-4, atol=1e-4)


def test_twins_take_a_plain_number_for_the_yaw() -> None:
    vectors = RNG.standard_normal((5, 3))
    for yaw in (0.3, -np.pi, 2.5):
        np.testing.assert_allclose(g.rotate_yaw_torch(torch.from_numpy(vectors), yaw).numpy(),
                                   g.rotate_yaw(vectors, yaw), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(g.rotate_yaw_xz_torch(torch.from_numpy(vectors[:, :2]), yaw).numpy(),
                                   g.rotate_yaw_xz(vectors[:, :2], yaw), rtol=1e-12, atol=1e-12)


def test_local_rotations_twins_agree_with_batch_dims() -> None:
    glob = random_rotations((2, 3, NUM_JOINTS))
    expected = g.local_rotations(glob, CANONICAL_PARENTS)
    np.testing.assert_allclose(g.local_rotations_torch(torch.from_numpy(glob), CANONICAL_PARENTS).numpy(),
                               expected, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("law", g.IK_LAWS)
@pytest.mark.parametrize("margin", [None, 1e-6])
def test_two_bone_ik_twins_agree(law: str, margin: float | None) -> None:
    root, target, pole = RNG.standard_normal((3, 2, 50, 3))
    target = root + 0.8 * (target - root) / np.linalg.norm(target - root, axis=-1, keepdims=True)
    upper, lower = RNG.uniform(0.4, 0.5, (2, 2, 50, 1))
    middle, end = g.two_bone_ik(root, target, pole, upper, lower, law=law, margin=margin)
    middle_t, end_t = g.two_bone_ik_torch(*torch_of(root, target, pole, upper, lower), law=law, margin=margin)
    np.testing.assert_allclose(middle_t.numpy(), middle, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(end_t.numpy(), end, rtol=1e-10, atol=1e-12)


def test_wrap_angle_twins_agree_bit_for_bit_on_the_edges() -> None:
    np.testing.assert_array_equal(g.wrap_angle_torch(torch.from_numpy(EDGE_ANGLES)).numpy(), g.wrap_angle(EDGE_ANGLES))


def test_direction_yaw_twins_agree_on_the_axes() -> None:
    axes = np.array([[0.0, 1.0], [1.0, 0.0], [0.0, -1.0], [-0.0, -1.0], [-1.0, 0.0], [1e-300, -1.0]])
    np.testing.assert_array_equal(g.direction_yaw_torch(torch.from_numpy(axes)).numpy(), g.direction_yaw(axes))


def test_torch_twins_are_differentiable() -> None:
    yaw = torch.tensor([0.3, -2.0], dtype=torch.float64, requires_grad=True)
    vectors = torch.randn(2, 3, dtype=torch.float64, requires_grad=True)
    assert torch.autograd.gradcheck(lambda v, a: g.rotate_yaw_torch(v, a), (vectors, yaw))
    assert torch.autograd.gradcheck(lambda a: g.rotation_y_torch(a), (yaw,))
    root = torch.zeros(2, 3, dtype=torch.float64)
    target = torch.tensor([[0.1, -0.7, 0.2], [0.0, -0.6, -0.3]], dtype=torch.float64, requires_grad=True)
    pole = torch.tensor([[0.0, 0.0, 1.0]] * 2, dtype=torch.float64)
    for law in g.IK_LAWS:
        def knee(t: torch.Tensor, law: str = law) -> torch.Tensor:
            return g.two_bone_ik_torch(root, t, pole, 0.45, 0.42, law=law)[0]

        assert torch.autograd.gradcheck(knee, (target,))


# ---------------------------------------------------------------------------------------------
# Conventions (Y up, yaw θ faces (sin θ, 0, cos θ), positive yaw turns +Z towards +X)


def test_wrap_angle_range_and_period() -> None:
    angles = np.concatenate([RNG.uniform(-100, 100, 1000), EDGE_ANGLES])
    wrapped = g.wrap_angle(angles)
    assert np.all(np.abs(wrapped) <= np.pi)
    np.testing.assert_allclose(np.sin(wrapped), np.sin(angles), atol=1e-9)
    np.testing.assert_allclose(np.cos(wrapped), np.cos(angles), atol=1e-9)
    inside = RNG.uniform(-3.1, 3.1, 100)
    np.testing.assert_allclose(g.wrap_angle(inside), inside, atol=1e-15)
    assert g.wrap_angle(np.pi) == -np.pi and g.wrap_angle(-np.pi) == -np.pi  # [-π, π): π itself wraps


def test_yaw_conventions() -> None:
    quarter = np.pi / 2
    np.testing.assert_allclose(g.rotate_yaw(np.array([0.0, 0.0, 1.0]), quarter), [1.0, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(g.rotate_yaw(np.array([1.0, 0.0, 0.0]), quarter), [0.0, 0.0, -1.0], atol=1e-15)
    np.testing.assert_allclose(g.rotate_yaw_xz(np.array([0.0, 1.0]), quarter), [1.0, 0.0], atol=1e-15)
    yaw = RNG.uniform(-np.pi, np.pi, 200)
    forward = g.facing_direction(yaw)
    np.testing.assert_allclose(forward, g.rotate_yaw(np.array([0.0, 0.0, 1.0]), yaw)[:, [0, 2]], atol=1e-15)
    np.testing.assert_allclose(g.left_direction(yaw), g.rotate_yaw(np.array([1.0, 0.0, 0.0]), yaw)[:, [0, 2]],
                               atol=1e-15)
    np.testing.assert_allclose(g.direction_yaw(3.0 * forward), yaw, atol=1e-12)
    assert g.direction_yaw(np.array([0.0, -1.0])) == np.pi and g.direction_yaw(np.array([-0.0, -1.0])) == -np.pi


def test_rotate_yaw_keeps_height_and_length_and_matches_rotation_y() -> None:
    vectors = RNG.standard_normal((7, NUM_JOINTS, 3))
    yaw = RNG.uniform(-np.pi, np.pi, (7, 1))
    turned = g.rotate_yaw(vectors, yaw)
    np.testing.assert_array_equal(turned[..., 1], vectors[..., 1])
    np.testing.assert_allclose(np.linalg.norm(turned, axis=-1), np.linalg.norm(vectors, axis=-1), rtol=1e-12)
    by_matrix = np.einsum("nab,njb->nja", g.rotation_y(yaw[:, 0]), vectors)
    np.testing.assert_allclose(turned, by_matrix, atol=1e-12)
    np.testing.assert_allclose(g.rotate_yaw(turned, -yaw), vectors, atol=1e-12)
    np.testing.assert_allclose(g.rotate_yaw_xz(vectors[..., [0, 2]], yaw), turned[..., [0, 2]], atol=1e-15)


def test_axis_rotations_are_proper_and_turn_the_documented_way() -> None:
    angles = RNG.uniform(-7, 7, 50)
    for matrix in (g.rotation_x, g.rotation_y, g.rotation_z):
        r = matrix(angles)
        np.testing.assert_allclose(r @ np.swapaxes(r, -1, -2), np.broadcast_to(np.eye(3), r.shape), atol=1e-12)
        np.testing.assert_allclose(np.linalg.det(r), 1.0, atol=1e-12)
        assert matrix(0.3).shape == (3, 3)
    small = 0.1
    assert (g.rotation_x(small) @ [0.0, 1.0, 0.0])[2] > 0  # leaning forward tips +Y towards +Z
    assert (g.rotation_y(small) @ [0.0, 0.0, 1.0])[0] > 0  # a left turn: +Z towards +X
    assert (g.rotation_z(small) @ [1.0, 0.0, 0.0])[1] > 0  # raises +X (the body's left side)


def test_local_rotations_invert_forward_kinematics() -> None:
    local = random_rotations((2, 5, NUM_JOINTS))
    offsets = RNG.standard_normal((NUM_JOINTS, 3))
    _, glob = forward_kinematics(local, offsets, CANONICAL_PARENTS, return_rotations=True)
    np.testing.assert_allclose(g.local_rotations(glob, CANONICAL_PARENTS), local, atol=1e-12)
    back = forward_kinematics_torch(g.local_rotations_torch(torch.from_numpy(glob), CANONICAL_PARENTS),
                                    torch.from_numpy(offsets), CANONICAL_PARENTS)
    np.testing.assert_allclose(back.numpy(), forward_kinematics(local, offsets, CANONICAL_PARENTS), atol=1e-12)


def test_relative_rotation_is_the_parent_inverse_times_the_child() -> None:
    parent, child = random_rotations((2, 10))
    np.testing.assert_allclose(g.relative_rotation(parent, child), np.linalg.inv(parent) @ child, atol=1e-12)


# ---------------------------------------------------------------------------------------------
# Two-bone IK


def leg(n: int = 200) -> tuple[np.ndarray, ...]:
    """Hips, reachable ankle targets, a forward pole, thigh and shin lengths."""
    hip = RNG.standard_normal((n, 3))
    direction = RNG.standard_normal((n, 3))
    direction /= np.linalg.norm(direction, axis=-1, keepdims=True)
    target = hip + RNG.uniform(0.1, 0.8, (n, 1)) * direction
    return hip, target, RNG.standard_normal((n, 3)), 0.45, 0.42


@pytest.mark.parametrize("law", g.IK_LAWS)
def test_two_bone_ik_keeps_bones_reaches_the_target_and_bends_to_the_pole(law: str) -> None:
    hip, target, pole, upper, lower = leg()
    knee, end = g.two_bone_ik(hip, target, pole, upper, lower, law=law)
    np.testing.assert_array_equal(end, target)
    np.testing.assert_allclose(np.linalg.norm(knee - hip, axis=-1), upper, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(target - knee, axis=-1), lower, atol=1e-9)
    axis = (target - hip) / np.linalg.norm(target - hip, axis=-1, keepdims=True)
    across = lambda v: v - np.sum(v * axis, -1, keepdims=True) * axis  # noqa: E731
    assert np.all(np.sum(across(knee - hip) * across(pole), axis=-1) > 0)
    plane_normal = np.cross(axis, pole)
    np.testing.assert_allclose(np.sum((knee - hip) * plane_normal, axis=-1), 0.0, atol=1e-9)


def test_two_bone_ik_laws_are_the_same_geometry() -> None:
    hip, target, pole, upper, lower = leg()
    by_distances = g.two_bone_ik(hip, target, pole, upper, lower, law="distances")[0]
    by_cosines = g.two_bone_ik(hip, target, pole, upper, lower, law="cosines")[0]
    np.testing.assert_allclose(by_distances, by_cosines, atol=1e-12)


def test_two_bone_ik_margin_pulls_an_unreachable_target_in() -> None:
    hip = np.zeros((2, 3))
    target = np.array([[0.0, -2.0, 0.0], [0.0, -0.001, 0.0]])  # too far; closer than |thigh − shin|
    pole = np.array([[0.0, 0.0, 1.0]] * 2)
    knee, end = g.two_bone_ik(hip, target, pole, 0.45, 0.42, law="cosines", margin=1e-6)
    np.testing.assert_allclose(np.linalg.norm(end - hip, axis=-1), [0.87 - 1e-6, 0.03 + 1e-6], atol=1e-12)
    np.testing.assert_allclose(end[:, [0, 2]], 0.0, atol=1e-15)  # along the hip→target line
    np.testing.assert_allclose(np.linalg.norm(knee - hip, axis=-1), 0.45, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(end - knee, axis=-1), 0.42, atol=1e-6)


def test_two_bone_ik_rejects_an_unknown_law() -> None:
    hip, target, pole, upper, lower = leg(2)
    with pytest.raises(ValueError, match="law must be one of .*'sines'"):
        g.two_bone_ik(hip, target, pole, upper, lower, law="sines")
    with pytest.raises(ValueError, match="law must be one of"):
        g.two_bone_ik_torch(*torch_of(hip, target, pole), upper, lower, law="sines")
