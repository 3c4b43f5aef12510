import numpy as np
import pytest

from stylemotion.annotate.annotation import (
    AnnotationInputError,
    AnnotationSettings,
    annotate_features,
    drop_short_runs,
    frame_scores,
    keys_in_order,
    segment_scores,
    segments,
)
from stylemotion.annotate.command import annotate_positions
from stylemotion.annotate.documents import join_takes, part_scores, partition_documents
from stylemotion.annotate.subsequence import subsequence_dtw
from stylemotion.annotate.templates import MotionTemplate

#: Per-take recall and precision (mean, sample SD, takes) of the synthetic VAL takes, measured once with the
#: default settings by ``take_scores(synthetic_model, synthetic_split["val"])`` (val data, never the test takes).
VAL_RECALL, VAL_PRECISION, VAL_TAKES = (0.8155, 0.2951), (0.8644, 0.3036), 28


def take_scores(model, takes) -> tuple[np.ndarray, np.ndarray, list[dict]]:
    """Per-take recall and precision of one document of ``takes`` (name order) annotated with the defaults."""
    takes = sorted(takes, key=lambda t: t.name)
    doc = join_takes([(t.name, t.content, t.style, t.positions) for t in takes], 30.0)
    labels, records = annotate_positions(doc.positions, model)
    parts = part_scores(doc, labels)
    return np.array([p["recall"] for p in parts]), np.array([p["precision"] for p in parts]), records


def within_validation(test: np.ndarray, val: tuple[float, float]) -> float:
    """The least test mean the validation split allows: val mean − 3 standard errors of the difference of two
    means (val's SD for both samples)."""
    mean, sd = val
    return mean - 3 * sd * np.sqrt(1 / VAL_TAKES + 1 / len(test))


def test_test_takes_score_within_the_validation_tolerance(synthetic_model, synthetic_split):
    recall, precision, records = take_scores(synthetic_model, synthetic_split["test"])
    assert recall.mean() >= within_validation(recall, VAL_RECALL)
    assert precision.mean() >= within_validation(precision, VAL_PRECISION)
    assert all(r["style"] in synthetic_model.tensors[r["label"]].styles for r in records)


def brute_force_subsequence_dtw(cost: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The recursion written cell by cell: D(0, j) = c(0, j); D(i, j) = c(i, j) + min(D(i−1, j−1), D(i−2, j−1),
    D(i−1, j−2)); Δ = D(m−1, ·) / m and the start column of each best path."""
    m, n = cost.shape
    d = np.full((m, n), np.inf)
    start = np.full((m, n), -1)
    d[0], start[0] = cost[0], np.arange(n)
    for i in range(1, m):
        for j in range(n):
            options = [(d[i - 1, j - 1], start[i - 1, j - 1]) if j >= 1 else (np.inf, -1),
                       (d[i - 2, j - 1], start[i - 2, j - 1]) if i >= 2 and j >= 1 else (np.inf, -1),
                       (d[i - 1, j - 2], start[i - 1, j - 2]) if j >= 2 else (np.inf, -1)]
            best, s = min(options, key=lambda o: o[0])
            if np.isfinite(best):
                d[i, j], start[i, j] = cost[i, j] + best, s
    return d[-1] / m, start[-1]


@pytest.mark.parametrize("fractions", [False, True])
@pytest.mark.parametrize("m, n", [(1, 5), (4, 9), (7, 30), (12, 20), (14, 73), (23, 74)])
def test_subsequence_dtw_equals_the_cell_by_cell_recursion(m, n, fractions):
    """Also on costs of a few fractions (like local_cost's), where predecessor sums tie after rounding."""
    rng = np.random.default_rng(m * 100 + n)
    cost = rng.integers(0, 8, (m, n)) / 21 if fractions else rng.random((m, n))
    delta, start = subsequence_dtw(cost)
    want_delta, want_start = brute_force_subsequence_dtw(cost)
    assert np.array_equal(np.isinf(delta), np.isinf(want_delta))
    assert np.allclose(delta[np.isfinite(delta)], want_delta[np.isfinite(want_delta)], atol=1e-12)
    assert np.array_equal(start, want_start)


def test_key_frames_in_order_equal_a_scan_of_every_segment():
    rng = np.random.default_rng(3)
    for _ in range(20):
        matches = rng.random((3, 40)) < 0.15
        start = rng.integers(-1, 40, size=40)
        start = np.where(start <= np.arange(40), start, -1)
        want = []
        for end, a in enumerate(start):
            t, ok = a, a >= 0
            for row in matches:
                hits = [f for f in range(max(t, 0), end + 1) if row[f]] if ok else []
                ok, t = bool(hits), (hits[0] if hits else t)
            want.append(ok)
        assert keys_in_order(matches, start).tolist() == want


def test_short_runs_equal_a_loop_over_runs():
    rng = np.random.default_rng(5)
    labels = rng.choice([-1, 0, 1, 2], size=300, p=[0.1, 0.3, 0.3, 0.3])
    labels = np.repeat(labels, rng.integers(1, 8, size=300))
    for min_run in (0, 1, 3, 6, 12):
        want = labels.copy()
        i = 0
        while i < len(labels):
            j = i
            while j < len(labels) and labels[j] == labels[i]:
                j += 1
            if labels[i] >= 0 and j - i < min_run:
                want[i:j] = -1
            i = j
        assert np.array_equal(drop_short_runs(labels, min_run), want)


def test_frame_score_counts_add_up():
    truth = ["a", "a", "b", "", "b", "c", ""]
    pred = ["a", "", "a", "a", "b", "", ""]
    f = frame_scores(truth, pred)
    assert (f["unlabelled1"], f["confused1"], f["spurious1"]) == (2, 1, 1)
    assert f["unlabelled1"] + f["confused1"] + round(f["R1"] * f["relevant1"]) == f["relevant1"]


def test_partition_uses_every_take_once(synthetic_split):
    pool = [(t.name, t.content, t.style, t.positions) for t in synthetic_split["val"]]
    docs = partition_documents(pool, 30.0, 20.0, np.random.default_rng(1), blend_frames=8)
    names = [p[0] for d in docs for p in d.parts]
    assert sorted(names) == sorted(t[0] for t in pool)
    assert all(len(d.labels) >= 20 * 30 for d in docs)
    for d in docs:
        for _name, content, _, a, b in d.parts:
            assert set(d.labels[a:b]) == {content}


def test_scores_and_segments():
    truth = ["a", "a", "", "b", "b", "b"]
    pred = ["a", "", "", "b", "a", "a"]
    assert segments(pred) == [(0, 1, "a"), (3, 4, "b"), (4, 6, "a")]
    f = frame_scores(truth, pred)
    assert (f["P1"], f["R1"]) == (2 / 4, 2 / 5)
    s = segment_scores(truth, pred)
    assert (s["P2"], s["R2"]) == (2 / 3, 1.0)


def test_key_frames_in_order():
    matches = np.zeros((2, 10), dtype=bool)
    matches[0, 2] = matches[1, 6] = True
    ok = keys_in_order(matches, np.array([0, 0, 0, 0, 0, 0, 0, 0, 3, -1]))
    assert ok.tolist() == [False] * 6 + [True, True, False, False]


def test_blends_are_unlabelled(synthetic_split):
    takes = [(t.name, t.content, t.style, t.positions) for t in synthetic_split["test"][:2]]
    doc = join_takes(takes, 30.0, blend_frames=8)
    first_end = doc.parts[0][4]
    assert doc.labels[first_end:first_end + 8] == ("",) * 8 and len(doc.labels) == len(doc.positions)


def test_document_shorter_than_the_templates():
    t = MotionTemplate("long", np.zeros((40, 3)), 2)
    with pytest.raises(AnnotationInputError, match="shorter than any template"):
        annotate_features(np.zeros((10, 3), dtype=bool), [t], AnnotationSettings())


def test_sub_templates_find_a_part_shorter_than_half_the_template():
    """A document holding a third of a class's pattern: the whole template cannot match it (tempo at most 2×),
    windows of the template can, and they label the planted frames with the class."""
    rng = np.random.default_rng(3)
    pattern = rng.random((60, 8)) > 0.5
    template = MotionTemplate("walk", pattern.astype(float), 9)
    noise = ~pattern[::-1][:40]                            # frames contradicting the pattern everywhere near
    document = np.concatenate([noise, pattern[20:40], noise])
    whole = annotate_features(document, [template], AnnotationSettings(tau=0.05, min_run=0))
    assert (whole.labels < 0).all()
    parts = annotate_features(document, [template], AnnotationSettings(tau=0.05, min_run=0, sub_frames=20))
    planted = parts.labels[40:60]
    assert (planted == 0).mean() >= 0.9
    assert (parts.labels[:30] < 0).all() and (parts.labels[70:] < 0).all()


def test_negative_sub_frames_are_refused():
    t = MotionTemplate("walk", np.zeros((40, 3)), 2)
    with pytest.raises(AnnotationInputError, match="sub_frames=-1"):
        annotate_features(np.zeros((60, 3), dtype=bool), [t], AnnotationSettings(sub_frames=-1))
