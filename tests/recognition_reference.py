"""An independent reference for the style classifier's verdict on samples: the share recomputed by hand with
scikit-learn (descriptors built here from the clips' frames, not through :mod:`stylemotion.evaluation`), for the
tests that check a recognition figure (the evaluation's, the leave-one-style-out's)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import torch
from sklearn.decomposition import PCA
from sklearn.linear_model import LogisticRegression
from sklearn.preprocessing import StandardScaler

from stylemotion.primitives.segmentation import time_normalize


def descriptors(frames: np.ndarray, duration_s: np.ndarray) -> np.ndarray:
    """``(n, length · 66 + 1)``: frames ``(n, length, 66)`` on the canonical timeline flattened, then log duration."""
    frames = np.asarray(frames, dtype=np.float64)
    return np.concatenate([frames.reshape(len(frames), -1), np.log(np.asarray(duration_s, dtype=np.float64))[:, None]],
                          axis=1)


def hand_share(train_clips: Sequence, length: int, frames: np.ndarray, duration_s: np.ndarray, style: str,
               components: int, C: float, seed: int) -> float:
    """Share of motions (``frames`` ``(n, length, 66)``, durations ``(n,)`` s) that a z-score → PCA → logistic
    regression classifier fitted on ``train_clips`` (resampled to ``length`` frames) labels ``style``."""
    x = descriptors(np.stack([time_normalize(c.frames, length) for c in train_clips]),
                    np.array([c.duration_s for c in train_clips]))
    labels = np.array([c.style for c in train_clips])
    scaler = StandardScaler().fit(x)
    pca = PCA(min(components, x.shape[0] - 1, x.shape[1]), random_state=seed).fit(scaler.transform(x))
    regression = LogisticRegression(C=C, max_iter=5000, random_state=seed).fit(pca.transform(scaler.transform(x)),
                                                                               labels)
    predicted = regression.predict(pca.transform(scaler.transform(descriptors(frames, duration_s))))
    return float((predicted == style).mean())


def example_gram(judge, data, model) -> torch.Tensor:
    """Table 5.1's column of a style model, by hand: the mean of ``F Fᵀ / T`` over the judge autoencoder's features
    ``F`` of the model's example clip(s) (found in ``data``, a :class:`~stylemotion.evaluation.reference.
    PrimitiveData`), resampled to the length the model recorded for them. The column is this plain Gram whatever
    the model's own style term saw (e.g. the pose-only Gram of the commands' default)."""
    clips = [data.find_example(record) for record in model.examples]
    grams = []
    for clip, record in zip(clips, model.examples):
        frames = time_normalize(clip.frames, int(record.get("encoded_frames") or model.timeline_frames))
        with torch.no_grad():
            features = judge.encode(torch.from_numpy(np.asarray(frames))[None].float())[0]
        grams.append(features @ features.T / features.shape[-1])
    return torch.stack(grams).mean(0)
