"""Graph walk with look-ahead (§4.5.1): the choice among a step's variants, turn variants of clips, and
variants loaded for stylemotion-generate."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from stylemotion.config import ConfigError
from stylemotion.geometry import rotate_yaw_xz
from stylemotion.morphable import FitSettings, fit_primitive
from stylemotion.morphable.lookahead import MeanStep, choose, mean_step, step_states
from stylemotion.morphable.synthesis import MapSettings, MorphablePrimitive
from stylemotion.morphable.variants import clip_turn_deg, select_turn, variant_name
from stylemotion.synthesis import follow_path
from stylemotion.synthesis.morphable_graph import load_morphable_graph
from stylemotion.synthesis.path import GroundPath

STRAIGHT = MeanStep("straight", np.array([0.0, 0.6]), 0.0)
LEFT = MeanStep("turn-left", np.array([0.1, 0.55]), math.radians(30))


def test_looking_ahead_turns_early_where_the_greedy_choice_does_not():
    # the targets are where two turning steps end, except that the first asks for no turn yet and lies halfway
    # between where a straight and a turning step end: greedy keeps straight, two steps ahead turn at once
    first_left = LEFT.displacement
    second = first_left + rotate_yaw_xz(LEFT.displacement, LEFT.turn)
    targets = [((STRAIGHT.displacement + first_left) / 2, 0.0), (second, 2 * LEFT.turn)]
    greedy = choose([[STRAIGHT, LEFT]], np.zeros(2), 0.0, targets[:1], 0.05, 0.15)
    ahead = choose([[STRAIGHT, LEFT], [STRAIGHT, LEFT]], np.zeros(2), 0.0, targets, 0.05, 0.15)
    assert greedy.index == 0 and ahead.index == 1 and ahead.sequence == ["turn-left", "turn-left"]
    # the cost of the best sequence that starts turning: only the first step's error (30° of heading, half the gap)
    gap = float(((first_left - targets[0][0]) ** 2).sum())
    assert ahead.first_costs[1] == pytest.approx(gap / 0.05 ** 2 + LEFT.turn ** 2 / 0.15 ** 2)
    with pytest.raises(ValueError, match="at least one target"):
        choose([[STRAIGHT]], np.zeros(2), 0.0, [], 0.05, 0.15)


def test_turn_variants_split_the_clips_by_heading_change(left_clips):
    clips = left_clips["train"]
    turns = np.array([clip_turn_deg(c) for c in clips])
    parts = {t: select_turn(clips, t, 5.0) for t in ("straight", "left", "right")}
    assert sum(len(p) for p in parts.values()) == len(clips) and all(parts.values())
    assert all(clip_turn_deg(c) > 5.0 for c in parts["left"]) and all(clip_turn_deg(c) < -5.0 for c in parts["right"])
    # walk-turn-left clips turn left (positive), walk-turn-right clips right
    contents = np.array([c.content for c in clips])
    assert np.median(turns[contents == "walk-turn-left"]) > 0 > np.median(turns[contents == "walk-turn-right"])
    assert select_turn(clips, None) == list(clips)
    assert variant_name("left") == "turn-left" and variant_name(None) == "all"
    with pytest.raises(ValueError, match="unknown turn variant 'up'"):
        select_turn(clips, "up")


@pytest.fixture(scope="module")
def turn_models(left_clips, right_clips):
    models = {}
    for side, clips in (("leftStance", left_clips), ("rightStance", right_clips)):
        for turn in (None, "left", "right"):
            chosen = select_turn(clips["train"], turn, 5.0)
            model = fit_primitive(chosen, FitSettings(latent_dim=3, reduction="fpca", num_coefficients=6),
                                  meta={"variant": variant_name(turn)})
            model.build_tree(300, seed=0)
            models[(side, variant_name(turn))] = model
    return models


def test_turn_variants_mean_steps_turn_their_way(turn_models):
    for side in ("leftStance", "rightStance"):
        turns = {v: mean_step(turn_models[(side, v)], v).turn for v in ("all", "turn-left", "turn-right")}
        assert turns["turn-left"] > turns["all"] > turns["turn-right"]
    state = step_states(turn_models[("leftStance", "all")], turn_models[("leftStance", "all")].gmm.means[:2])
    assert state["displacement"].shape == (2, 2) and state["first_pose"].shape == (2, 63)


def test_the_walk_chooses_variants_and_decodes_with_them(turn_models, tmp_path):
    paths = {}
    for (side, variant), model in turn_models.items():
        paths.setdefault(f"walk_{side}", []).append(str(model.save(tmp_path / side / variant / "model.npz")))
    graph = load_morphable_graph(paths, settings=MapSettings(lookahead_steps=2))
    node = graph.models["leftStance"]
    assert sorted(node.variants) == ["all", "turn-left", "turn-right"]
    assert node.following and node.following[0] is graph.models["rightStance"]
    used = {}
    for side in (1, -1):  # an arc of radius 3 m bending left (+X, the body's left at the start), then right
        phi = np.linspace(0.0, 4.0 / 3.0, 60)
        arc = GroundPath.from_points(np.stack([side * 3.0 * (1 - np.cos(phi)), 3.0 * np.sin(phi)], axis=1))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            walk = follow_path(graph, arc, seed=0)
        used[side] = [s.variant for s in walk.steps]
    # ~12° per step (76° in ~6 steps): the turn variants' mean steps (±7–10°; unsplit −2°) are closest
    assert used[1].count("turn-left") > len(used[1]) / 2 and used[-1].count("turn-right") > len(used[-1]) / 2
    step = walk.steps[0]
    chosen = graph.models[step.primitive].variants[step.variant]
    decoded = chosen.decode_latent(np.asarray(step.latent)[None])
    assert abs(float(decoded.duration_s[0]) - step.duration_s) < 1e-5  # the step was decoded by its variant
    with pytest.raises(ConfigError, match="empty list"):
        load_morphable_graph({**paths, "walk_leftStance": []})
    with pytest.raises(ValueError, match="lookahead_steps"):
        MapSettings(lookahead_steps=0)
    same = MorphablePrimitive([turn_models[("leftStance", "all")]] * 2)  # same variant name twice: suffixed
    assert list(same.variants) == ["all", "all_1"]


def test_variants_of_different_shapes_sample_together(turn_models, left_clips):
    other = fit_primitive(select_turn(left_clips["train"], "left", 5.0),
                          FitSettings(latent_dim=2, reduction="fpca", num_coefficients=5), meta={"variant": "small"})
    node = MorphablePrimitive([turn_models[("leftStance", "all")], other])
    samples = node.sample(10, seed=0)
    assert samples.positions.shape[0] == 10 and samples.num_frames.shape == (10,)
    assert samples.latent.shape == (10, 0) and samples.features.shape[1] == 0  # codes of different spaces: dropped
