"""A style classifier on real clips, and the feature space of the Fréchet distance and diversity.

The thesis judged style only by the Gram distance its models were trained to minimize (Table 5.1).
This classifier is an outside judge that never sees the autoencoder: it is fitted on **real**
train-split clips of every style of one primitive, and must first show its accuracy on real
held-out clips before its verdict on generated samples means anything.

Descriptor of a clip: its 66-dim frames on the primitive's canonical timeline (``length`` frames:
root-local joint positions in metres, root ground velocity in m/s, yaw rate in rad/s, see
:mod:`stylemotion.representation`), flattened, plus the log of its real duration in seconds:
``length · 66 + 1`` values. Pipeline (scikit-learn, deterministic for a fixed ``seed``):

    descriptor ──z-score per value (train clips)──▶ PCA to ``components`` dims ──▶ multinomial
    logistic regression (L2, inverse strength ``C``)

The **feature space** is the PCA scores, ``(n, components)`` in units of standardized descriptor
values; :func:`stylemotion.evaluation.metrics.frechet_distance` and
:func:`~stylemotion.evaluation.metrics.diversity` are computed there. It spans the directions of
largest variation of real clips of all styles, so it sees content (speed, turning, step length) as
well as style.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from sklearn.decomposition import PCA
from sklearn.linear_model import LogisticRegression
from sklearn.preprocessing import StandardScaler

from stylemotion.representation import FRAME_DIM


def clip_descriptors(normalized_frames: np.ndarray, duration_s: np.ndarray) -> np.ndarray:
    """Descriptors of time-normalized clips (see the module doc).

    Args:
        normalized_frames: ``(n, length, 66)`` frames on the canonical timeline.
        duration_s: ``(n,)`` real durations, seconds (> 0).

    Returns:
        ``(n, length · 66 + 1)`` float64.
    """
    f = np.asarray(normalized_frames, dtype=np.float64)
    d = np.asarray(duration_s, dtype=np.float64).reshape(-1)
    if f.ndim != 3 or f.shape[-1] != FRAME_DIM or len(f) != len(d):
        raise ValueError(f"need frames (n, length, {FRAME_DIM}) and n durations, got {f.shape} and {d.shape}")
    if len(d) and not (d > 0).all():
        raise ValueError("durations must be positive")
    return np.concatenate([f.reshape(len(f), -1), np.log(d)[:, None]], axis=1)


@dataclass
class ClassifierReport:
    """Accuracy and confusion of the classifier on labelled clips.

    Attributes:
        styles: class order of the confusion matrix.
        accuracy: share of clips assigned their own style.
        confusion: ``(styles, styles)`` counts, rows = true style, columns = predicted style.
        clips: number of clips.
    """

    styles: list[str]
    accuracy: float
    confusion: np.ndarray
    clips: int

    @property
    def recall(self) -> dict[str, float]:
        """Per true style: the share of its clips classified correctly (NaN without clips)."""
        totals = self.confusion.sum(1)
        return {s: float(self.confusion[i, i] / totals[i]) if totals[i] else float("nan")
                for i, s in enumerate(self.styles)}


class StyleClassifier:
    """Style classifier of one primitive's clips (see the module doc).

    Args:
        components: PCA dimensions (the feature space).
        C: inverse L2 regularization strength of the logistic regression.
        seed: seeds the PCA solver and the regression.
    """

    def __init__(self, components: int = 32, C: float = 1.0, seed: int = 0):
        if components < 1 or not C > 0:
            raise ValueError(f"need components ≥ 1 and C > 0, got {components} and {C}")
        self.components, self.C, self.seed = int(components), float(C), int(seed)
        self.styles: list[str] = []
        self.length: int | None = None

    def fit(self, normalized_frames: np.ndarray, duration_s: np.ndarray, styles: Sequence[str]) -> StyleClassifier:
        """Fit on real clips: ``(n, length, 66)`` frames, ``(n,)`` durations, ``n`` style labels."""
        x = clip_descriptors(normalized_frames, duration_s)
        labels = np.asarray(list(styles))
        if len(labels) != len(x):
            raise ValueError(f"{len(x)} clips but {len(labels)} labels")
        self.styles = sorted(set(labels.tolist()))
        if len(self.styles) < 2:
            raise ValueError(f"a style classifier needs clips of at least 2 styles, got {self.styles}")
        components = min(self.components, x.shape[0] - 1, x.shape[1])
        self.length = int(np.asarray(normalized_frames).shape[1])
        self.scaler = StandardScaler().fit(x)
        self.pca = PCA(components, random_state=self.seed).fit(self.scaler.transform(x))
        self.regression = LogisticRegression(C=self.C, max_iter=5000, random_state=self.seed)
        self.regression.fit(self.pca.transform(self.scaler.transform(x)), labels)
        return self

    def features(self, normalized_frames: np.ndarray, duration_s: np.ndarray) -> np.ndarray:
        """``(n, components)`` feature-space coordinates of clips (see the module doc)."""
        if self.length is None:
            raise RuntimeError("fit the classifier first")
        frames = np.asarray(normalized_frames)
        if frames.ndim != 3 or frames.shape[1] != self.length:
            raise ValueError(f"the classifier was fitted on clips of {self.length} frames; got {frames.shape}")
        return self.pca.transform(self.scaler.transform(clip_descriptors(frames, duration_s)))

    def predict_features(self, features: np.ndarray) -> np.ndarray:
        """Style labels ``(n,)`` of feature-space points."""
        return self.regression.predict(features)

    def predict(self, normalized_frames: np.ndarray, duration_s: np.ndarray) -> np.ndarray:
        """Style labels ``(n,)`` of clips."""
        return self.predict_features(self.features(normalized_frames, duration_s))

    def evaluate(self, normalized_frames: np.ndarray, duration_s: np.ndarray,
                 styles: Sequence[str]) -> ClassifierReport:
        """Accuracy and confusion matrix on labelled clips (e.g. real held-out clips)."""
        truth = np.asarray(list(styles))
        predicted = self.predict(normalized_frames, duration_s)
        return ClassifierReport(self.styles, float((predicted == truth).mean()) if len(truth) else float("nan"),
                                confusion(truth, predicted, self.styles), len(truth))


def confusion(truth: Sequence[str], predicted: Sequence[str], styles: Sequence[str]) -> np.ndarray:
    """``(len(styles), len(styles))`` int counts, rows = true, columns = predicted."""
    index = {s: i for i, s in enumerate(styles)}
    out = np.zeros((len(styles), len(styles)), dtype=np.int64)
    for t, p in zip(truth, predicted):
        out[index[t], index[p]] += 1
    return out


def predicted_shares(predicted: Sequence[str], styles: Sequence[str]) -> dict[str, float]:
    """Share of predictions per style (sums to 1 over ``styles``)."""
    predicted = np.asarray(list(predicted))
    n = max(len(predicted), 1)
    return {s: float((predicted == s).sum() / n) for s in styles}
