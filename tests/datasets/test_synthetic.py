"""The procedural synthetic locomotion: determinism, physical plausibility and known ground truth."""

from __future__ import annotations

import time

import numpy as np
import pytest

from stylemotion.datasets.synthetic import CONTENTS, STYLES, SyntheticTake, generate_take, generate_takes
from stylemotion.representation import frames_to_positions, positions_to_frames
from stylemotion.skeleton import JOINT_INDEX, bone_lengths

FEET = (("Foot_L", "Toes_L"), ("Foot_R", "Toes_R"))  # contact columns 0 (left) and 1 (right)


@pytest.fixture(scope="module")
def takes() -> dict[tuple[str, str], list[SyntheticTake]]:
    """Two takes of every (content, style) pair, keyed by (content, style)."""
    out: dict[tuple[str, str], list[SyntheticTake]] = {}
    for take in generate_takes(takes_per_pair=2):
        out.setdefault((take.labels["content"], take.labels["style"]), []).append(take)
    return out


def all_takes(takes: dict[tuple[str, str], list[SyntheticTake]]) -> list[SyntheticTake]:
    return [t for group in takes.values() for t in group]


def local_frames(take: SyntheticTake) -> np.ndarray:
    """``(frames, 66)`` frame representation of a take."""
    return positions_to_frames(take.positions, take.fps)[0]


def mean_over(takes, content: str, style: str, measure) -> float:
    return float(np.mean([measure(t) for t in takes[(content, style)]]))


def root_speed(take: SyntheticTake) -> float:
    """Mean ground speed of the root, m/s."""
    return float(np.linalg.norm(local_frames(take)[:, 63:65], axis=1).mean())


def cadence(take: SyntheticTake) -> float:
    """Footfalls per minute (rising edges of the contacts)."""
    strikes = np.sum(np.diff(take.contacts.astype(int), axis=0) == 1)
    return 60.0 * strikes / (len(take.positions) / take.fps)


def stride_length(take: SyntheticTake) -> float:
    """Mean distance between consecutive footfalls of the same foot, metres."""
    lengths = []
    for column, (ankle, _) in enumerate(FEET):
        strikes = np.nonzero(np.diff(take.contacts[:, column].astype(int)) == 1)[0] + 1
        spots = take.positions[strikes, JOINT_INDEX[ankle]][:, [0, 2]]
        lengths.extend(np.linalg.norm(np.diff(spots, axis=0), axis=1))
    return float(np.mean(lengths))


def arm_swing(take: SyntheticTake) -> float:
    """Standard deviation of the hands' forward position relative to the body, metres."""
    local = local_frames(take)[:, :63].reshape(-1, 21, 3)
    return float(np.mean([local[:, JOINT_INDEX[h], 2].std() for h in ("Hand_L", "Hand_R")]))


def torso_lean(take: SyntheticTake) -> float:
    """Mean forward offset of the neck over the hips, metres."""
    local = local_frames(take)[:, :63].reshape(-1, 21, 3)
    return float((local[:, JOINT_INDEX["Neck"], 2] - local[:, JOINT_INDEX["Hips"], 2]).mean())


def head_drop(take: SyntheticTake) -> float:
    """Mean forward offset of the head over the neck, metres."""
    local = local_frames(take)[:, :63].reshape(-1, 21, 3)
    return float((local[:, JOINT_INDEX["Head"], 2] - local[:, JOINT_INDEX["Neck"], 2]).mean())


def foot_lift(take: SyntheticTake) -> float:
    """Mean of the highest ankle height in each take's swings, metres (95th percentile)."""
    heights = [take.positions[~take.contacts[:, c], JOINT_INDEX[a], 1] for c, (a, _) in enumerate(FEET)]
    return float(np.percentile(np.concatenate(heights), 95))


def test_api_lists_bandai_styles_and_locomotion_contents():
    assert set(STYLES) == {"active", "elderly", "exhausted", "feminine", "masculine", "normal", "youthful"}
    assert CONTENTS == ("walk", "walk-turn-left", "walk-turn-right", "run")


def test_same_arguments_give_identical_takes_and_other_seeds_differ():
    a = generate_take("walk", "elderly", 3, seed=7)
    b = generate_take("walk", "elderly", 3, seed=7)
    assert np.array_equal(a.positions, b.positions) and np.array_equal(a.contacts, b.contacts)
    for other in (generate_take("walk", "elderly", 3, seed=8), generate_take("walk", "elderly", 4, seed=7)):
        assert np.abs(other.positions - a.positions).max() > 0.01


def test_shapes_dtypes_names_and_labels(takes):
    names = set()
    for take in all_takes(takes):
        assert take.positions.shape == (240, 21, 3) and take.positions.dtype == np.float32
        assert take.contacts.shape == (240, 2) and take.contacts.dtype == np.bool_
        assert take.fps == 30.0 and np.isfinite(take.positions).all()
        assert take.labels["actor"] == "synthetic" and take.labels["content"] in CONTENTS
        assert take.labels["style"] in STYLES and take.labels["take"] in ("000", "001")
        names.add(take.name)
    assert len(names) == len(CONTENTS) * len(STYLES) * 2
    assert "synthetic_walk-turn-left_elderly_001" in names
    assert generate_take("run", "normal", 0, fps=60.0, duration_s=2.5).positions.shape == (150, 21, 3)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"content": "jump", "style": "normal"}, r"unknown content 'jump'.*walk-turn-left"),
        ({"content": "walk", "style": "angry"}, r"unknown style 'angry'.*youthful"),
    ],
)
def test_unknown_content_or_style_is_a_clear_error(kwargs, message):
    with pytest.raises(ValueError, match=message):
        generate_take(index=0, **kwargs)
    with pytest.raises(ValueError, match=message):
        generate_takes(1, styles=[kwargs["style"]], contents=[kwargs["content"]])


def test_subsets_and_order():
    subset = generate_takes(2, styles=["youthful", "elderly"], contents=["run"], duration_s=1.0)
    assert [t.name for t in subset] == [
        "synthetic_run_youthful_000", "synthetic_run_youthful_001",
        "synthetic_run_elderly_000", "synthetic_run_elderly_001",
    ]  # fmt: skip


def test_bone_lengths_are_constant(takes):
    for take in all_takes(takes):
        lengths = bone_lengths(take.positions.astype(np.float64))
        assert np.ptp(lengths, axis=0).max() < 1e-4, take.name


def test_body_size_is_adult_and_varies_per_take(takes):
    heads = [t.positions[:, JOINT_INDEX["Head"], 1].mean() for t in takes[("walk", "normal")]]
    heads += [t.positions[:, JOINT_INDEX["Head"], 1].mean() for t in takes[("walk", "masculine")]]
    assert all(1.35 < h < 1.65 for h in heads)
    thighs = [bone_lengths(t.positions[0])[JOINT_INDEX["LowerLeg_L"]] for t in all_takes(takes)]
    assert np.ptp(thighs) > 0.02 and all(0.40 < x < 0.46 for x in thighs)


def test_planted_feet_are_still_on_the_ground_and_nothing_goes_below_it(takes):
    for take in all_takes(takes):
        assert take.positions[..., 1].min() > -1e-3, take.name
        for column, (ankle, toes) in enumerate(FEET):
            planted = take.contacts[:-1, column] & take.contacts[1:, column]
            assert planted.mean() > 0.2, take.name
            for joint, height in ((ankle, 0.09), (toes, 0.03)):
                track = take.positions[:, JOINT_INDEX[joint]]
                speed = np.linalg.norm(np.diff(track[:, [0, 2]], axis=0), axis=1) * take.fps
                assert speed[planted].max() < 0.02, (take.name, joint)
                assert track[take.contacts[:, column], 1].max() < height, (take.name, joint)
            swinging = ~take.contacts[:, column]
            assert take.positions[swinging, JOINT_INDEX[ankle], 1].max() > 0.1, take.name


def test_a_plain_speed_threshold_finds_the_contacts_within_one_frame(takes):
    for take in all_takes(takes):
        for column, joints in enumerate(FEET):
            tracks = take.positions[:, [JOINT_INDEX[j] for j in joints]]
            speed = (np.linalg.norm(np.diff(tracks, axis=0), axis=-1) * take.fps).max(axis=1)
            detected = np.concatenate([speed, speed[-1:]]) < 0.2
            truth = take.contacts[:, column]
            edges = np.nonzero(np.diff(truth.astype(int)))[0] + 0.5
            wrong = np.nonzero(detected != truth)[0]
            assert len(wrong) == 0 or np.abs(wrong[:, None] - edges).min(axis=1).max() <= 1.0, take.name


def test_walks_have_double_support_and_runs_have_flight(takes):
    for take in all_takes(takes):
        both = take.contacts.all(axis=1).mean()
        neither = (~take.contacts.any(axis=1)).mean()
        if take.labels["content"] == "run":
            assert neither > 0.1 and both == 0.0, take.name
        else:
            assert 0.1 < both < 0.4 and neither == 0.0, take.name


@pytest.mark.parametrize(("content", "low", "high"), [
    ("walk-turn-left", 60.0, 125.0), ("walk-turn-right", -125.0, -60.0), ("walk", -30.0, 30.0), ("run", -30.0, 30.0),
])  # fmt: skip
def test_takes_turn_the_right_way(takes, content, low, high):
    for style in STYLES:
        for take in takes[(content, style)]:
            frames = local_frames(take)
            turned = np.degrees(frames[:-1, 65].sum() / take.fps)
            assert low < turned < high, (take.name, turned)


def test_body_faces_the_direction_of_travel(takes):
    for take in all_takes(takes):
        frames = local_frames(take)
        forward, sideways = frames[:, 64], frames[:, 63]
        assert forward.mean() > 0.4, take.name
        assert np.abs(sideways).mean() < 0.25 * forward.mean(), take.name


def test_positions_frames_positions_round_trip(takes):
    for take in (takes[("walk-turn-left", "feminine")][0], takes[("run", "active")][1]):
        frames, start_xz, start_yaw = positions_to_frames(take.positions, take.fps)
        back = frames_to_positions(frames, take.fps, start_xz, start_yaw)
        assert np.abs(back - take.positions).max() < 1e-3


def test_styles_differ_as_designed(takes):
    def m(measure, style, content="walk"):
        return mean_over(takes, content, style, measure)

    assert m(root_speed, "elderly") < m(root_speed, "normal") < m(root_speed, "active")
    assert m(root_speed, "exhausted") < m(root_speed, "normal") < m(root_speed, "youthful")
    assert m(stride_length, "elderly") < m(stride_length, "normal") < m(stride_length, "active")
    assert m(cadence, "exhausted") < m(cadence, "elderly") < m(cadence, "normal") < m(cadence, "youthful")
    assert m(arm_swing, "elderly") < m(arm_swing, "normal") < m(arm_swing, "youthful")
    assert m(torso_lean, "normal") + 0.03 < m(torso_lean, "exhausted") < m(torso_lean, "elderly")
    assert m(head_drop, "normal") + 0.03 < m(head_drop, "exhausted")
    assert m(foot_lift, "exhausted") < m(foot_lift, "normal") < m(foot_lift, "youthful")
    for style in STYLES:  # runs are faster, with a higher cadence and longer strides
        for measure in (root_speed, cadence, stride_length):
            assert m(measure, style, "run") > 1.2 * m(measure, style), (style, measure.__name__)


def test_step_width_differs_between_masculine_and_feminine(takes):
    def width(take: SyntheticTake) -> float:
        """Mean sideways distance between the ankles, metres."""
        local = local_frames(take)[:, :63].reshape(-1, 21, 3)
        return float(np.abs(local[:, JOINT_INDEX["Foot_L"], 0] - local[:, JOINT_INDEX["Foot_R"], 0]).mean())

    assert mean_over(takes, "walk", "feminine", width) + 0.08 < mean_over(takes, "walk", "masculine", width)


def test_default_set_is_fast():
    start = time.perf_counter()
    generated = generate_takes()
    assert len(generated) == len(STYLES) * len(CONTENTS) * 4
    assert time.perf_counter() - start < 10.0


@pytest.mark.parametrize("options", [{"duration_s": 1e9}, {"takes_per_pair": 10**7}, {"fps": 1e7}])
def test_sizes_beyond_the_generator_are_refused_before_anything_is_generated(options) -> None:
    """An absurd size from a config is one line naming the keys, never an allocation of terabytes."""
    from stylemotion.datasets.registry import DatasetOptionError, load_dataset

    with pytest.raises(DatasetOptionError, match="data.takes_per_pair=.*data.duration_s=.*more than the synthetic"):
        load_dataset("synthetic", **options)
