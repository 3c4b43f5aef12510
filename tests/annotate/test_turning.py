"""The turning layer over the template annotation: rates against poses turned by hand, families against templates
built to match or not, the relabelling against runs whose rates are set."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.annotate.templates import MotionTemplate
from stylemotion.annotate.turning import (
    MIN_SD,
    refine_by_turning,
    template_families,
    turning_rate,
    turning_statistics,
)
from stylemotion.datasets.registry import load_synthetic
from stylemotion.geometry import rotate_yaw

FPS = 30.0


@pytest.fixture(scope="module")
def pose() -> np.ndarray:
    take = load_synthetic(takes_per_pair=1, seed=0, duration_s=2.0, styles=["normal"], contents=["walk"]).takes[0]
    frame = np.asarray(take.positions[0], dtype=np.float64)
    return frame - frame[0] * np.array([1.0, 0.0, 1.0])       # the root over the origin


def _turned(pose: np.ndarray, rate: float, seconds: float = 3.0) -> np.ndarray:
    t = np.arange(int(seconds * FPS)) / FPS
    return np.stack([rotate_yaw(pose, rate * s) for s in t])


@pytest.mark.parametrize("rate", [-0.6, 0.0, 0.3, 1.0])
def test_the_rate_of_a_pose_turned_at_a_known_rate(pose, rate):
    assert turning_rate(_turned(pose, rate), FPS) == pytest.approx(rate, abs=0.02)


def test_statistics_per_class_and_the_sd_floor(pose):
    stats = turning_statistics({"walk": [_turned(pose, 0.0), _turned(pose, 0.0)],
                                "turn": [_turned(pose, 0.2), _turned(pose, 0.4)]}, FPS)
    assert stats["walk"]["mean"] == pytest.approx(0.0, abs=0.01) and stats["walk"]["sd"] == MIN_SD
    assert stats["turn"]["mean"] == pytest.approx(0.3, abs=0.02) and stats["turn"]["sd"] == pytest.approx(0.1, abs=0.02)
    assert stats["turn"]["takes"] == 2


def test_families_join_templates_that_match_each_other():
    rng = np.random.default_rng(0)
    walk = (rng.random((40, 12)) > 0.5).astype(float)
    turn = walk.copy()
    turn[:, 0] = 0.5                                          # one feature a wildcard: the same template otherwise
    wave = 1.0 - walk                                         # contradicts walk everywhere
    families = template_families([MotionTemplate("walk", walk, 9), MotionTemplate("turn", turn, 9),
                                  MotionTemplate("wave", wave, 9)], tau=0.05)
    assert families == {"walk": {"turn"}, "turn": {"walk"}, "wave": set()}


def _document_yaw(rates: list[tuple[int, float]]) -> np.ndarray:
    """Unwrapped yaw of a document whose stretches of ``frames`` frames turn at ``rate`` rad/s."""
    steps = np.concatenate([np.full(n, r / FPS) for n, r in rates])
    return np.r_[0.0, np.cumsum(steps)][:-1]


def test_a_run_that_does_not_turn_like_its_class_goes_to_the_family_member_it_turns_like():
    classes = ("walk", "turn-left", "turn-right", "wave")
    stats = {"walk": {"mean": 0.0, "sd": 0.03}, "turn-left": {"mean": 0.3, "sd": 0.08},
             "turn-right": {"mean": -0.3, "sd": 0.08}, "wave": {"mean": 0.0, "sd": 0.02}}
    families = {"walk": {"turn-left", "turn-right"}, "turn-left": {"walk", "turn-right"},
                "turn-right": {"walk", "turn-left"}, "wave": set()}
    # four runs of 60 frames: straight labelled turn-left, turning left labelled turn-left, turning right labelled
    # walk, turning labelled wave (no family: kept)
    labels = np.repeat([1, 1, 0, 3], 60)
    labels[60] = -1                                           # a gap splits the first two runs
    yaw = _document_yaw([(60, 0.0), (60, 0.3), (60, -0.32), (60, 0.5)])
    delta = np.full((4, 240), 0.02)
    out = refine_by_turning(labels, classes, delta, yaw, FPS, stats, families, z=2.0)
    assert (out[:60] == 0).all()                              # straight: walk
    assert (out[61:120] == 1).all()                           # turns left as turn-left does: kept
    assert (out[120:180] == 2).all()                          # turning right: turn-right
    assert (out[180:] == 3).all()                             # wave has no family member: kept
    assert out[60] == -1
    assert (refine_by_turning(labels, classes, delta, yaw, FPS, stats, families, z=100.0) == labels).all()


def test_a_run_is_decided_in_pieces_of_the_window():
    classes = ("walk", "turn-left")
    stats = {"walk": {"mean": 0.0, "sd": 0.03}, "turn-left": {"mean": 0.3, "sd": 0.08}}
    families = {"walk": {"turn-left"}, "turn-left": {"walk"}}
    labels = np.full(120, 1)                                  # one run: straight, then turning left
    yaw = _document_yaw([(60, 0.0), (60, 0.4)])
    delta = np.full((2, 120), 0.02)
    whole = refine_by_turning(labels, classes, delta, yaw, FPS, stats, families, 2.0, window=0)
    assert (whole == 1).all()                                 # 0.2 rad/s over the run: nearer turn-left's 0.3
    pieces = refine_by_turning(labels, classes, delta, yaw, FPS, stats, families, 2.0, window=60)
    assert (pieces[:60] == 0).all() and (pieces[60:] == 1).all()


def test_among_rivals_that_turn_alike_the_best_matching_template_wins_and_alike_classes_never_compete():
    classes = ("walk", "run", "turn", "jog")
    stats = {"walk": {"mean": 0.0, "sd": 0.03}, "run": {"mean": 0.01, "sd": 0.03}, "turn": {"mean": 0.4, "sd": 0.05},
             "jog": {"mean": 0.0, "sd": 0.03}}
    families = {c: set(classes) - {c} for c in classes}
    labels = np.full(60, 2)
    yaw = _document_yaw([(60, 0.0)])
    delta = np.full((4, 60), 0.05)
    delta[1, 30] = 0.01                                       # run's template matched this stretch best
    assert (refine_by_turning(labels, classes, delta, yaw, FPS, stats, families, 2.0) == 1).all()
    jog = np.full(60, 3)                                      # jog and walk/run turn alike: jog stays jog
    assert (refine_by_turning(jog, classes, delta, yaw, FPS, stats, families, 2.0) == 3).all()
    left = _document_yaw([(60, 0.35)])                        # a turning stretch labelled turn: kept
    assert (refine_by_turning(labels, classes, delta, left, FPS, stats, families, 2.0) == 2).all()


def test_speed_statistics_and_a_walk_labelled_run_goes_to_walk_by_its_speed(pose):
    from stylemotion.annotate.turning import ground_speed, refine_labels, root_track, speed_statistics

    def travelling(speed: float, frames: int = 60) -> np.ndarray:
        steps = np.arange(frames)[:, None, None] / FPS * np.array([0.0, 0.0, speed])
        return pose[None] + steps                                 # the pose carried forward along +z

    assert ground_speed(root_track(travelling(1.3)), FPS) == pytest.approx(1.3)
    stats = speed_statistics({"walk": [travelling(1.2), travelling(1.4)], "run": [travelling(3.0)]}, FPS)
    assert stats["walk"]["mean"] == pytest.approx(1.3) and stats["walk"]["sd"] == pytest.approx(0.1)
    assert stats["run"]["sd"] == 0.05                             # the floor
    classes = ("walk", "run")
    families = {"walk": {"run"}, "run": {"walk"}}
    document = np.concatenate([travelling(1.3), travelling(3.1)])
    labels = np.full(120, 1)                                      # all labelled run: a walk, then a run
    delta = np.full((2, 120), 0.02)
    yaw = np.zeros(120)
    out = refine_labels(labels, classes, delta, yaw, root_track(document), FPS, families, None, stats, 2.0, 60)
    assert (out[:60] == 0).all() and (out[60:] == 1).all()
    same = refine_labels(labels, classes, delta, yaw, root_track(document), FPS, families, None, None, 2.0, 60)
    assert (same == labels).all()                                 # no statistics: the pass is skipped


def test_among_rivals_alike_in_turning_the_speed_decides(pose):
    """A straight 1 m/s walk labelled turn-right: walk and run both turn as little; its speed picks walk, although
    run's template matched it better."""
    from stylemotion.annotate.turning import refine_labels

    classes = ("walk", "run", "turn-right")
    turning = {"walk": {"mean": 0.0, "sd": 0.02}, "run": {"mean": 0.0, "sd": 0.03},
               "turn-right": {"mean": -0.45, "sd": 0.13}}
    speed = {"walk": {"mean": 1.2, "sd": 0.2}, "run": {"mean": 2.7, "sd": 0.5}, "turn-right": {"mean": 1.1, "sd": 0.2}}
    families = {c: set(classes) - {c} for c in classes}
    labels = np.full(60, 2)
    delta = np.full((3, 60), 0.05)
    delta[1, 30] = 0.01                                           # run's template matched best
    track = np.stack([np.zeros(60), np.arange(60) / FPS * 1.0], axis=1)
    out = refine_labels(labels, classes, delta, np.zeros(60), track, FPS, families, turning, speed, 1.0)
    assert (out == 0).all()
    no_speed = refine_labels(labels, classes, delta, np.zeros(60), track, FPS, families, turning, None, 1.0)
    assert (no_speed == 1).all()                                  # without speeds, the template decides
