"""Forward kinematics: against an independent implementation (bvhio) and numpy vs torch."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from conftest import BANDAI_MEMBERS, OTHER_SKELETONS
from scipy.spatial.transform import Rotation

from stylemotion.io.bvh import format_bvh, parse_bvh, read_bvh
from stylemotion.skeleton import forward_kinematics, forward_kinematics_torch

bvhio = pytest.importorskip("bvhio")

#: bvhio computes in float32 (PyGLM vec3/quat, a transform per joint), so its world positions carry
#: rounding errors of a few float32 ulps of the largest coordinates along each chain. Bandai takes sit
#: up to ~5.5 m (550 cm) from the origin, where one ulp is 3e-5..6e-5 cm, and bvhio's deviation there
#: reaches ~2e-4 cm (our own FK run in float32 on the same take deviates 6e-5 cm from float64). The
#: bound is therefore 1e-4 file units, or 8 float32 ulps of the largest coordinate when that is larger
#: (4.6e-4 cm at 480 cm; still under 5 micrometres). The other conventions are held to 1e-4 file units.
FLOAT32_EPS = float(np.finfo(np.float32).eps)


def _bvhio_world_positions(path, frames):
    """``(len(frames), joints, 3)`` world positions from bvhio, and its joint names (file order)."""
    root = bvhio.readAsHierarchy(str(path))
    layout = [joint for joint, _, _ in root.layout()]
    out = []
    for f in frames:
        root.loadPose(int(f), recursive=True)
        out.append([list(joint.PositionWorld) for joint in layout])
    return np.array(out, dtype=np.float64), [joint.Name for joint in layout]


def _check_against_bvhio(path, motion, float32_bound: bool = False):
    n = motion.num_frames
    rng = np.random.default_rng(0)
    frames = sorted({0, 1, n // 3, n // 2, n - 1, *rng.integers(0, n, 3).tolist()})
    ours = motion.global_positions()[frames]
    ref, names = _bvhio_world_positions(path, frames)
    assert names == motion.skeleton.names
    tol = max(1e-4, 8 * FLOAT32_EPS * np.abs(ref).max()) if float32_bound else 1e-4
    err = np.abs(ours - ref).max()
    assert err <= tol, f"{path}: max FK deviation from bvhio {err:.3g} > {tol:.3g} file units"
    # The comparison is not vacuous: the joints move between the checked frames.
    assert np.abs(ref[-1] - ref[0]).max() > 1000 * tol
    return err


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(OTHER_SKELETONS))
def test_fk_matches_bvhio_other_conventions(name, other_skeleton_paths):
    path = other_skeleton_paths[name]
    _check_against_bvhio(path, read_bvh(path))


@pytest.mark.realdata
@pytest.mark.parametrize("member", BANDAI_MEMBERS)
def test_fk_matches_bvhio_bandai(bandai_zip, tmp_path, member):
    path = tmp_path / member
    path.write_bytes(bandai_zip.read(member))  # bvhio reads paths only; the zip stays untouched
    motion = parse_bvh(bandai_zip.read(member), f"{bandai_zip.filename}::{member}")
    _check_against_bvhio(path, motion, float32_bound=True)


@pytest.mark.realdata
def test_written_file_matches_bvhio(other_skeleton_paths, tmp_path):
    """Our writer's output, read by bvhio, gives our FK of the original motion."""
    motion = read_bvh(other_skeleton_paths["xia_cmu31"])
    path = tmp_path / "written.bvh"
    path.write_text(format_bvh(motion))
    _check_against_bvhio(path, motion)


def test_fk_known_values():
    """A 90° turn about +Z of the root carries a child offset (1, 0, 0) to (0, 1, 0)."""
    parents = [-1, 0, 1]
    rot = np.broadcast_to(np.eye(3), (3, 3, 3)).copy()
    rot[0] = Rotation.from_euler("z", 90, degrees=True).as_matrix()
    rot[1] = Rotation.from_euler("x", 90, degrees=True).as_matrix()
    trans = np.array([[5.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]])
    pos, grot = forward_kinematics(rot, trans, parents, return_rotations=True)
    # joint 1: root + Rz90 (1,0,0) = (5,1,0); joint 2: + Rz90 Rx90 (0,2,0) = + Rz90 (0,0,2) = (5,1,2)
    np.testing.assert_allclose(pos, [[5, 0, 0], [5, 1, 0], [5, 1, 2]], atol=1e-12)
    np.testing.assert_allclose(grot[2], rot[0] @ rot[1], atol=1e-12)


def _random_tree(rng, joints):
    return [-1] + [int(rng.integers(0, j)) for j in range(1, joints)]


def test_torch_fk_equals_numpy_fk():
    rng = np.random.default_rng(1)
    parents = _random_tree(rng, 9)
    rot = Rotation.random(4 * 6 * 9, random_state=2).as_matrix().reshape(4, 6, 9, 3, 3)
    trans = rng.normal(size=(4, 6, 9, 3)) * 30
    ref = forward_kinematics(rot, trans, parents)
    out = forward_kinematics_torch(torch.from_numpy(rot), torch.from_numpy(trans), parents)
    assert out.dtype == torch.float64 and out.shape == (4, 6, 9, 3)
    np.testing.assert_allclose(out.numpy(), ref, rtol=0, atol=1e-12)
    # The positions depend on the rotations (not just the offsets).
    assert np.abs(ref - forward_kinematics(np.broadcast_to(np.eye(3), (9, 3, 3)), trans, parents)).max() > 1.0


@pytest.mark.parametrize(("rot_lead", "trans_lead"), [((5,), ()), ((), (5,)), ((2, 1), (1, 3))])
def test_torch_fk_broadcasts_like_numpy(rot_lead, trans_lead):
    rng = np.random.default_rng(3)
    parents = [-1, 0, 1, 1]
    rot = Rotation.random(int(np.prod(rot_lead, dtype=int)) * 4, random_state=4).as_matrix()
    rot = rot.reshape(rot_lead + (4, 3, 3))
    trans = rng.normal(size=trans_lead + (4, 3))
    ref = forward_kinematics(rot, trans, parents)
    out = forward_kinematics_torch(torch.from_numpy(rot), torch.from_numpy(trans), parents)
    assert tuple(out.shape) == ref.shape
    np.testing.assert_allclose(out.numpy(), ref, rtol=0, atol=1e-12)


@pytest.mark.realdata
def test_torch_fk_on_real_motion(other_skeleton_paths):
    motion = read_bvh(other_skeleton_paths["cmu21_walk"])
    ref = motion.global_positions()
    out = forward_kinematics_torch(
        torch.from_numpy(motion.rotation_matrices()), torch.from_numpy(motion.translations),
        motion.skeleton.parents,
    )
    np.testing.assert_allclose(out.numpy(), ref, rtol=0, atol=1e-9)


def test_torch_fk_gradcheck():
    parents = [-1, 0, 1, 1]
    rot = torch.from_numpy(Rotation.random(2 * 4, random_state=5).as_matrix().reshape(2, 4, 3, 3))
    trans = torch.randn(2, 4, 3, dtype=torch.float64, generator=torch.Generator().manual_seed(6))
    rot.requires_grad_(True)
    trans.requires_grad_(True)
    assert torch.autograd.gradcheck(lambda r, t: forward_kinematics_torch(r, t, parents), (rot, trans))
    # The gradient reaches every joint's rotation that has a child below it.
    forward_kinematics_torch(rot, trans, parents).sum().backward()
    assert rot.grad is not None and trans.grad is not None
    assert torch.all(rot.grad[:, :2].abs().sum(dim=(-1, -2)) > 0)
    assert torch.all(trans.grad.abs().sum(dim=-1) > 0)
