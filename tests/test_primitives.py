"""Segmentation into the six primitives, placement, canonical timelines; Bandai checks with numbers."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from stylemotion.datasets import Take, TakeSet, load_dataset
from stylemotion.datasets.synthetic import STYLES, SyntheticTake, generate_take
from stylemotion.geometry import rotate_yaw
from stylemotion.primitives.segmentation import (
    PRIMITIVES,
    STANCE_FOOT,
    Segmentation,
    SegmentSettings,
    action_of,
    canonical_timelines,
    check_primitive,
    playback_fps,
    restore_duration,
    segment_take,
    segment_takes,
    stance_speeds,
    support_phases,
    time_normalize,
)
from stylemotion.representation import facing_yaw, frames_to_positions
from stylemotion.skeleton import CANONICAL_MIRROR, JOINT_INDEX

LOCOMOTION = ["walk", "walk-turn-left", "walk-turn-right", "run"]


def as_take(g: SyntheticTake, positions: np.ndarray | None = None, name: str | None = None) -> Take:
    return Take(name or g.name, g.positions if positions is None else positions.astype(np.float32), g.fps,
                dict(g.labels))


def mirrored(positions: np.ndarray) -> np.ndarray:
    """Left and right swapped: x negated and _L/_R joints exchanged."""
    out = positions[:, list(CANONICAL_MIRROR)].copy()
    out[..., 0] *= -1
    return out


# ---------------------------------------------------------------------------------------------
# Synthetic ground truth


@pytest.mark.parametrize("content", ["walk", "walk-turn-left", "run"])
def test_stance_clips_match_ground_truth_contacts(content: str) -> None:
    for style in ("normal", "elderly", "youthful"):
        g = generate_take(content, style, 0, seed=5, duration_s=5.0)
        seg = segment_take(as_take(g))
        assert seg.rejections and all(r.kind == "border" for r in seg.rejections)
        assert len(seg.clips) >= 6
        truth_phases = support_phases(g.contacts)  # every true step away from the take's ends is a clip
        for before, (foot, a, b), after in zip(truth_phases, truth_phases[1:], truth_phases[2:]):
            if before[1] >= 3 and after[2] <= g.contacts.shape[0] - 3:  # its neighbours are not cut either
                assert [c for c in seg.clips if c.stance_foot == foot and c.start <= (a + b) // 2 < c.stop], \
                    f"true {('left', 'right')[foot]} step [{a}, {b}) of {g.name} has no clip"
        for clip in seg.clips:
            assert clip.primitive in ("leftStance", "rightStance")
            assert clip.action == action_of(content) and clip.style == style and clip.content == content
            assert clip.take == g.name and clip.num_frames == clip.stop - clip.start
            assert clip.duration_s == pytest.approx((clip.num_frames - 1) / 30.0)
            truth = g.contacts[clip.start:clip.stop]
            stance, swing = truth[:, clip.stance_foot], truth[:, 1 - clip.stance_foot]
            n = clip.num_frames
            assert stance[n // 4 + 1:n - n // 4 - 1].all(), f"{clip.describe()}: planted foot not down mid-clip"
            assert not swing.all(), f"{clip.describe()}: swing foot never lifts"
        # alternation and contiguity: consecutive clips share their boundary keyframe
        for a, b in zip(seg.clips, seg.clips[1:]):
            assert a.stance_foot != b.stance_foot and a.stop - 1 == b.start


def test_keyframes_lie_inside_the_true_support_transfer() -> None:
    for content in ("walk", "run"):
        g = generate_take(content, "masculine", 1, seed=2, duration_s=5.0)
        seg = segment_take(as_take(g))
        both_or_none = g.contacts.all(1) | ~g.contacts.any(1)
        for k in seg.keyframes:
            window = both_or_none[max(k - 2, 0):k + 3]
            assert window.any(), f"{content}: keyframe {k} is 2+ frames from any double support/flight"


def test_mirrored_take_swaps_left_and_right_stances() -> None:
    g = generate_take("walk", "feminine", 0, seed=1, duration_s=4.0)
    plain = segment_take(as_take(g))
    mirror = segment_take(as_take(g, mirrored(g.positions)))
    assert [(c.start, c.stop) for c in plain.clips] == [(c.start, c.stop) for c in mirror.clips]
    swap = {"leftStance": "rightStance", "rightStance": "leftStance"}
    assert [swap[c.primitive] for c in plain.clips] == [c.primitive for c in mirror.clips]


def test_clip_starts_at_origin_facing_z_and_keeps_its_shape() -> None:
    g = generate_take("walk-turn-right", "active", 0, seed=0, duration_s=5.0)
    seg = segment_take(as_take(g))
    clip = seg.clips[len(seg.clips) // 2]
    p = clip.positions
    assert p.shape == (clip.num_frames, 21, 3)
    np.testing.assert_allclose(p[0, JOINT_INDEX["Hips"], [0, 2]], 0.0, atol=1e-5)
    assert abs(facing_yaw(p, clip.fps, smooth_seconds=0.0)[0]) < 0.15
    source = g.positions[clip.start:clip.stop].astype(np.float64)
    yaw0 = facing_yaw(g.positions, g.fps)[clip.start]
    centred = source - np.array([source[0, JOINT_INDEX["Hips"], 0], 0.0, source[0, JOINT_INDEX["Hips"], 2]])
    rotated = rotate_yaw(centred, -yaw0)
    np.testing.assert_allclose(p, rotated, atol=2e-3)  # a rigid placement of the source frames


def test_stance_foot_is_still_and_swing_foot_moves() -> None:
    g = generate_take("walk", "exhausted", 0, seed=0, duration_s=5.0)
    for clip in segment_take(as_take(g)).clips:
        speeds = stance_speeds(clip.positions, clip.fps, clip.stance_foot, clip.contacts)
        assert speeds["planted_mid"] < 0.05 and speeds["swing_mid"] > 0.5
        assert speeds["planted_contact"] < 0.1


def _with_rest(g: SyntheticTake, frames: int = 20) -> tuple[np.ndarray, int, int]:
    """The take standing still ``frames`` frames before its first and after its last full double
    support; returns positions and the true stance foot of the first and of the last step."""
    both = np.flatnonzero(g.contacts.all(1))
    first = both[both > 5][0]
    last = both[both < g.contacts.shape[0] - 5][-1]
    body = g.positions[first:last + 1]
    positions = np.concatenate([np.repeat(body[:1], frames, 0), body, np.repeat(body[-1:], frames, 0)])
    after = g.contacts[first:]
    lifts_first = 0 if np.argmin(after[:, 0]) < np.argmin(after[:, 1]) else 1
    before = g.contacts[:last + 1][::-1]
    landed_last = 0 if np.argmin(before[:, 0]) < np.argmin(before[:, 1]) else 1  # last to lift before the end
    return positions, 1 - lifts_first, 1 - landed_last


def test_begin_and_end_primitives_from_standing() -> None:
    for index in range(3):
        g = generate_take("walk", "normal", index, seed=7, duration_s=4.0)
        positions, begin_foot, end_foot = _with_rest(g)
        seg = segment_take(as_take(g, positions))
        assert not [r for r in seg.rejections if r.kind != "border"]
        first, last = seg.clips[0], seg.clips[-1]
        assert first.primitive == f"begin{('Left', 'Right')[begin_foot]}Stance", first.describe()
        assert last.primitive == f"end{('Left', 'Right')[end_foot]}Stance", last.describe()
        assert STANCE_FOOT[first.primitive] == begin_foot
        assert first.start >= 15 and last.stop <= positions.shape[0] - 15  # cut at the rest's edge
        assert all(c.primitive in ("leftStance", "rightStance") for c in seg.clips[1:-1])
        assert len(seg.rests) == 2


def test_every_single_support_phase_is_a_clip_or_reported() -> None:
    for content in ("walk", "run"):
        g = generate_take(content, "youthful", 0, seed=0, duration_s=4.0)
        seg = segment_take(as_take(g))
        assert len(support_phases(seg.contacts)) == len(seg.clips) + len(seg.rejections)
        borders = [r for r in seg.rejections if r.kind == "border"]
        assert len(borders) == 2
        assert "take's start" in borders[0].reason and "take's end" in borders[1].reason
        covered = np.zeros(g.positions.shape[0], int)  # clips and border steps tile the take
        for start, stop in [(c.start, c.stop) for c in seg.clips] + [(r.start, r.stop) for r in borders]:
            covered[start:stop] += 1
        assert covered.min() >= 1 and covered.max() <= 2  # neighbours share one keyframe


# ---------------------------------------------------------------------------------------------
# Bad input


def test_take_too_short_no_contact_one_foot() -> None:
    g = generate_take("walk", "normal", 0, seed=0, duration_s=2.0)
    short = segment_take(as_take(g, g.positions[:4]))
    assert not short.clips and short.rejections[0].kind == "take"
    assert "too short for a step" in short.rejections[0].reason

    pose = g.positions[0]
    glide = np.repeat(pose[None], 40, 0) + (np.arange(40)[:, None, None] * np.array([0, 0, 0.1])).astype(np.float32)
    none = segment_take(as_take(g, glide))
    assert not none.clips and "no foot contact" in none.rejections[0].reason

    one = np.repeat(pose[None], 40, 0).copy()
    angle = np.linspace(0, 4 * np.pi, 40)
    for joint in ("Foot_R", "Toes_R"):  # the right foot circles 15 cm off the ground at ~1.5 m/s
        one[:, JOINT_INDEX[joint], 0] += 0.2 * np.cos(angle)
        one[:, JOINT_INDEX[joint], 2] += 0.2 * np.sin(angle)
        one[:, JOINT_INDEX[joint], 1] += 0.15
    only = segment_take(as_take(g, one))
    assert not only.clips and "only the left foot touches the ground" in only.rejections[0].reason


def test_unknown_settings_are_named() -> None:
    with pytest.raises(ValueError, match=r"unknown SegmentSettings option\(s\) \['max_step'\]"):
        SegmentSettings.from_dict({"max_step": 1.0})
    with pytest.raises(ValueError, match=r"unknown ContactSettings option\(s\) \['speed'\]"):
        SegmentSettings.from_dict({"contacts": {"speed": 1.0}})
    assert SegmentSettings.from_dict({"contacts": {"speed_on": 0.2}}).contacts.speed_on == 0.2


def test_rejected_steps_carry_reasons() -> None:
    g = generate_take("walk", "normal", 0, seed=0, duration_s=4.0)
    strict = segment_take(as_take(g), SegmentSettings(max_step_s=0.3))
    assert not strict.clips
    steps = [r for r in strict.rejections if r.kind == "step"]
    assert steps and all("too long" in r.reason and r.start is not None for r in steps)
    assert all(r.reason.startswith(("leftStance", "rightStance")) for r in steps)


def test_non_locomotion_and_unknown_primitive() -> None:
    g = generate_take("walk", "normal", 0, seed=0, duration_s=2.0)
    wave = Take("wave_take", g.positions, 30.0, {"content": "wave-left-hand", "style": "normal"})
    with pytest.raises(ValueError, match="none of the locomotion actions"):
        segment_take(wave)
    seg = segment_takes([wave, as_take(g)])
    assert seg.ignored == [("wave_take", "wave-left-hand")] and len(seg.takes) == 1
    with pytest.raises(ValueError, match="unknown motion primitive 'LeftStance'.*beginLeftStance"):
        seg.select("walk", ["LeftStance"])
    assert check_primitive("endRightStance") == "endRightStance"
    assert action_of("walk-turn-left") == "walk" and action_of("walking") is None and action_of("run") == "run"


# ---------------------------------------------------------------------------------------------
# Canonical timelines and time normalization


def test_canonical_timeline_is_the_median_length() -> None:
    takes = [as_take(generate_take("walk", s, 0, seed=0, duration_s=4.0)) for s in ("normal", "elderly")]
    seg = segment_takes(takes)
    canon = canonical_timelines(seg.clips)
    for (_, primitive), length in canon.items():
        lengths = [c.num_frames for c in seg.clips if c.primitive == primitive]
        assert length == int(round(float(np.median(lengths))))
    assert canonical_timelines(seg.clips, "max")[("walk", "leftStance")] >= canon[("walk", "leftStance")]
    with pytest.raises(ValueError, match="statistic"):
        canonical_timelines(seg.clips, "mode")


def test_time_normalization_keeps_duration_and_physical_velocities() -> None:
    g = generate_take("walk-turn-left", "active", 1, seed=0, duration_s=4.0)
    for clip in segment_take(as_take(g)).clips[:4]:
        for length in (clip.num_frames // 2 + 2, 60):
            normalized = time_normalize(clip.frames, length)
            assert normalized.shape == (length, 66) and normalized.dtype == np.float32
            np.testing.assert_allclose(normalized[0, :63], clip.frames[0, :63], atol=1e-6)
            np.testing.assert_allclose(normalized[-1, :63], clip.frames[-1, :63], atol=1e-6)
            # velocities stay m/s and rad/s: played back over the real duration the root ends where it did
            replay = frames_to_positions(normalized, playback_fps(length, clip.duration_s))
            hips = JOINT_INDEX["Hips"]
            np.testing.assert_allclose(replay[-1, hips], clip.positions[-1, hips], atol=0.01)
            # (a per-frame velocity would be off by the ratio of frame rates, far beyond 1 cm)
            back = restore_duration(normalized, clip.duration_s, clip.fps)
            assert back.shape == clip.frames.shape
            if length > clip.num_frames:  # upsampled and back: nothing lost (the last frame's velocity
                np.testing.assert_allclose(back[:-1], clip.frames[:-1], atol=0.01)  # points past the clip)
                np.testing.assert_allclose(back[-1, :63], clip.frames[-1, :63], atol=1e-5)
    with pytest.raises(ValueError, match="at least 2 frames"):
        time_normalize(np.zeros((1, 66)), 10)
    with pytest.raises(ValueError, match="positive"):
        playback_fps(10, 0.0)


# ---------------------------------------------------------------------------------------------
# Bandai: all seven styles, walks and runs (checks with numbers)


@pytest.fixture(scope="module")
def bandai_segmentation(bandai_zip_path: Path) -> tuple[TakeSet, Segmentation]:
    full = load_dataset("bandai", root=bandai_zip_path, contents=LOCOMOTION)
    picked: dict[tuple[str, str], list[Take]] = {}
    for take in full.takes:  # 3 takes per content × style: 84 takes
        group = picked.setdefault((take.content, take.style), [])
        if len(group) < 3:
            group.append(take)
    takes = [t for group in picked.values() for t in group]
    return TakeSet("bandai-subset", takes, full.fps), segment_takes(takes)


@pytest.mark.realdata
def test_bandai_step_coverage_and_still_planted_feet(bandai_segmentation) -> None:
    takeset, seg = bandai_segmentation
    assert {t.style for t in takeset.takes} == set(STYLES)
    assert not [r for r in seg.rejections if r.kind == "take"]
    for action in ("walk", "run"):
        takes = [t for t in seg.takes if t.action == action]
        clips = sum(len(t.clips) for t in takes)
        assert clips / sum(t.complete_steps for t in takes) >= 0.9, f"{action} step coverage"
    for style in STYLES:
        for action in ("walk", "run"):
            stance = [c for c in seg.clips if c.style == style and c.action == action]
            assert len(stance) >= 8, f"{action} {style}: only {len(stance)} clips"
            speeds = [stance_speeds(c.positions, c.fps, c.stance_foot, c.contacts) for c in stance]
            planted = np.mean([s["planted_mid"] for s in speeds])
            swing = np.mean([s["swing_mid"] for s in speeds])
            contact = np.mean([s["planted_contact"] for s in speeds])
            if action == "walk":
                assert planted <= 0.15, f"walk {style}: planted foot at {planted:.3f} m/s mid-clip"
            assert contact <= 0.2, f"{action} {style}: planted foot at {contact:.3f} m/s while in contact"
            assert swing > 5 * max(planted, 0.05), f"{action} {style}: swing {swing:.2f} vs planted {planted:.2f}"


@pytest.mark.realdata
def test_bandai_left_and_right_stances_alternate(bandai_segmentation) -> None:
    _, seg = bandai_segmentation
    kinds = Counter(c.primitive for c in seg.clips)
    assert set(kinds) <= set(PRIMITIVES) and kinds["leftStance"] and kinds["rightStance"]
    for take in seg.takes:
        for a, b in zip(take.clips, take.clips[1:]):
            if a.stop - 1 == b.start:
                assert a.stance_foot != b.stance_foot, f"{take.take}: {a.describe()} then {b.describe()}"
        for clip in take.clips:  # the planted foot touches the ground in the middle of its clip
            n = clip.num_frames
            assert clip.contacts[n // 2 - 1:n // 2 + 2, clip.stance_foot].any(), clip.describe()
