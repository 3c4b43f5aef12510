"""Dynamic motion graphs (Krüger §4.3): keys of a database take are met closely, held-out keys are joined with the
keys exact and less foot skating after cleaning, impossible keys and bad keys are named."""

from __future__ import annotations

import numpy as np
import pytest
from reconstruct_fixtures import synthetic_split

from stylemotion.datasets.base import TakeSet
from stylemotion.datasets.registry import load_dataset
from stylemotion.geometry import wrap_angle
from stylemotion.reconstruct.keyframes import (
    DynamicMotionGraph,
    Keyframe,
    KeyframeError,
    NoConnectionError,
    keys_from_motion,
    move_key,
    place,
    placements,
    resample,
    turn_key,
)
from stylemotion.reconstruct.texture import MotionTexturer, TextureInputError
from stylemotion.search.database import MotionDatabase
from stylemotion.synthesis.quality import skating

FPS = 30.0


@pytest.fixture(scope="module")
def split():
    return synthetic_split()


@pytest.fixture(scope="module")
def graph(split):
    return DynamicMotionGraph(split[0])


def _cm(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b, axis=-1).mean() * 100.0)


def test_keys_of_a_database_take_are_met_closely(split, graph):
    take = [t for t in split[1] if t.content == "walk"][0]
    keys = keys_from_motion(take.positions, FPS, 1.0, 0.5, 4.5)
    result = graph.synthesize(keys)
    assert result.key_frames == [0, 30, 60, 90, 120] and len(result.positions) == 121
    mid_key_errors = [result.settings["intermediate_first_key_error_cm"]]
    mid_key_errors += [p["intermediate_key_error_cm"] for p in result.pairs]
    truth = np.asarray(take.positions[15:15 + 121], dtype=np.float64)
    # References from the take itself, not from this result: the take's own frames are in the database, so a key is
    # met closer than half a frame of the take's motion (a neighbouring frame would be that far), and the whole
    # result is closer to the take than the take is to itself one frame later.
    one_frame = _cm(truth[1:], truth[:-1])
    assert np.mean(mid_key_errors) < 0.5 * one_frame, (mid_key_errors, one_frame)
    assert _cm(result.positions, truth) < _cm(np.asarray(take.positions[16:16 + 121]), truth)
    assert all(abs(p["duration_error_s"]) <= 1.0 / FPS + 1e-9 for p in result.pairs)  # within a frame


def test_held_out_keys_are_joined_exactly_and_cleaned(split, graph):
    take = [t for t in split[2] if t.content == "walk"][0]
    keys = keys_from_motion(take.positions, FPS, 2.0, 0.5, 6.5)
    result = graph.synthesize(keys)
    for frame, key in zip(result.key_frames, keys):
        np.testing.assert_allclose(result.positions[frame], key.pose, atol=1e-9)
    assert result.key_frames == [0, 60, 120, 180]
    assert all(p["iterations"] <= graph.max_iterations and p["connections"] >= 1 for p in result.pairs)
    # reference: the motion the keys alone give (linear interpolation between them) is farther from the take
    truth = np.asarray(take.positions[15:15 + len(result.positions)], dtype=np.float64)
    linear = np.concatenate([(1 - w) * truth[a] + w * truth[b] for a, b in zip(result.key_frames[:-1],
                                                                                 result.key_frames[1:])
                             for w in [np.linspace(0.0, 1.0, b - a + 1)[:-1, None, None]]] + [truth[-1:]])
    assert _cm(result.positions, truth) < _cm(linear, truth)
    # cleaning: less foot skating than the joined segments (measured 0.23 → 0.11), no frame-to-frame jump
    assert skating(result.positions, FPS)[0] < skating(result.intermediate, FPS)[0]
    assert np.linalg.norm(np.diff(result.positions, axis=0), axis=-1).max() < 0.3


def test_keys_too_far_apart_fail_naming_them(split):
    small = DynamicMotionGraph(split[0], max_iterations=2, clean=False)
    take = split[2][0]
    far = Keyframe(1.0, take.positions[40] + np.array([25.0, 0.0, 0.0]))
    with pytest.raises(NoConnectionError, match=r"keys at 0 s → 1 s.*did not meet in 2 iterations"):
        small.synthesize([Keyframe(0.0, take.positions[10]), far])


def test_bad_keys_and_settings_are_named(split, graph):
    pose = split[2][0].positions[0]
    with pytest.raises(KeyframeError, match="keyframe 1: time 1 s is not after keyframe 0's 2 s"):
        graph.synthesize([Keyframe(2.0, pose), Keyframe(1.0, pose)])
    with pytest.raises(KeyframeError, match="1 keyframe"):
        graph.synthesize([Keyframe(0.0, pose)])
    with pytest.raises(KeyframeError, match=r"keyframe 0: the pose must be \(21, 3\)"):
        graph.synthesize([Keyframe(0.0, pose[:5]), Keyframe(1.0, pose)])
    with pytest.raises(KeyframeError, match="voxel_m=0"):
        DynamicMotionGraph(split[0], voxel_m=0, clean=False)


def test_placing_and_resampling():
    take = load_dataset("synthetic", takes_per_pair=1).takes[0]
    p = np.asarray(take.positions[:20], dtype=np.float64)
    ground, yaw = placements(p, FPS)
    moved = place(p, ground[0], yaw[0], np.array([1.0, 0.0, 2.0]), yaw[0] + 0.5)
    back = place(moved, np.array([1.0, 0.0, 2.0]), yaw[0] + 0.5, ground[0], yaw[0])
    np.testing.assert_allclose(back, p, atol=1e-9)
    g2, y2 = placements(moved, FPS)
    np.testing.assert_allclose(g2[0], [1.0, 0.0, 2.0], atol=1e-9)
    np.testing.assert_allclose(np.angle(np.exp(1j * (y2 - yaw - 0.5))), 0.0, atol=1e-9)
    np.testing.assert_allclose(resample(p, 39)[::2], p, atol=1e-9)


def test_texturing_keeps_pinned_frames(split):
    take = split[2][0]
    coarse = np.asarray(take.positions[:60], dtype=np.float64) + 0.02
    texturer = MotionTexturer(split[0], "texture")
    out = texturer.apply(coarse, pinned=[0, 30, 59]).positions
    np.testing.assert_array_equal(out[[0, 30, 59]], coarse[[0, 30, 59]])
    assert not np.allclose(out[15], coarse[15], atol=1e-4)
    with pytest.raises(TextureInputError, match="pinned frame 60"):
        texturer.apply(coarse, pinned=[60])


@pytest.fixture(scope="module")
def short_turns():
    """A database of 3 s synthetic walks and ±90° turning walks (turns as tight as Bandai's, ~60°/s at most), and
    a held-out straight walk whose first two keys 1 s apart the tests turn and move."""
    ts = load_dataset("synthetic", takes_per_pair=1, duration_s=3.0, contents=["walk", "walk-turn-left",
                                                                               "walk-turn-right"])
    held = [t for t in ts.takes if t.content == "walk"][0]
    database = MotionDatabase.from_takeset(TakeSet("short-turns", [t for t in ts.takes if t is not held], ts.fps))
    first, second = keys_from_motion(held.positions, FPS, 1.0, 0.2, 1.2)
    return database, first, second


def _end_at(path: np.ndarray, key: Keyframe) -> tuple[float, float]:
    """Ground gap (cm) of the path's last Hips to the key's and their facing difference (degrees)."""
    ground, yaw = placements(np.stack([path[-1], key.pose]), FPS)
    return float(np.linalg.norm(ground[0] - ground[1]) * 100.0), float(np.rad2deg(abs(wrap_angle(yaw[0] - yaw[1]))))


def test_turn_and_move_key_transforms(short_turns):
    _, first, second = short_turns
    ground, yaw = placements(np.stack([first.pose, second.pose, turn_key(second.pose, np.pi / 2)]), FPS)
    np.testing.assert_allclose(ground[2], ground[1], atol=1e-12)  # turned about its own vertical
    assert np.rad2deg(wrap_angle(yaw[2] - yaw[1])) == pytest.approx(90.0)
    moved = move_key(first.pose, second.pose, 0.5, np.pi)
    g, y = placements(np.stack([moved]), FPS)
    # half as far, on the other side of the first key, facing back
    np.testing.assert_allclose(g[0] - ground[0], -0.5 * (ground[1] - ground[0]), atol=1e-12)
    assert abs(np.rad2deg(wrap_angle(y[0] - yaw[1]))) == pytest.approx(180.0)


def test_key_turned_against_travel_joins_with_the_turning_search(short_turns):
    database, first, second = short_turns
    back = Keyframe(second.time_s, turn_key(second.pose, np.pi))
    # the search before turn_radius_m (D_node of eq. 4.12 only): the trees stall face to face and never meet
    before = DynamicMotionGraph(database, turn_radius_m=0.0, max_iterations=12, clean=False)
    with pytest.raises(NoConnectionError, match="did not meet in 12 iterations"):
        before.connect(first, back)
    after = DynamicMotionGraph(database, turn_radius_m=1.0, max_iterations=24, clean=False)
    pair = after.connect(first, back)
    gap_cm, facing_deg = _end_at(pair.positions, back)
    # the path ends on the key (its incoming segments are placed onto it) facing its way, after a detour
    assert gap_cm < 1.0 and facing_deg < 15.0, (gap_cm, facing_deg)
    assert _end_at(pair.positions[:1], first)[0] < 1.0
    assert pair.figures["duration_s"] > 2.0  # a 180° turn at ≤ 60°/s cannot fit the keys' 1 s


def test_facing_search_first_falls_back_to_the_turning_search(short_turns):
    database, first, second = short_turns
    back = Keyframe(second.time_s, turn_key(second.pose, np.pi))
    facing = DynamicMotionGraph(database, turn_radius_m=0.0, max_iterations=12, clean=False)
    turning = DynamicMotionGraph(database, turn_radius_m=1.0, max_iterations=24, clean=False)
    both = DynamicMotionGraph(database, turn_radius_m=1.0, max_iterations=24, facing_first_iterations=12,
                              clean=False)
    # a straight pair: eq. 4.12's search meets, and its path is the one taken
    straight = both.connect(first, second)
    assert straight.figures["search"] == "facing"
    np.testing.assert_array_equal(straight.positions, facing.connect(first, second).positions)
    # the key turned back: eq. 4.12's search fails (test above), the turn-aware search from scratch joins it
    turned = both.connect(first, back)
    assert turned.figures["search"] == "turn-aware"
    alone = turning.connect(first, back)
    np.testing.assert_array_equal(turned.positions, alone.positions)
    assert turned.figures["seconds"] > 0 and both.settings()["facing_first_iterations"] == 12
    with pytest.raises(KeyframeError, match="facing_first_iterations=-1"):
        DynamicMotionGraph(database, facing_first_iterations=-1, clean=False)


def test_moved_key_path_ends_where_the_key_was_moved(short_turns):
    database, first, second = short_turns
    graph = DynamicMotionGraph(database, turn_radius_m=1.0, max_iterations=24, clean=False)
    for scale in (0.5, 1.5):
        moved = Keyframe(second.time_s, move_key(first.pose, second.pose, scale, 0.0))
        path = graph.connect(first, moved).positions
        gap_cm, facing_deg = _end_at(path, moved)
        assert gap_cm < 1.0 and facing_deg < 15.0, (scale, gap_cm, facing_deg)
        # and not where the key was before it moved (0.5 × or 1.5 × the walk's ~1 m apart)
        assert _end_at(path, second)[0] > 20.0
