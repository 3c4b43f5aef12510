"""How much repeated walks along one path differ, against how much real steps differ (Du §4.6.3).

Walks are compared step by step: step ``k`` of every walk (the same primitive, since stances alternate) is one
aligned set. Real clips of a primitive are one set. For a set of steps:

* **pose spread** (m): the root-local joint positions (the 66-dim frames' 63 joint values) of each step,
  time-normalized to ``length`` frames (:func:`~stylemotion.primitives.segmentation.time_normalize`), and the RMS
  distance of each step's joints to the set's mean step, over steps, frames and joints;
* **step length SD** (m): the standard deviation of the root's ground displacement from a step's first to its
  last frame;
* **duration SD** (s): the standard deviation of the steps' durations.

A set of identical steps has spread 0. A walk's figures are the means over its aligned steps.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stylemotion.primitives.segmentation import time_normalize
from stylemotion.representation import JOINT_DIMS


def step_frames(frames: np.ndarray, starts: Sequence[int]) -> list[np.ndarray]:
    """The ``(n_k, 66)`` frames of each step of a stitched motion ``(frames, 66)`` whose steps start at frames
    ``starts`` (a step runs to the next step's start frame, which both share; the last one to the end)."""
    bounds = list(starts) + [len(frames) - 1]
    return [np.asarray(frames[a:max(b, a + 1) + 1]) for a, b in zip(bounds[:-1], bounds[1:])]


def pose_spread(steps: Sequence[np.ndarray], length: int) -> float:
    """RMS distance (m) of the steps' time-normalized root-local joints to their mean (module doc); ``steps``:
    ``(n_k, 66)`` frames each, at least two steps."""
    if len(steps) < 2:
        raise ValueError(f"a spread needs at least two steps, got {len(steps)}")
    joints = np.stack([time_normalize(np.asarray(s, dtype=np.float64), length)[:, JOINT_DIMS] for s in steps])
    joints = joints.reshape(len(steps), length, -1, 3)
    return float(np.sqrt(((joints - joints.mean(0)) ** 2).sum(-1).mean()))


def set_variation(steps: Sequence[np.ndarray], step_lengths_m: Sequence[float], durations_s: Sequence[float],
                  length: int) -> dict[str, float]:
    """``pose_spread_m``, ``step_length_sd_m`` and ``duration_sd_s`` of one set of steps (module doc)."""
    return {"pose_spread_m": pose_spread(steps, length),
            "step_length_sd_m": float(np.std(np.asarray(step_lengths_m, dtype=np.float64))),
            "duration_sd_s": float(np.std(np.asarray(durations_s, dtype=np.float64)))}


def clip_variation(frames: Sequence[np.ndarray], positions: Sequence[np.ndarray], fps: float, length: int
                   ) -> dict[str, float]:
    """:func:`set_variation` of real clips of one primitive: ``frames`` ``(n_k, 66)`` and ``positions``
    ``(n_k, 21, 3)`` (metres, Y up) each, at ``fps``."""
    lengths = [float(np.linalg.norm(p[-1, 0, [0, 2]] - p[0, 0, [0, 2]])) for p in positions]
    durations = [(len(f) - 1) / fps for f in frames]
    return {**set_variation(frames, lengths, durations, length), "clips": len(frames)}


def walk_variation(walks: Sequence, length: int) -> dict[str, object]:
    """:func:`set_variation` of the aligned steps of repeated walks along one path
    (:class:`~stylemotion.synthesis.controller.SynthesizedMotion` each, at least two), averaged over the steps
    every walk has (``steps``); ``per_step`` lists each step's figures. Step lengths are measured on the ground
    track the controller placed each step at (from the previous step's end, the first from the path's start)."""
    if len(walks) < 2:
        raise ValueError(f"a spread needs at least two walks, got {len(walks)}")
    count = min(len(w.steps) for w in walks)
    per_step = []
    for k in range(count):
        primitives = {w.steps[k].primitive for w in walks}
        if len(primitives) > 1:
            break  # walks no longer aligned (a different primitive at this step)
        clips, lengths, durations = [], [], []
        for w in walks:
            clips.append(step_frames(w.frames, [s.start_frame for s in w.steps])[k])
            before = np.asarray(w.path.start if k == 0 else w.steps[k - 1].end_xz, dtype=np.float64)
            lengths.append(float(np.linalg.norm(np.asarray(w.steps[k].end_xz) - before)))
            durations.append(w.steps[k].duration_s)
        per_step.append({"primitive": primitives.pop(), **set_variation(clips, lengths, durations, length)})
    keys = ("pose_spread_m", "step_length_sd_m", "duration_sd_s")
    means = {k: float(np.mean([s[k] for s in per_step])) if per_step else float("nan") for k in keys}
    return {**means, "steps": len(per_step), "walks": len(walks), "per_step": per_step}
