import numpy as np
import pytest

from stylemotion.annotate.subsequence import subsequence_dtw
from stylemotion.annotate.templates import (
    MotionTemplate,
    TemplateInputError,
    learn_template,
    local_cost,
    sub_templates,
)


def test_identical_examples_give_a_consistent_template():
    rng = np.random.default_rng(0)
    x = rng.random((40, 6)) > 0.5
    t = learn_template("c", [x, x, x])
    assert t.num_frames == 40 and t.mask.all()
    assert np.array_equal(t.quantized, x.astype(float))
    assert np.allclose(np.diag(local_cost(t, x)), 0.0)


def test_time_warped_examples_average_to_the_pattern():
    base = np.zeros((30, 2), dtype=bool)
    base[10:20, 0] = True
    slow = np.repeat(base, 2, axis=0)                   # the same motion at half speed
    t = learn_template("c", [base, slow])
    assert t.num_frames == 45
    on = t.values[:, 0] > 0.5
    assert 0.25 < on.mean() < 0.45                      # the on-phase keeps its share of the timeline
    assert (t.values[:, 1] == 0).all()


def test_masked_cost_ignores_wildcards():
    t = MotionTemplate("c", np.array([[1.0, 0.5, 0.0]]), 2)
    doc = np.array([[1, 1, 0], [1, 0, 0], [0, 0, 1]], dtype=bool)
    assert np.allclose(local_cost(t, doc), [[0.0, 0.0, 1.0]])


def test_fewer_than_two_examples():
    with pytest.raises(TemplateInputError, match="'jump' has 1 example"):
        learn_template("jump", [np.zeros((5, 3))])


def test_subsequence_dtw_finds_a_planted_segment():
    cost = np.ones((6, 50))
    cost[:, 20:32] = 0.0                                  # a stretch matched at 2x slower tempo
    delta, start = subsequence_dtw(cost)
    end = int(np.argmin(delta))
    assert delta[end] == 0.0 and 20 <= start[end] and end <= 31
    assert np.isinf(delta[:2]).all()                       # a 6-frame template needs ≥ 3 document frames


def test_sub_templates_cover_the_template_half_overlapping():
    values = np.random.default_rng(1).random((50, 4))
    parts = sub_templates(MotionTemplate("walk", values, 9), 20)
    assert [p.num_frames for p in parts] == [20] * 4 and all(p.label == "walk" and p.examples == 9 for p in parts)
    starts = [int(np.flatnonzero((values == p.values[0]).all(1))[0]) for p in parts]
    assert starts == [0, 10, 20, 30]                      # every 10 frames, the last ending at frame 49
    assert np.array_equal(parts[-1].values, values[30:])
    assert sub_templates(MotionTemplate("walk", values, 9), 0)[0].values is values
    assert len(sub_templates(MotionTemplate("walk", values, 9), 50)) == 1
