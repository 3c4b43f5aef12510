"""The style classifier on synthetic clips, where the seven styles are known by construction."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.datasets.registry import load_synthetic
from stylemotion.evaluation.classifier import StyleClassifier, clip_descriptors, confusion, predicted_shares
from stylemotion.evaluation.reference import primitive_data
from stylemotion.evaluation.sources import motions_from_clips

SPLIT = {"seed": 0, "val_fraction": 0.2, "test_fraction": 0.2}


@pytest.fixture(scope="module")
def data():
    takeset = load_synthetic(takes_per_pair=5, duration_s=5.0, contents=["walk"])  # all seven styles
    return primitive_data(takeset, "walk_rightStance", 16, split=SPLIT)


def _motions(clips):
    m = motions_from_clips(clips, 16)
    return m.normalized_frames.numpy(), m.duration_s.numpy(), [c.style for c in clips]


def test_classifier_recognizes_real_heldout_clips_well_above_chance(data) -> None:
    assert len(data.styles) == 7
    frames, durations, styles = _motions(data.split("train"))
    clf = StyleClassifier(components=16, seed=0).fit(frames, durations, styles)
    held_frames, held_durations, held_styles = _motions(data.heldout())
    report = clf.evaluate(held_frames, held_durations, held_styles)
    assert report.clips == len(held_styles) >= 30
    assert report.accuracy >= 0.8, report.confusion  # chance is 1/7
    assert report.confusion.sum() == report.clips
    assert np.trace(report.confusion) == round(report.accuracy * report.clips)
    assert min(report.recall.values()) >= 0.5
    features = clf.features(held_frames, held_durations)
    assert features.shape == (len(held_styles), 16)
    again = StyleClassifier(components=16, seed=0).fit(frames, durations, styles)  # fixed seed: same verdicts
    assert (again.predict(held_frames, held_durations) == clf.predict(held_frames, held_durations)).all()


def test_classifier_bad_input(data) -> None:
    frames, durations, styles = _motions(data.split("train", "normal"))
    with pytest.raises(ValueError, match="at least 2 styles"):
        StyleClassifier().fit(frames, durations, styles)
    with pytest.raises(RuntimeError, match="fit"):
        StyleClassifier().features(frames, durations)
    frames, durations, styles = _motions(data.split("train"))
    clf = StyleClassifier(components=4).fit(frames, durations, styles)
    with pytest.raises(ValueError, match="16 frames"):
        clf.features(frames[:, :10], durations)
    with pytest.raises(ValueError, match="positive"):
        clip_descriptors(frames, -durations)


def test_confusion_and_shares() -> None:
    m = confusion(["a", "a", "b"], ["a", "b", "b"], ["a", "b"])
    assert m.tolist() == [[1, 1], [0, 1]]
    assert predicted_shares(["a", "b", "b", "b"], ["a", "b", "c"]) == {"a": 0.25, "b": 0.75, "c": 0.0}
