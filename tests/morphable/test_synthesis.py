"""Keyframe constraints solved by the MAP of eq. 4.9, unreachable keyframes reported, path following through
the VAE controller and ``stylemotion-generate``'s library entry."""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

from stylemotion.morphable.constraints import KeyframeConstraint, objective
from stylemotion.morphable.synthesis import (
    MapSettings,
    MorphablePrimitive,
    UnreachableConstraintWarning,
    solve_constraints,
)
from stylemotion.skeleton import CANONICAL_JOINTS
from stylemotion.synthesis import follow_path, s_curve
from stylemotion.synthesis.generate import generate
from stylemotion.synthesis.graph import MotionGraph

HAND = CANONICAL_JOINTS.index("Hand_L")


def test_constraints_name_bad_joints_shapes_and_frames():
    with pytest.raises(ValueError, match="unknown joint 'Hand_Left'"):
        KeyframeConstraint("position", np.zeros(3), joint="Hand_Left")
    with pytest.raises(ValueError, match=r"shape \(3,\)"):
        KeyframeConstraint("position", np.zeros(2), joint="Hand_L")
    with pytest.raises(ValueError, match="normalized time"):
        KeyframeConstraint("pose", np.zeros((21, 3)), frame=2.0)
    with pytest.raises(ValueError, match="unknown constraint kind"):
        KeyframeConstraint("velocity", np.zeros(3), joint="Hand_L")


def test_reachable_keyframes_are_met(left_model):
    code = left_model.gmm.sample(1, seed=11)
    pos, rot = left_model.canonical_positions(code, rotations=True)
    constraints = [KeyframeConstraint("position", pos[0, -1, HAND], joint="Hand_L"),
                   KeyframeConstraint("orientation", rot[0, -1, 0], joint="Hips", frame=1.0)]
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnreachableConstraintWarning)
        result = solve_constraints(left_model, constraints)
    assert max(result.errors_m) < 0.02 and not result.unreachable
    assert result.cost <= result.start_cost  # the MAP objective (constraints + prior) never rises from the tree's pick
    assert result.evaluations > 0 and np.isfinite(result.neg_log_prior)
    assert objective(left_model, constraints)(result.latent[None])[0] == pytest.approx(sum(result.errors_m))


def test_unreachable_keyframe_reports_its_residual(left_model):
    far = KeyframeConstraint("position", np.array([0.0, 3.0, 0.5]), joint="Hand_L", frame=1.0)
    with pytest.warns(UnreachableConstraintWarning, match=r"position constraint on Hand_L at frame 1: residual \d"):
        result = solve_constraints(left_model, [far], MapSettings(max_evaluations=50))
    assert result.unreachable and result.errors_m[0] > MapSettings().tolerance_m
    assert f"residual {result.errors_m[0]:.3f} m" in result.unreachable[0]
    # a hand 3 m up is out of any walk's reach: the solve moves towards it, and what remains is reported
    assert result.errors_m[0] < result.start_errors_m[0]


def test_path_following_through_the_controller(left_model, right_model, tmp_path):
    graph = MotionGraph("walk", "normal", {"leftStance": MorphablePrimitive(left_model),
                                           "rightStance": MorphablePrimitive(right_model)})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        walk = follow_path(graph, s_curve(4.0, amplitude_m=0.2, waves=0.5), seed=0)
    assert [s.primitive for s in walk.steps[:3]] == ["leftStance", "rightStance", "leftStance"]
    deviation = np.linalg.norm(walk.root_xz[-1] - walk.path.end)
    assert deviation < 0.2 and walk.positions.shape[1:] == (21, 3)
    assert all(s.cost_final <= s.cost_best_candidate + 1e-9 for s in walk.steps)
    paths = {"walk_leftStance": str(left_model.save(tmp_path / "l" / "model.npz")),
             "walk_rightStance": str(tmp_path / "r")}
    right_model.save(tmp_path / "r" / "model.npz")
    cfg = {"model": {"family": "morphable"}, "models": paths, "style": "neutral", "seed": 0, "out": str(tmp_path / "g"),
           "path": {"s_curve": {"length_m": 3.0, "amplitude_m": 0.2}}, "outputs": {"bvh": False, "gif": False}}
    summary = generate(cfg)
    saved = json.loads((tmp_path / "g" / "summary.json").read_text())
    assert saved["meta"]["model"] == "morphable" and saved["deviation"]["mean_m"] == summary["deviation"]["mean_m"]
    assert summary["deviation"]["mean_m"] < 0.15  # the end may be up to half a step short (the controller's rule)
    with pytest.raises(ValueError, match="no morphable model at"):
        generate({**cfg, "out": str(tmp_path / "h"), "models": {**paths, "walk_rightStance": str(tmp_path / "none")}})
    with pytest.raises(ValueError, match="holds a walk_leftStance model, not walk_rightStance"):
        generate({**cfg, "out": str(tmp_path / "h"), "models": {"walk_rightStance": paths["walk_leftStance"],
                                                                 "walk_leftStance": paths["walk_leftStance"]}})
