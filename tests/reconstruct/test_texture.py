"""Motion completion and texturing (Krüger §4.2): exact on database takes, better than the nearest neighbour on
held-out takes, trusted joints kept, a style database transfers its style, bad inputs named."""

from __future__ import annotations

import numpy as np
import pytest
from reconstruct_fixtures import synthetic_split

from stylemotion.datasets.base import TakeSet
from stylemotion.datasets.registry import load_dataset
from stylemotion.reconstruct.texture import LEG_JOINTS, MotionTexturer, TextureInputError, key_spline
from stylemotion.search.database import MotionDatabase
from stylemotion.skeleton import JOINT_INDEX

TRUSTED = [JOINT_INDEX[j] for j in LEG_JOINTS]
UPPER = [i for i in range(21) if i not in TRUSTED]


def _cm(a: np.ndarray, b: np.ndarray, joints: list[int]) -> float:
    return float(np.linalg.norm(a[:, joints] - b[:, joints], axis=-1).mean() * 100)


@pytest.fixture(scope="module")
def split():
    return synthetic_split()


@pytest.fixture(scope="module")
def completer(split):
    return MotionTexturer(split[0], "complete")


def test_a_database_take_is_completed_almost_exactly(split, completer):
    take = split[1][3]
    legs_only = take.positions.astype(np.float64).copy()
    legs_only[:, UPPER] = np.nan
    result = completer.apply(legs_only)
    assert _cm(result.positions, take.positions, UPPER) < 0.05
    assert result.positions.shape == take.positions.shape


def test_held_out_upper_bodies_beat_the_nearest_neighbour(split, completer):
    ours, baseline = [], []
    for take in split[2]:
        result = completer.apply(take.positions)
        ours.append(_cm(result.positions, take.positions, UPPER))
        baseline.append(_cm(result.nearest_neighbour, take.positions, UPPER))
    assert np.mean(ours) < 0.97 * np.mean(baseline), (ours, baseline)


def test_trusted_joints_are_kept_and_the_rest_is_smooth(split, completer):
    take = split[2][0]
    result = completer.apply(take.positions)
    np.testing.assert_array_equal(result.positions[:, TRUSTED], take.positions[:, TRUSTED])
    jerk = np.abs(np.diff(result.positions[:, UPPER], 3, axis=0)).mean()
    assert jerk < 2 * np.abs(np.diff(take.positions[:, UPPER], 3, axis=0)).mean() + 1e-4


def test_texturing_a_key_spline_brings_the_detail_back(split):
    take = split[1][3]
    spline = key_spline(take.positions, 3)
    result = MotionTexturer(split[0], "texture").apply(spline)
    everything = list(range(21))
    assert _cm(result.raw, take.positions, everything) < 0.8 * _cm(spline, take.positions, everything)
    assert _cm(result.positions, take.positions, everything) < _cm(spline, take.positions, everything)


def test_an_elderly_database_makes_completion_a_style_transfer():
    ts = load_dataset("synthetic", takes_per_pair=1)
    elderly = [t for t in ts.takes if t.style == "elderly" and t.content != "walk"]
    database = MotionDatabase.from_takeset(TakeSet("synthetic", elderly, ts.fps))
    by_name = {t.name: t.positions for t in ts.takes}
    query, old = by_name["synthetic_walk_normal_000"], by_name["synthetic_walk_elderly_000"]
    result = MotionTexturer(database, "complete").apply(query)

    def posture(p: np.ndarray) -> np.ndarray:  # mean upper body relative to the hips
        return (p[:, UPPER] - p[:, [JOINT_INDEX["Hips"]]]).mean(axis=0)

    assert np.linalg.norm(posture(result.positions) - posture(old)) < np.linalg.norm(
        posture(result.positions) - posture(query))


def test_bad_inputs_name_the_value(split, completer):
    with pytest.raises(TextureInputError, match="'Tail'"):
        MotionTexturer(split[0], "complete", joints=["Hips", "Tail"])
    with pytest.raises(TextureInputError, match="mode=smooth"):
        MotionTexturer(split[0], "smooth")
    with pytest.raises(TextureInputError, match="2 frame"):
        completer.apply(split[2][0].positions[:2])
    broken = split[2][0].positions.astype(np.float64).copy()
    broken[5, JOINT_INDEX["Foot_L"], 1] = np.nan
    with pytest.raises(TextureInputError, match="Foot_L is not finite at frame 5"):
        completer.apply(broken)
    with pytest.raises(TextureInputError, match="weights.smooth=-1"):
        MotionTexturer(split[0], "texture", weights={"smooth": -1})
