"""Arm primitives (stylemotion.morphable.arm): cuts on constructed takes, and a raise primitive of Bandai
fitted and driven to hand targets (realdata)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stylemotion.datasets import Take, load_dataset
from stylemotion.datasets.synthetic import generate_take
from stylemotion.morphable import FitSettings, fit_primitive
from stylemotion.morphable.arm import ArmSettings, arm_clips, arm_keyframes, segment_arm_take
from stylemotion.morphable.constraints import KeyframeConstraint
from stylemotion.morphable.synthesis import MapSettings, solve_constraints
from stylemotion.skeleton import CANONICAL_JOINTS

FPS = 30.0
HAND_L = CANONICAL_JOINTS.index("Hand_L")


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
        arm_clips([], "raise-up-left-hand", "wave")


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
