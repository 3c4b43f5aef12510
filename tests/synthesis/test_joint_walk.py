"""Du's Algorithm 1, line 9: all steps of a Morphable Graph walk optimized together, checked against the stitcher
itself (the walk re-stitched from the codes) and against the greedy walk it starts from."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from stylemotion.morphable import FitSettings, fit_primitive
from stylemotion.morphable.synthesis import MapSettings, MorphablePrimitive
from stylemotion.synthesis import follow_path, s_curve
from stylemotion.synthesis.controller import restitch
from stylemotion.synthesis.graph import MotionGraph
from stylemotion.synthesis.joint_walk import JointStep, optimize_steps, walk_objective
from stylemotion.synthesis.morphable_graph import finish_walk, optimize_walk, target_error
from stylemotion.synthesis.quality import walk_figures
from stylemotion.synthesis.settings import FollowSettings


@pytest.fixture(scope="module")
def graph():
    from stylemotion.datamodules.clips import ClipDataModule
    from stylemotion.datasets.registry import load_synthetic

    takes = load_synthetic(takes_per_pair=6, seed=0, duration_s=6.0, styles=["normal"],
                           contents=["walk", "walk-turn-left", "walk-turn-right"])
    nodes = {}
    for primitive in ("leftStance", "rightStance"):
        dm = ClipDataModule(takeset=takes, primitives=[primitive], styles=["normal"],
                            split={"seed": 0, "val_fraction": 0.0, "test_fraction": 0.2})
        dm.setup()
        model = fit_primitive(dm.clips["train"], FitSettings(latent_dim=6, reduction="fpca", num_coefficients=6))
        nodes[primitive] = MorphablePrimitive(model, MapSettings(max_evaluations=40, joint_evaluations=30))
    return MotionGraph("walk", "normal", nodes)


@pytest.fixture(scope="module")
def walk(graph):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return follow_path(graph, s_curve(4.0, amplitude_m=0.5, waves=1.0), seed=1)


def _steps(graph, walk, latents=None):
    latents = latents or [s.latent for s in walk.steps]
    return [JointStep(graph.models[s.primitive].model, np.asarray(z, dtype=np.float64), np.asarray(s.target_xz),
                      s.target_yaw) for s, z in zip(walk.steps, latents)]


def test_the_objective_places_steps_where_the_stitched_walk_ends_them(graph, walk):
    """The joint objective's chain (decode, blend, integrate) against the controller's own stitching, at the walk's
    codes and at codes moved away from them."""
    follow = FollowSettings()
    _, ends = walk_objective(_steps(graph, walk), walk.path.start, float(walk.path.heading_at(0.0)), follow)
    stitched = np.array([[*s.end_xz, s.end_yaw] for s in walk.steps])
    assert np.abs(ends - stitched).max() < 1e-9
    rng = np.random.default_rng(0)
    moved = [np.asarray(s.latent) + 0.3 * rng.normal(size=len(s.latent)) for s in walk.steps]
    decoders = [graph.models[s.primitive].model.decode_latent for s in walk.steps]
    again = restitch(walk, decoders, moved, follow)
    _, ends = walk_objective(_steps(graph, walk, moved), walk.path.start, float(walk.path.heading_at(0.0)), follow)
    assert np.abs(ends - np.array([[*s.end_xz, s.end_yaw] for s in again.steps])).max() < 1e-9
    assert np.abs(ends - stitched).max() > 1e-3  # the moved codes do walk elsewhere


def test_restitching_the_walks_own_codes_gives_the_walk(graph, walk):
    decoders = [graph.models[s.primitive].model.decode_latent for s in walk.steps]
    again = restitch(walk, decoders, [np.asarray(s.latent) for s in walk.steps], FollowSettings())
    assert np.allclose(again.frames, walk.frames, atol=1e-6)
    assert again.junctions == walk.junctions


def test_joint_optimization_lowers_the_objective_and_brings_steps_nearer_their_targets(graph, walk):
    follow = FollowSettings()
    joint, record = optimize_walk(graph, walk, follow, 30)
    assert record["kept"] and record["objective_after"] < record["objective_before"]
    assert record["target_error_after"] == pytest.approx(target_error(joint, follow))
    assert record["target_error_after"] < record["target_error_before"]
    assert walk_figures(joint)["deviation"]["mean_m"] < walk_figures(walk)["deviation"]["mean_m"]
    assert [s.primitive for s in joint.steps] == [s.primitive for s in walk.steps]
    assert [s.target_xz for s in joint.steps] == [s.target_xz for s in walk.steps]


def test_a_walk_already_at_the_optimum_is_returned_as_it_is(graph, walk):
    follow = FollowSettings()
    joint, _ = optimize_walk(graph, walk, follow, 30)
    again, record = optimize_walk(graph, joint, follow, 30)
    assert record["objective_after"] <= record["objective_before"]
    if not record["kept"]:
        assert again is joint


def test_finish_walk_runs_only_when_asked(graph, walk):
    follow = FollowSettings()
    done, record = finish_walk(graph, walk, follow)
    assert record is not None and record["kept"]
    off = MotionGraph("walk", "normal", {k: MorphablePrimitive(n.model, MapSettings(joint_evaluations=0))
                                         for k, n in graph.models.items()})
    same, none = finish_walk(off, walk, follow)
    assert same is walk and none is None


def test_bad_joint_settings_are_refused(graph, walk):
    with pytest.raises(ValueError, match="joint_evaluations"):
        MapSettings(joint_evaluations=-1)
    with pytest.raises(ValueError, match="at least one step"):
        optimize_steps([], np.zeros(2), 0.0, FollowSettings())


def test_the_jacobian_equals_differences_of_the_whole_walk(graph, walk):
    """The Jacobian recomputes only the moved step and those its blend reaches; against differences of the full
    objective recomputed from scratch."""
    from stylemotion.synthesis.joint_walk import DIFFERENCE_STEP, _Walk

    chain = _Walk(_steps(graph, walk), walk.path.start, float(walk.path.heading_at(0.0)), FollowSettings())
    x = np.concatenate([np.asarray(s.latent, dtype=np.float64) for s in walk.steps])
    jac = chain.jacobian(x)
    base = chain.function(x)
    for k in np.random.default_rng(0).choice(len(x), size=8, replace=False):
        moved = x.copy()
        moved[k] += DIFFERENCE_STEP
        assert np.allclose(jac[:, k], (chain.function(moved) - base) / DIFFERENCE_STEP, rtol=1e-6, atol=1e-6)
