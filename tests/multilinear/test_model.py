import numpy as np
import pytest

from stylemotion.datasets import load_dataset
from stylemotion.io.bvh import read_bvh
from stylemotion.io.export import write_motion_bvh
from stylemotion.multilinear.compare import PCA, fit_natural_weights, path_error, pose_error, project_technical
from stylemotion.multilinear.model import TensorDesignError, build_model
from stylemotion.multilinear.warping import warp_function, warp_positions
from stylemotion.representation import positions_to_frames
from stylemotion.skeleton import JOINT_INDEX


@pytest.fixture(scope="module")
def examples():
    """Two actors (the synthetic walks, and the same walks on a body 10 % larger) × two styles × two takes."""
    takes = load_dataset("synthetic").takes
    out = {}
    for style in ("normal", "elderly"):
        walks = [t.positions.astype(np.float64) for t in takes if t.content == "walk" and t.style == style][:2]
        out[("small", style)] = walks
        out[("tall", style)] = [w * 1.1 for w in walks]
    return out


@pytest.fixture(scope="module")
def built(examples):
    return build_model("walk", examples, 30.0, warping="physics")


def test_unit_coefficients_return_the_warped_example_and_its_root_path(built, examples):
    model, theta, stats = built
    assert theta.shape == (66, model.frames, 2, 2, 2) and stats.cells.shape == (2, 2, 2)
    motion = examples[("tall", "elderly")][1]
    w, _ = warp_function(model.reference, motion, 30.0, "physics")
    warped = warp_positions(motion, w)
    frames = model.synthesize_frames(actor={"tall": 1}, style={"elderly": 1}, repetition={"1": 1})
    assert np.abs(frames - theta[:, :, 1, 0, 1].T).max() < 1e-10
    start = warped[0, JOINT_INDEX["Hips"], [0, 2]]
    _, xz, yaw = positions_to_frames(warped, 30.0)
    positions = model.synthesize(actor={"tall": 1}, style={"elderly": 1}, repetition={"1": 1}, start_xz=xz,
                                 start_yaw=yaw)
    assert np.abs(positions - warped).max() < 1e-4                   # metres (float32 frames)
    assert np.allclose(xz, start)


def test_blended_styles_travel_between_the_two(built):
    model, _, _ = built
    distance = {}
    for name, style in [("normal", {"normal": 1}), ("elderly", {"elderly": 1}),
                        ("half", {"normal": 0.5, "elderly": 0.5})]:
        p = model.synthesize(style=style)
        distance[name] = float(np.linalg.norm(p[-1, 0, [0, 2]] - p[0, 0, [0, 2]]))
    low, high = sorted([distance["normal"], distance["elderly"]])
    assert high - low > 0.1 and low < distance["half"] < high


def test_export_writes_one_skeleton(built, tmp_path):
    model, _, _ = built
    offsets = model.rest_offsets()
    for k, style in enumerate([{"normal": 1}, {"normal": 0.5, "elderly": 0.5}]):
        write_motion_bvh(model.synthesize(style=style), tmp_path / f"m{k}.bvh", model.fps, offsets)
    a, b = (read_bvh(tmp_path / f"m{k}.bvh") for k in range(2))
    assert a.num_frames == b.num_frames == model.frames
    assert np.allclose(a.skeleton.offsets, b.skeleton.offsets)


def test_truncated_models_and_the_held_out_measures(built, examples):
    model, theta, _ = built
    x = theta[:, :, 0, 1, 0].T
    fitted, (alpha, beta, gamma) = fit_natural_weights(model, x)
    assert pose_error(fitted, x) < 1e-6 and path_error(fitted, x, 30.0) < 1e-6
    assert np.allclose(np.einsum("a,b,c->abc", alpha, beta, gamma),
                       np.einsum("a,b,c->abc", model.factors[2][0], model.factors[3][1], model.factors[4][0]))
    assert np.allclose(project_technical(model, x), x)
    small = model.truncated((10, 20, 2, 2, 2))
    assert 0 < pose_error(project_technical(small, x), x) < 0.05
    rows = theta.reshape(66 * model.frames, -1).T
    pca = PCA(rows)
    assert np.allclose(pca.reconstruct(rows, pca.max_components), rows)
    with pytest.raises(ValueError, match="k must"):
        pca.reconstruct(rows, 99)


def test_an_incomplete_design_is_named(examples):
    partial = {k: v for k, v in examples.items() if k != ("tall", "normal")}
    with pytest.raises(TensorDesignError, match="tall"):
        build_model("walk", partial, 30.0)
    with pytest.raises(TensorDesignError, match="repetitions"):
        build_model("walk", examples, 30.0, repetitions=5)
