"""Joining primitive clips into one motion at their shared contact keyframes (thesis §4.5.3, §5.4.4).

Consecutive clips share a keyframe: clip ``k`` ends and clip ``k + 1`` starts in the middle of the
same support transfer (:mod:`stylemotion.primitives.segmentation`). The motion is assembled in the 66-dim frame
representation, which is placement-free, and integrated once at the end
(:func:`stylemotion.representation.frames_to_positions`), so the root path is continuous by
construction::

    motion = clip_0[:-1] ++ blend(clip_1)[:-1] ++ … ++ blend(clip_last)

The last frame of each clip is dropped in favour of the next clip's first frame (the same
keyframe; its velocities describe the motion that follows). The next clip generally starts in a
slightly different pose and speed than its predecessor ended; that jump ``δ = prev[-1] − next[0]``
(all 66 channels: pose, root velocity, yaw rate) is added to the first ``blend_frames`` frames of
the next clip with a weight falling smoothly from 1 to 0, so the pose and speed are continuous at
the keyframe and the next clip takes over within ``blend_frames / fps`` seconds.
"""

from __future__ import annotations

import numpy as np

from stylemotion.representation import FRAME_DIM


def blend_weights(frames: int) -> np.ndarray:
    """``(frames,)`` weights falling from 1 (at the keyframe) towards 0: ``1 − smoothstep(t / frames)``."""
    if frames < 0:
        raise ValueError(f"blend_frames must be ≥ 0, got {frames}")
    t = np.arange(frames, dtype=np.float64) / max(frames, 1)
    return 1.0 - t * t * (3.0 - 2.0 * t)


def blend_into(previous_last: np.ndarray, clip: np.ndarray, blend_frames: int) -> np.ndarray:
    """``clip`` ``(frames, 66)`` with the jump from ``previous_last`` ``(66,)`` faded out over its
    first ``blend_frames`` frames (a copy; ``clip[0]`` becomes ``previous_last`` when blending)."""
    clip = np.array(clip, dtype=np.float64)
    count = min(int(blend_frames), len(clip))
    if count:
        delta = np.asarray(previous_last, dtype=np.float64) - clip[0]
        clip[:count] += blend_weights(count)[:, None] * delta
    return clip


def append_clip(motion: np.ndarray | None, clip: np.ndarray, blend_frames: int) -> tuple[np.ndarray, int]:
    """Append a clip to a motion at their shared keyframe.

    Args:
        motion: ``(frames, 66)`` the motion so far (its last frame is the keyframe), or None.
        clip: ``(frames, 66)`` the next clip, starting at that keyframe (≥ 2 frames).
        blend_frames: frames over which the pose/speed jump fades (0: hard cut).

    Returns:
        The longer motion ``(frames', 66)`` float64, and the index of the keyframe where the clip starts.
    """
    clip = np.asarray(clip, dtype=np.float64)
    if clip.ndim != 2 or clip.shape[1] != FRAME_DIM or len(clip) < 2:
        raise ValueError(f"a clip must be (frames ≥ 2, {FRAME_DIM}), got {clip.shape}")
    if motion is None or len(motion) == 0:
        return clip.copy(), 0
    junction = len(motion) - 1
    return np.concatenate([motion[:-1], blend_into(motion[-1], clip, blend_frames)]), junction


def _peak_ratio(values: np.ndarray, near: np.ndarray, percentile: float) -> tuple[float, float, float]:
    """Max of ``values`` (rows: time) where ``near``, the ``percentile`` elsewhere, and their ratio."""
    inside = float(np.percentile(values[~near], percentile)) if (~near).any() else float("nan")
    peak = float(values[near].max()) if near.any() else float("nan")
    return peak, inside, peak / inside if near.any() and inside > 0 else float("nan")


def transition_speed_ratio(positions: np.ndarray, fps: float, junctions: list[int], window: int = 1,
                           percentile: float = 99.0) -> dict[str, float]:
    """How fast joints move (and how hard they accelerate) at the transitions compared with inside clips.

    Joint speeds are ``‖p[t+1] − p[t]‖ · fps`` (m/s, per frame interval) and accelerations
    ``‖p[t+1] − 2p[t] + p[t−1]‖ · fps²`` (m/s², per frame) of every joint. Transition intervals and
    frames are those within ``window`` frames of a junction keyframe (both sides); the rest are
    "inside clips". A pop shows in both; the speed ratio (the issue's figure) also compares with
    the fast swing of hands and feet mid-step, so a transition rarely exceeds it unless the pop is
    large — the acceleration ratio is the more sensitive of the two.

    Args:
        positions: ``(frames, 21, 3)`` metres.
        fps: frames per second.
        junctions: keyframe indices where clips meet (e.g. from :func:`append_clip`).
        window: intervals (frames) on each side of a junction that count as the transition.
        percentile: the reference statistic of the inside values.

    Returns:
        ``max_transition_mps``, ``inside_p99_mps``, ``ratio`` (speed) and ``max_transition_accel``,
        ``inside_p99_accel``, ``accel_ratio`` (m/s²); NaN without junctions.
    """
    p = np.asarray(positions, dtype=np.float64)
    speed = np.linalg.norm(np.diff(p, axis=0), axis=-1) * fps  # (frames - 1, joints): interval t → t + 1
    accel = np.linalg.norm(p[2:] - 2 * p[1:-1] + p[:-2], axis=-1) * fps ** 2  # (frames - 2, joints): frame t + 1
    near_speed = np.zeros(len(speed), dtype=bool)
    near_accel = np.zeros(len(accel), dtype=bool)
    for j in junctions:
        near_speed[max(0, j - window): j + window] = True
        near_accel[max(0, j - 1 - window): max(0, j + window)] = True
    peak, inside, ratio = _peak_ratio(speed, near_speed, percentile)
    peak_a, inside_a, ratio_a = _peak_ratio(accel, near_accel, percentile)
    return {"max_transition_mps": peak, "inside_p99_mps": inside, "ratio": ratio,
            "max_transition_accel": peak_a, "inside_p99_accel": inside_a, "accel_ratio": ratio_a}
