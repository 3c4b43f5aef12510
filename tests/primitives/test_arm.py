"""Arm primitives (stylemotion.primitives.arm): cuts on constructed takes (raise/lower, and wave cycles against
their known extremes at any facing), a raise primitive of Bandai fitted and driven to hand targets, and the wave
cycles of Bandai's wave-left-hand takes (realdata)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stylemotion.datasets import Take, load_dataset
from stylemotion.datasets.synthetic import generate_take
from stylemotion.geometry import rotate_yaw
from stylemotion.morphable import FitSettings, fit_primitive
from stylemotion.morphable.constraints import KeyframeConstraint
from stylemotion.morphable.synthesis import MapSettings, solve_constraints
from stylemotion.primitives.actions import segment_action, segment_actions
from stylemotion.primitives.arm import ArmSettings, arm_clips, arm_keyframes, segment_arm_take, wave_signal
from stylemotion.primitives.segmentation import check_primitive, parse_primitive, stance_foot
from stylemotion.representation import facing_yaw
from stylemotion.skeleton import CANONICAL_JOINTS

FPS = 30.0
HAND_L = CANONICAL_JOINTS.index("Hand_L")
HAND_R = CANONICAL_JOINTS.index("Hand_R")


def _standing_pose() -> np.ndarray:
    return np.asarray(generate_take("walk", "normal", 0, duration_s=1.0).positions[0], dtype=np.float64)


def _raise_take(rise: tuple[int, int], fall: tuple[int, int], frames: int = 80, lift_m: float = 0.6,
                name: str = "arm_raise-up-left-hand_normal_001", back_down: bool = True) -> Take:
    """A standing pose whose left hand rises by ``lift_m`` (smoothly) over frames ``rise`` and falls over ``fall``."""
    t = np.arange(frames, dtype=np.float64)

    def ramp(a: int, b: int) -> np.ndarray:
        x = np.clip((t - a) / (b - a), 0.0, 1.0)
        return x * x * (3 - 2 * x)

    lift = lift_m * (ramp(*rise) - (ramp(*fall) if back_down else 0.0))
    positions = np.repeat(_standing_pose()[None], frames, axis=0)
    positions[:, HAND_L, 1] += lift
    return Take(name, positions.astype(np.float32), FPS,
                {"content": "raise-up-left-hand", "style": "normal", "take": name[-3:]})


def test_cuts_at_rest_and_at_the_top() -> None:
    found = arm_keyframes(_raise_take((10, 30), (50, 70)).positions, FPS)
    assert not isinstance(found, str), found
    ranges, hands = found
    assert hands == ["Hand_L"]
    # the smoothstep is at rest (speed 0) up to frame 10 and at the top from 30; the search window is 15 frames
    (r0, r1), (l0, l1) = ranges["raise"], ranges["lower"]
    assert 8 <= r0 <= 10 and 30 <= r1 - 1 <= 32, ranges
    assert 48 <= l0 <= 50 and 70 <= l1 - 1 <= 72, ranges


def test_segment_take_gives_clips_from_the_origin() -> None:
    clips, reason = segment_arm_take(_raise_take((10, 30), (50, 70)))
    assert reason is None
    assert [c.primitive for c in clips] == ["raise", "lower"]
    raise_clip = clips[0]
    assert raise_clip.action == "raise-up-left-hand" and raise_clip.frames.shape == (raise_clip.num_frames, 66)
    rise = raise_clip.positions[-1, HAND_L, 1] - raise_clip.positions[0, HAND_L, 1]
    assert rise == pytest.approx(0.6, abs=0.03)
    assert np.abs(raise_clip.positions[0, 0, [0, 2]]).max() < 1e-5  # root starts above the origin


def test_rejections_name_the_reason() -> None:
    assert "no hand rises" in arm_keyframes(_raise_take((10, 30), (50, 70), lift_m=0.05).positions, FPS)
    assert "does not come back down" in arm_keyframes(_raise_take((10, 30), (50, 70), back_down=False).positions, FPS)
    assert "shorter than min_frames" in arm_keyframes(_raise_take((10, 13), (50, 70)).positions, FPS,
                                                      ArmSettings(search_s=0.0, min_frames=8))
    with pytest.raises(ValueError, match="not an arm motion"):
        segment_arm_take(Take("w", np.zeros((5, 21, 3), np.float32), FPS, {"content": "walk", "style": "normal"}))
    with pytest.raises(ValueError, match="threshold"):
        ArmSettings(threshold=0.7)
    with pytest.raises(ValueError, match="unknown arm primitive"):
        arm_clips([], "raise-up-left-hand", "hold")


def _ramp(t: np.ndarray, a: float, b: float) -> np.ndarray:
    x = np.clip((t - a) / (b - a), 0.0, 1.0)
    return x * x * (3 - 2 * x)


def _wave_take(cycles: int, period: float, yaw: float, amplitude_m: float = 0.15, hands: str = "left",
               content: str = "wave-left-hand") -> tuple[Take, list[float]]:
    """A standing body that raises its hand(s) by 0.6 m over frames 10–30, moves them side to side from frame 35
    as ``amplitude_m · sin(2π (t − 35) / period)`` along a body-frame axis 17° off its left (+X) for
    ``cycles + ½`` periods, holds 5 frames, lowers them over 20 frames and rests 10; the whole take turned by
    ``yaw`` about +Y and moved off the origin. ``hands``: ``left``, ``mirrored`` (both hands, the right one
    mirrored: both out at once) or ``parallel`` (both hands moving to the same side). Also returns the frames of
    the left hand's outward extremes (``cycles + 1``: ``cycles`` whole cycles between them)."""
    t0, end = 35.0, 35.0 + (cycles + 0.5) * period
    frames = int(np.ceil(end)) + 5 + 20 + 10
    t = np.arange(frames, dtype=np.float64)
    pose = _standing_pose()
    body_yaw = float(facing_yaw(pose[None], FPS)[0])
    side = np.sin(2 * np.pi * (t - t0) / period) * ((t >= t0) & (t <= end)) * amplitude_m
    axis = np.array([np.cos(0.3), 0.0, np.sin(0.3)])  # body frame: mostly +X (the body's left), a little forward
    lift = 0.6 * (_ramp(t, 10, 30) - _ramp(t, end + 5, end + 25))
    positions = np.repeat(pose[None], frames, axis=0)
    moved = [(HAND_L, axis)] + {"left": [], "mirrored": [(HAND_R, axis * [-1, 1, 1])],
                                "parallel": [(HAND_R, axis)]}[hands]
    for joint, direction in moved:
        positions[:, joint] += side[:, None] * rotate_yaw(direction, body_yaw) + lift[:, None] * [0.0, 1.0, 0.0]
    positions = rotate_yaw(positions, yaw) + np.array([1.5, 0.0, -2.0])
    name = f"arm_{content}_normal_001"
    extremes = [t0 + period / 4 + k * period for k in range(cycles + 1)]
    return Take(name, positions.astype(np.float32), FPS, {"content": content, "style": "normal", "take": "001"}), \
        extremes


@pytest.mark.parametrize("yaw,period,hands", [(0.0, 20.0, "left"), (2.3, 17.0, "left"), (-1.2, 24.0, "mirrored"),
                                              (0.7, 19.0, "parallel")])
def test_wave_cycles_match_the_known_extremes_at_any_facing(yaw: float, period: float, hands: str) -> None:
    content = "wave-left-hand" if hands == "left" else "wave-both-hands"
    take, extremes = _wave_take(5, period, yaw, hands=hands, content=content)
    clips, reason = segment_arm_take(take)
    assert reason is None, reason
    assert [c.primitive for c in clips] == ["raise"] + ["wave"] * 5 + ["lower"]
    waves = [c for c in clips if c.primitive == "wave"]
    for clip, first, last in zip(waves, extremes[:-1], extremes[1:]):
        # a cycle runs from one outward extreme to the next, both included
        assert abs(clip.start - first) <= 2 and abs(clip.stop - 1 - last) <= 2, (clip.describe(), first, last)
        assert clip.action == content and clip.frames.shape == (clip.num_frames, 66)
        assert clip.duration_s == pytest.approx(period / FPS, abs=2 / FPS)
    assert [c.take for c in arm_clips([take], content, "wave")[0]] == [take.name] * 5


def test_wave_refusals_name_the_reason() -> None:
    take, _ = _wave_take(5, 20.0, 0.4, amplitude_m=0.0)
    clips, reason = segment_arm_take(take)
    assert [c.primitive for c in clips] == ["raise", "lower"] and "wave: no oscillation" in reason
    clips, rejected = arm_clips([take], "wave-left-hand", "wave")
    assert clips == [] and len(rejected) == 1 and "no oscillation" in rejected[0]
    clips, rejected = arm_clips([take], "wave-left-hand", "raise")  # the wave's rejection is not the raise's
    assert [c.primitive for c in clips] == ["raise"] and rejected == []
    # 4 cm from side to side: the inner extremes are found (prominence 4 cm ≥ 2.5 cm; the first and last only
    # stand 2 cm above the hand's rest before and after) but their cycles are below min_wave_m = 5 cm
    clips, rejected = arm_clips([_wave_take(4, 20.0, 0.4, amplitude_m=0.02)[0]], "wave-left-hand", "wave")
    assert clips == [] and len(rejected) == 2 and all("amplitude 0.040 m" in r for r in rejected), rejected
    # 6-frame cycles against min_frames = 8
    clips, rejected = arm_clips([_wave_take(6, 6.0, 0.4)[0]], "wave-left-hand", "wave")
    assert clips == [] and len(rejected) == 6 and all("shorter than min_frames" in r for r in rejected), rejected
    raise_up = _raise_take((10, 30), (50, 70))
    with pytest.raises(ValueError, match="'raise-up-left-hand' has no 'wave'"):
        arm_clips([raise_up], "raise-up-left-hand", "wave")
    with pytest.raises(ValueError, match="'raise-up-left-hand' has no 'wave'"):
        segment_arm_take(raise_up, primitives=["wave"])
    with pytest.raises(ValueError, match="min_wave_m"):
        ArmSettings(min_wave_m=0.0)


@pytest.mark.realdata
def test_bandai_raise_primitive_reaches_held_out_hand_targets(bandai_zip_path: Path) -> None:
    takes = load_dataset("bandai", root=bandai_zip_path, contents=["raise-up-left-hand"], styles=["normal"])
    split = takes.split(seed=0, val_fraction=0.1, test_fraction=0.1)
    train, rejected = arm_clips(split["train"], "raise-up-left-hand", "raise")
    test, _ = arm_clips(split["test"], "raise-up-left-hand", "raise")
    assert len(train) >= 0.9 * len(split["train"]), rejected
    # every raise ends with the hand near the top of its take (within 5 cm), having risen at least 40 cm
    for clip in train:
        take = next(t for t in split["train"] if t.name == clip.take)
        assert take.positions[:, HAND_L, 1].max() - take.positions[clip.stop - 1, HAND_L, 1] < 0.05
        assert clip.positions[-1, HAND_L, 1] - clip.positions[0, HAND_L, 1] > 0.4
    model = fit_primitive(train, FitSettings(latent_dim=8, reduction="fpca"))
    model.build_tree(2000, seed=0)
    for clip in test[:4]:
        target = clip.positions[-1, HAND_L]
        # σ_c = 5 mm: at the default 2 cm the prior of this 60-clip primitive outweighs a cm of hand error
        result = solve_constraints(model, [KeyframeConstraint("position", target, joint="Hand_L")],
                                   MapSettings(constraint_scale_m=0.005))
        assert result.errors_m[0] < 0.02, (clip.describe(), result.errors_m, result.start_errors_m)
        assert result.cost <= result.start_cost  # the MAP objective (constraint + prior) never worsens


@pytest.mark.realdata
def test_bandai_wave_left_hand_cycles_are_single_waves(bandai_zip_path: Path) -> None:
    takes = load_dataset("bandai", root=bandai_zip_path, contents=["wave-left-hand"], styles=["normal"])
    train = takes.split(seed=0, val_fraction=0.1, test_fraction=0.1)["train"][:4]
    assert len(train) == 4
    for take in train:
        clips, rejected = arm_clips([take], "wave-left-hand", "wave")
        assert len(clips) >= 3, (take.name, rejected)
        for clip in clips:
            assert 0.3 <= clip.duration_s <= 2.0, clip.describe()
            s = wave_signal(np.asarray(take.positions, np.float64), take.fps, (clip.start, clip.stop), ["Hand_L"])
            travel = float(np.ptp(s))
            assert 0.1 <= travel <= 0.8, (clip.describe(), travel)  # a hand wave: 10–80 cm from side to side
            # it starts and ends at the same phase: both ends are the hand's outermost positions (within 20 %)
            assert s.max() - min(s[0], s[-1]) <= 0.2 * travel, (clip.describe(), s[0], s[-1], s.max())
            assert int(np.argmin(s)) not in (0, len(s) - 1)  # the inward extreme lies inside the cycle


def test_arm_primitive_names_parse_and_refuse_what_the_content_lacks() -> None:
    assert parse_primitive("raise-up-right-hand_raise") == ("raise-up-right-hand", "raise")
    assert parse_primitive("wave-both-hands_wave") == ("wave-both-hands", "wave")
    assert parse_primitive("run_leftStance") == ("run", "leftStance")
    with pytest.raises(ValueError, match="raise-up-left-hand_raise, raise-up-left-hand_lower"):
        parse_primitive("raise-up-left-hand_wave")
    with pytest.raises(ValueError, match="arm primitive"):
        parse_primitive("walk_raise")
    assert check_primitive("lower", "raise-up-left-hand") == "lower"
    with pytest.raises(ValueError):
        check_primitive("leftStance", "raise-up-left-hand")
    with pytest.raises(ValueError):
        check_primitive("raise", "walk")
    assert stance_foot("raise") is None and stance_foot("leftStance") == 0 and stance_foot("endRightStance") == 1


def test_segment_action_cuts_an_arm_content_as_arm_clips_does() -> None:
    takes = [_raise_take((10, 30), (50, 70)), _raise_take((5, 25), (45, 65), name="arm_raise-up-left-hand_normal_002"),
             _raise_take((10, 30), (50, 70), name="arm_raise-up-left-hand_normal_003", back_down=False),
             Take("synthetic_walk_normal_000", generate_take("walk", "normal", 0, duration_s=3.0).positions, FPS,
                  {"content": "walk", "style": "normal", "take": "000"})]
    seg = segment_action(takes, "raise-up-left-hand")
    expected = [(c.take, c.primitive, c.start, c.stop) for p in ("raise", "lower")
                for c in arm_clips(takes, "raise-up-left-hand", p)[0]]
    assert sorted((c.take, c.primitive, c.start, c.stop) for c in seg.clips) == sorted(expected)
    assert len(seg.clips) == 4 and {c.action for c in seg.clips} == {"raise-up-left-hand"}
    # the take that does not come back down is a counted rejection, the walk is not of the action
    assert [r.take for r in seg.rejections] == ["arm_raise-up-left-hand_normal_003"]
    assert [c.stance_foot for c in seg.clips] == [None] * 4
    assert segment_action(takes, "walk").clips
    merged = segment_actions(takes, ["raise-up-left-hand", "walk"])
    assert len(merged.clips) == len(seg.clips) + len(segment_action(takes, "walk").clips)
