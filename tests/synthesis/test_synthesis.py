"""Controlled synthesis: ground paths, the motion graph, stitching, path following and
``stylemotion-generate`` (on tiny VAEs trained on the synthetic data), including bad input."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
import torch
from vae_fixtures import feature_module, fit, tiny_autoencoder_ckpt

from stylemotion.io.outputs import OutputExistsError
from stylemotion.models.vae import PrimitiveVAE
from stylemotion.representation import frames_to_positions, positions_to_frames
from stylemotion.skeleton import bone_lengths
from stylemotion.synthesis import (
    FollowSettings,
    GroundPath,
    MotionGraph,
    PathError,
    SharpTurnWarning,
    UnknownStyleError,
    follow_path,
    load_graph,
    s_curve,
)
from stylemotion.synthesis.generate import generate
from stylemotion.synthesis.graph import TRANSITIONS, relocated
from stylemotion.synthesis.stitching import append_clip, blend_weights, transition_speed_ratio

torch.set_num_threads(1)


# -- paths


def test_path_arc_length_points_headings_and_projection() -> None:
    path = GroundPath.from_points([[0, 0], [0, 3], [4, 3]])
    assert path.length == pytest.approx(7.0)
    np.testing.assert_allclose(path.point_at(5.0), [2.0, 3.0])
    assert path.heading_at(1.0) == pytest.approx(0.0)            # along +Z
    assert path.heading_at(4.0) == pytest.approx(math.pi / 2)    # along +X
    s, d = path.project(np.array([[1.0, 1.0], [5.0, 2.0]]))
    np.testing.assert_allclose(s, [1.0, 7.0])
    np.testing.assert_allclose(d, [1.0, math.hypot(1.0, 1.0)])


def test_s_curve_has_the_requested_length_and_bends_both_ways() -> None:
    path = s_curve(10.0, amplitude_m=1.0)
    assert path.length == pytest.approx(10.0, abs=2e-3)
    x = path.points[:, 0]
    assert x.max() == pytest.approx(1.0, abs=1e-3) and x.min() == pytest.approx(-1.0, abs=1e-3)


def test_spline_passes_through_its_points(tmp_path: Path) -> None:
    points = [[0, 0], [0.5, 2], [0, 4], [-0.5, 6]]
    path = GroundPath.from_points(points, spline=True)
    _, d = path.project(np.asarray(points, dtype=float))
    assert d.max() < 1e-4  # sampled every 2 cm: the control points lie on the polyline to 0.1 mm
    assert path.length > 6.0


def test_path_files_json_and_csv(tmp_path: Path) -> None:
    (tmp_path / "p.json").write_text(json.dumps({"points": [[0, 0], [0, 2]]}))
    (tmp_path / "p.csv").write_text("# a path\nx,z\n0,0\n0,2\n1,3\n")
    assert GroundPath.from_file(tmp_path / "p.json").length == pytest.approx(2.0)
    assert GroundPath.from_file(tmp_path / "p.csv", spline=False).length == pytest.approx(2.0 + math.sqrt(2))


@pytest.mark.parametrize("points, message", [
    ([[0, 0]], "at least two distinct points"),
    ([[1, 1], [1, 1]], "at least two distinct points"),
    ([[0, 0], [0, float("nan")]], "point 1 is not finite"),
    ([0, 1, 2], "must be (n, 2)"),
])
def test_bad_paths_are_refused(points, message) -> None:
    with pytest.raises(PathError, match=message.replace("(", r"\(").replace(")", r"\)")):
        GroundPath.from_points(points)


def test_bad_path_files_name_the_file_and_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("x,z\n0,0\n0,oops\n")
    with pytest.raises(PathError, match=r"bad.csv:3: not a number"):
        GroundPath.from_file(bad)
    broken = tmp_path / "broken.json"
    broken.write_text("[[0, 0],\n [0, 1]")
    with pytest.raises(PathError, match=r"broken.json:2: not valid JSON"):
        GroundPath.from_file(broken)
    with pytest.raises(PathError, match="does not exist"):
        GroundPath.from_file(tmp_path / "missing.csv")


# -- stitching


def _walk_frames(seconds: float = 1.0, fps: float = 30.0, speed: float = 1.0, bob: float = 0.0) -> np.ndarray:
    """66-dim frames of a body gliding forward, its joints bobbing up and down ``bob`` metres once a second."""
    t = np.arange(int(seconds * fps) + 1) / fps
    rest = np.random.default_rng(0).normal(scale=0.3, size=(21, 3))
    rest[:, 1] = np.abs(rest[:, 1]) + 0.1
    rest[[5, 9, 13, 17], 0] = [0.2, -0.2, 0.1, -0.1]  # shoulders/hips across: facing +Z
    pos = np.repeat(rest[None], len(t), 0)
    pos[:, :, 2] += speed * t[:, None]
    pos[:, :, 1] += bob * np.sin(2 * np.pi * t)[:, None] * np.linspace(0.5, 1.5, 21)
    frames, _, _ = positions_to_frames(pos, fps, smooth_seconds=0.0)
    return frames.astype(np.float64)


def test_append_clip_joins_at_the_shared_keyframe_and_fades_the_jump() -> None:
    a, b = _walk_frames(), _walk_frames()
    b[:, :63] += 0.05  # the next clip starts 5 cm off in every coordinate
    motion, junction = append_clip(None, a, 6)
    motion, junction = append_clip(motion, b, 6)
    assert junction == len(a) - 1 and len(motion) == len(a) + len(b) - 1
    np.testing.assert_allclose(motion[junction], a[-1])              # continuous at the keyframe
    np.testing.assert_allclose(motion[junction + 6:], b[6:])          # the clip's own frames after the blend
    jumps = np.abs(np.diff(motion[:, :63], axis=0)).max(1)
    assert jumps.max() < 0.05 / 2                                      # no 5 cm pop between frames
    hard, _ = append_clip(append_clip(None, a, 0)[0], b, 0)
    assert np.abs(np.diff(hard[:, :63], axis=0)).max() == pytest.approx(0.05)


def test_blend_weights_fall_from_one() -> None:
    w = blend_weights(6)
    assert w[0] == 1.0 and np.all(np.diff(w) < 0) and w[-1] > 0
    assert len(blend_weights(0)) == 0
    with pytest.raises(ValueError):
        blend_weights(-1)


def test_transition_ratio_sees_a_pop() -> None:
    a = _walk_frames(bob=0.05)
    motion, j = append_clip(append_clip(None, a, 0)[0], a + np.r_[np.full(63, 0.08), np.zeros(3)], 0)
    pos = frames_to_positions(motion, 30.0)
    popped = transition_speed_ratio(pos, 30.0, [j])
    smooth = transition_speed_ratio(frames_to_positions(append_clip(append_clip(None, a, 0)[0], a, 0)[0], 30.0),
                                    30.0, [j])
    assert popped["ratio"] > 2.0 and smooth["ratio"] < 1.2
    assert popped["accel_ratio"] > 2.0 and smooth["accel_ratio"] < 1.2


# -- graph and path following on tiny models


@pytest.fixture(scope="module")
def tiny_models(tmp_path_factory) -> dict[str, Path]:
    """Neutral tiny VAEs of both walk stances (trained for a few seconds on the synthetic data)."""
    folder = tmp_path_factory.mktemp("synthesis")
    ae = tiny_autoencoder_ckpt(folder / "ae")
    paths = {}
    for primitive in ("walk_leftStance", "walk_rightStance"):
        torch.manual_seed(0)
        dm = feature_module(ae, primitive=primitive)
        fit(PrimitiveVAE(samples_per_item=4), dm, steps=150, folder=folder / primitive)
        paths[primitive] = folder / primitive / "best.ckpt"
    return paths


@pytest.fixture(scope="module")
def tiny_graph(tiny_models) -> MotionGraph:
    graph = load_graph("neutral", models={k: str(v) for k, v in tiny_models.items()})
    graph.profile()
    return graph


def test_graph_transitions_alternate_the_planted_foot(tiny_graph: MotionGraph) -> None:
    for primitive, successors in TRANSITIONS.items():
        foot = "Left" if "Left" in primitive or primitive.startswith("left") else "Right"
        for nxt in successors:
            assert (foot == "Left") == ("Right" in nxt or nxt.startswith("right"))
    assert tiny_graph.first("left") == "leftStance"
    assert tiny_graph.next("leftStance") == "rightStance" and tiny_graph.next("rightStance", last=True) == "leftStance"
    for p in ("leftStance", "rightStance"):
        assert 0.2 < tiny_graph.profiles[p].length_m < 1.5


def test_following_is_seeded_and_stays_near_the_path(tiny_graph: MotionGraph) -> None:
    path = GroundPath.from_points([[0, 0], [0.3, 4]])  # the tiny models only saw (nearly) straight walks
    a = follow_path(tiny_graph, path, seed=1)
    b = follow_path(tiny_graph, path, seed=1)
    c = follow_path(tiny_graph, path, seed=2)
    np.testing.assert_array_equal(a.positions, b.positions)
    assert a.positions.shape != c.positions.shape or not np.allclose(a.positions, c.positions)
    assert [s.primitive for s in a.steps][:3] == ["leftStance", "rightStance", "leftStance"]
    _, dev = path.project(a.root_xz)
    assert np.linalg.norm(a.root_xz[-1] - path.end) < 0.3
    # the search does better than a single prior draw per step (no optimization)
    blind = follow_path(tiny_graph, path, seed=1, settings=FollowSettings(candidates=1, iterations=0))
    _, blind_dev = path.project(blind.root_xz)
    assert dev.mean() < blind_dev.mean()
    assert all(s.cost_final <= s.cost_best_candidate + 1e-6 for s in a.steps)


def test_a_turn_sharper_than_any_step_warns_and_still_walks(tiny_graph: MotionGraph) -> None:
    hairpin = GroundPath.from_points([[0, 0], [0, 1.5], [0.3, 1.5], [0.3, 0]])
    with pytest.warns(SharpTurnWarning, match="turns .* within one step"):
        motion = follow_path(tiny_graph, hairpin, seed=0, settings=FollowSettings(iterations=5, max_steps=20))
    assert motion.warnings and len(motion.steps) >= 2


def test_a_path_shorter_than_half_a_step_is_refused(tiny_graph: MotionGraph) -> None:
    from stylemotion.io.errors import UserInputError

    with pytest.raises(UserInputError, match="shorter than half a step"):  # one line, not a traceback (issue 26)
        follow_path(tiny_graph, GroundPath.from_points([[0, 0], [0, 0.05]]))


def test_unknown_style_lists_the_styles_there_are(tmp_path: Path, tiny_models) -> None:
    report = tmp_path / "run" / "report"
    report.mkdir(parents=True)
    entries = [{"primitive": p, "name": "neutral", "style": "normal", "path": str(c)} for p, c in tiny_models.items()]
    (report / "report.json").write_text(json.dumps({"meta": {"checkpoints": entries}}))
    assert set(load_graph("normal", run=tmp_path / "run").models) == {"leftStance", "rightStance"}
    with pytest.raises(UnknownStyleError, match=r"style 'sleepy' has no walk model .* styles there: \['neutral'\]"):
        load_graph("sleepy", run=tmp_path / "run")
    with pytest.raises(FileNotFoundError, match="report.json does not exist"):
        load_graph("neutral", run=tmp_path / "nowhere")
    with pytest.raises(ValueError, match="needs leftStance and rightStance"):
        load_graph("neutral", models={"walk_leftStance": str(tiny_models["walk_leftStance"])})


def test_a_moved_run_folder_still_loads(tmp_path: Path, tiny_models) -> None:
    """The report records absolute paths; a run copied elsewhere finds its files under its own folder."""
    run, old = tmp_path / "moved", Path("/nonexistent/runs/reproduce/old")
    entries = []
    for primitive, ckpt in tiny_models.items():
        (run / "vae" / primitive).mkdir(parents=True)
        shutil.copy(ckpt, run / "vae" / primitive / "best.ckpt")
        entries.append({"primitive": primitive, "name": "neutral", "style": "normal",
                        "path": str(old / "vae" / primitive / "best.ckpt")})
    ae_info = dict(torch.load(tiny_models["walk_leftStance"], map_location="cpu",
                              weights_only=True)["hyper_parameters"]["spec"]["autoencoder"])
    (run / "autoencoder").mkdir()
    shutil.copy(ae_info["path"], run / "autoencoder" / "best.ckpt")
    (run / "report").mkdir()
    meta = {"checkpoints": entries, "autoencoder": {"path": str(old / "autoencoder" / "best.ckpt"),
                                                    "fingerprint": ae_info["fingerprint"]}}
    (run / "report" / "report.json").write_text(json.dumps({"meta": meta}))
    assert relocated(old / "autoencoder" / "best.ckpt", run) == str(run / "autoencoder" / "best.ckpt")
    graph = load_graph("neutral", run=run)
    assert graph.sources["leftStance"] == str(run / "vae" / "walk_leftStance" / "best.ckpt")
    assert graph.models["leftStance"].autoencoder is graph.models["rightStance"].autoencoder
    assert relocated(old / "vae" / "missing.ckpt", run) == str(old / "vae" / "missing.ckpt")


# -- stylemotion-generate


def test_generate_writes_motion_bvh_gif_and_summary(tmp_path: Path, tiny_models) -> None:
    cfg = {"models": {k: str(v) for k, v in tiny_models.items()}, "style": "neutral", "seed": 0,
           "path": {"points": [[0, 0], [0, 3]], "spline": True},
           "follow": {"iterations": 10}, "outputs": {"bvh": True, "gif": True}, "out": str(tmp_path / "walk")}
    summary = generate(cfg)
    out = tmp_path / "walk"
    with np.load(out / "motion.npz") as npz:
        assert npz["positions"].shape[1:] == (21, 3) and float(npz["fps"]) == 30.0
        assert npz["frames"].shape == (len(npz["positions"]), 66)
    on_disk = json.loads((out / "summary.json").read_text())
    for key in ("deviation", "duration_s", "mean_speed_mps", "foot_skating_ratio", "transitions",
                "bvh_reimport_mpjpe_m", "synthesis_seconds", "meta", "steps_detail"):
        assert key in on_disk, key
    assert summary["bvh_reimport_mpjpe_m"] < 0.02
    # rigid bones: every bone of motion.npz keeps one length, so the BVH reads back with every joint within 1 cm
    assert summary["bvh_reimport_max_m"] < 0.01 and summary["rigid_bones"]["bone_length_spread_before"] > 0
    with np.load(out / "motion.npz") as npz:
        lengths = bone_lengths(npz["positions"].astype(np.float64))[:, 1:]
    assert float((lengths.max(0) - lengths.min(0)).max()) < 1e-4
    assert (out / "motion.gif").stat().st_size > 10_000 and (out / "motion.bvh").is_file()
    with pytest.raises(OutputExistsError, match="exists"):
        generate(cfg)
    before = (out / "summary.json").read_bytes()
    generate({**cfg, "force": True, "outputs": {"bvh": False, "gif": False}})
    assert (out / "summary.json").read_bytes() != before and not (out / "motion.gif").exists()
