"""Takes on rest skeletons of chosen bone lengths, shared by the retarget and actor-group tests."""

from __future__ import annotations

import numpy as np

from stylemotion.bones import BONE_NAMES, NUM_BONES, median_bone_lengths
from stylemotion.datasets import Take, TakeSet
from stylemotion.skeleton import CANONICAL_PARENTS, NUM_JOINTS, forward_kinematics


def skeleton_take(name: str, style: str, scale: np.ndarray | float = 1.0, frames: int = 12) -> Take:
    """A take of a fixed pose drifting forward, on a rest skeleton whose bones are multiplied by ``scale``."""
    rng = np.random.default_rng(0)
    offsets = rng.normal(size=(NUM_JOINTS, 3)) * 0.1
    offsets[1:] *= np.broadcast_to(scale, (NUM_BONES,))[:, None]
    translations = np.repeat(offsets[None], frames, axis=0)
    translations[:, 0] = np.stack([np.zeros(frames), np.full(frames, 1.0), 0.04 * np.arange(frames)], axis=-1)
    rotations = np.broadcast_to(np.eye(3), (frames, NUM_JOINTS, 3, 3))
    positions = forward_kinematics(rotations, translations, CANONICAL_PARENTS).astype(np.float32)
    return Take(name, positions, 30.0, {"content": "walk", "style": style}, source=f"<memory:{name}>")


def two_actors() -> TakeSet:
    """Styles normal and masculine on skeleton A (one take 0.4 mm off), feminine on B (one bone 5 % longer)."""
    b = np.ones(NUM_BONES)
    b[BONE_NAMES.index("LowerLeg_L")] = 1.05
    jitter = np.ones(NUM_BONES)
    jitter[BONE_NAMES.index("Spine")] += 0.0004 / float(median_bone_lengths(skeleton_take("x", "x").positions)[0])
    takes = [skeleton_take("a_normal_0", "normal"), skeleton_take("a_normal_1", "normal", jitter),
             skeleton_take("a_masculine_0", "masculine"), skeleton_take("b_feminine_0", "feminine", b),
             skeleton_take("b_feminine_1", "feminine", b)]
    return TakeSet("two_actors", sorted(takes, key=lambda t: t.name), 30.0)
