"""Keyframe boxes of a primitive's tree: true lower bounds of every constraint kind, branch and bound reaching
brute force, and the beam search for constraints off the keyframes."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.morphable.bounds import KEYFRAME_TIMES, best_code, clustering_features, keyframe_values
from stylemotion.morphable.constraints import KeyframeConstraint, objective
from stylemotion.morphable.tree import brute_force
from stylemotion.skeleton import CANONICAL_JOINTS


def _constraints(model, seed: int, frame: float = 1.0) -> list[KeyframeConstraint]:
    code = model.gmm.sample(1, seed=seed)
    index = int(round(frame * (model.length - 1)))
    pos, rot = model.poses_at(code, [index], rotations=True)
    hand, foot = CANONICAL_JOINTS.index("Hand_R"), CANONICAL_JOINTS.index("Foot_L")
    return [KeyframeConstraint("position", pos[0, 0, hand] + 0.01, joint="Hand_R", frame=frame),
            KeyframeConstraint("orientation", rot[0, 0, foot], joint="Foot_L", frame=frame),
            KeyframeConstraint("pose", pos[0, 0] - 0.02, frame=frame)]


def test_the_default_tree_clusters_keyframe_values(left_model):
    assert left_model.tree.space == "keyframes"
    features = clustering_features(left_model, left_model.tree.latent[:5])
    pos, rot = keyframe_values(left_model, left_model.tree.latent[:5])
    assert features.shape == (5, len(KEYFRAME_TIMES) * 21 * 12) and pos.shape == (5, 2, 21, 3)
    assert np.allclose(features[:, : 2 * 21 * 3], pos.reshape(5, -1))


@pytest.mark.parametrize("kind", ["position", "orientation", "pose"])
@pytest.mark.parametrize("frame", [0.0, 1.0])
def test_node_bounds_never_exceed_the_error_of_any_code_below(left_model, kind, frame):
    bounds = left_model.keyframe_bounds()
    tree = left_model.tree
    constraint = next(c for c in _constraints(left_model, seed=5, frame=frame) if c.kind == kind)
    bound = bounds.lower_bound([constraint], left_model.length)
    cost = objective(left_model, [constraint])(tree.latent)
    nodes = np.arange(len(tree.start))
    lower, _ = bound(nodes)
    smallest = np.array([cost[tree.start[n]:tree.stop[n]].min() for n in nodes])
    assert (lower <= smallest + 1e-6).all()
    assert (lower > 0).mean() > 0.3  # and they are informative: most nodes are bounded away from zero


def test_best_code_reaches_brute_force_for_keyframe_constraints(left_model):
    for seed in range(3):
        constraints = _constraints(left_model, seed=20 + seed)
        cost = objective(left_model, constraints)
        exact = brute_force(left_model.tree.latent, cost)
        found = best_code(left_model, constraints, max_evaluations=len(left_model.tree.latent))
        assert found.exact and found.cost == pytest.approx(exact.cost)
        budgeted = best_code(left_model, constraints)  # the default budget of 120
        assert budgeted.evaluations < 120 + 4 and budgeted.cost <= 1.5 * exact.cost


def test_constraints_off_the_keyframes_use_the_beam_search(left_model):
    constraints = _constraints(left_model, seed=7, frame=0.5)
    assert left_model.keyframe_bounds().lower_bound(constraints, left_model.length) is None
    found = best_code(left_model, constraints, candidates=4)
    beam = left_model.tree.search(objective(left_model, constraints), 4)
    assert found.index == beam.index and not found.exact and found.bound_checks == 0


def test_unknown_tree_space_is_refused(left_model):
    with pytest.raises(ValueError, match="unknown tree space 'pca'"):
        left_model.build_tree(100, space="pca")


def test_a_frames_model_bounds_positions_and_poses(left_clips):
    from stylemotion.morphable import FitSettings, fit_primitive

    model = fit_primitive(left_clips["train"], FitSettings(representation="frames", latent_dim=3, reduction="fpca",
                                                           num_coefficients=6))
    model.build_tree(400, seed=0)  # keyframe space: positions only (the frames have no joint orientations)
    assert model.tree.space == "keyframes" and model.keyframe_bounds().rotation_lo is None
    code = model.gmm.sample(1, seed=3)
    target = model.poses_at(code, [model.length - 1])[0, 0]
    pose = KeyframeConstraint("pose", target + 0.01)
    exact = brute_force(model.tree.latent, objective(model, [pose]))
    found = best_code(model, [pose], max_evaluations=len(model.tree.latent))
    assert found.exact and found.cost == pytest.approx(exact.cost)
    turn = KeyframeConstraint("orientation", np.eye(3), joint="Hips")
    assert model.keyframe_bounds().lower_bound([turn], model.length) is None  # no rotation boxes: beam search
