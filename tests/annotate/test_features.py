import numpy as np
import pytest

from stylemotion.annotate.features import FEATURE_NAMES, NUM_FEATURES, FeatureInputError, relational_features


def test_shape_names_and_scale_invariance(synthetic_split):
    take = synthetic_split["train"][0]
    f = relational_features(take.positions, take.fps)
    assert f.shape == (take.num_frames, NUM_FEATURES) and f.dtype == bool
    assert len(set(FEATURE_NAMES)) == NUM_FEATURES >= 40
    # thresholds in body units: a 1.5× larger body moving the same way (scaled in space) has the same features
    assert np.array_equal(relational_features(take.positions * 1.5, take.fps), f)


def test_walk_and_run_features(synthetic_split):
    def mean(content: str, name: str) -> float:
        take = next(t for t in synthetic_split["train"] if t.content == content)
        return float(relational_features(take.positions, take.fps)[:, FEATURE_NAMES.index(name)].mean())

    assert mean("walk", "root_fast") > 0.9 and mean("walk", "root_very_fast") == 0.0
    assert mean("run", "root_very_fast") > 0.9
    assert mean("walk-turn-left", "root_turning_left") > 0.5 > mean("walk-turn-left", "root_turning_right")
    assert mean("walk-turn-right", "root_turning_right") > 0.5 > mean("walk-turn-right", "root_turning_left")


@pytest.mark.parametrize("positions, match", [
    (np.zeros((5, 20, 3)), "21, 3"),
    (np.full((5, 21, 3), np.nan), "NaN or infinite"),
    (np.zeros((5, 21, 3)), "degenerate body"),
])
def test_bad_input(positions, match):
    with pytest.raises(FeatureInputError, match=match):
        relational_features(positions, 30.0)
