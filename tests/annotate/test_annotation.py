import numpy as np
import pytest

from stylemotion.annotate.annotation import (
    AnnotationInputError,
    AnnotationSettings,
    annotate_features,
    frame_scores,
    keys_in_order,
    segment_scores,
    segments,
)
from stylemotion.annotate.command import annotate_positions
from stylemotion.annotate.documents import join_takes, random_document
from stylemotion.annotate.templates import MotionTemplate


def test_a_document_of_known_takes_gets_their_labels(synthetic_model, synthetic_split):
    pool = [(t.name, t.content, t.style, t.positions) for t in synthetic_split["test"]]
    doc = random_document(pool, 30.0, 40.0, np.random.default_rng(0))
    labels, records = annotate_positions(doc.positions, synthetic_model)
    frame, segment = frame_scores(doc.labels, labels), segment_scores(doc.labels, labels)
    # measured on this document (seed 0): P1 0.92, R1 0.72, F1 0.80; P2 = R2 = F2 = 1.0
    assert frame["P1"] > 0.9 and frame["F1"] > 0.78
    assert segment["F2"] > 0.95
    assert all(r["style"] in synthetic_model.tensors[r["label"]].styles for r in records)


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
