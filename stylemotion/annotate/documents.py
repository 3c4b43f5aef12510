"""Evaluation documents: labelled takes joined by short blends into one long motion (Krüger §3.2.3's set-up).

Takes are joined in the placement-free 66-dim frame representation (:mod:`stylemotion.representation`) and
integrated once, so the root path is continuous. Between two takes ``blend_frames`` frames cross-fade from the
last frame of one to the first of the next (weights :func:`stylemotion.synthesis.stitching.blend_weights`);
they belong to no class and are labelled ``""``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from stylemotion.representation import frames_to_positions, positions_to_frames
from stylemotion.synthesis.stitching import blend_weights


@dataclass(frozen=True)
class Document:
    """A labelled document: ``positions`` ``(frames, 21, 3)`` metres; ``labels`` per frame (``""`` = blend);
    ``parts``: ``(take name, content, style, start, end_exclusive)`` of each take in it."""

    positions: np.ndarray
    fps: float
    labels: tuple[str, ...]
    parts: tuple[tuple[str, str, str, int, int], ...]


def join_takes(takes: Sequence[tuple[str, str, str, np.ndarray]], fps: float, blend_frames: int = 8) -> Document:
    """One document from ``(name, content, style, positions (frames, 21, 3))`` takes, in order."""
    if not takes:
        raise ValueError("a document needs at least one take")
    pieces: list[np.ndarray] = []
    labels: list[str] = []
    parts = []
    fade = blend_weights(blend_frames + 2)[1:-1] if blend_frames else np.zeros(0)   # strictly between 1 and 0
    for name, content, style, positions in takes:
        frames = positions_to_frames(np.asarray(positions, dtype=np.float64), fps)[0]
        if pieces and blend_frames:
            a, b = pieces[-1][-1], frames[0]
            pieces.append(fade[:, None] * a + (1.0 - fade[:, None]) * b)
            labels.extend([""] * blend_frames)
        start = len(labels)
        pieces.append(frames)
        labels.extend([content] * len(frames))
        parts.append((name, content, style, start, len(labels)))
    joined = np.concatenate(pieces)
    return Document(np.asarray(frames_to_positions(joined, fps), dtype=np.float32), fps, tuple(labels),
                    tuple(parts))


def random_document(pool: Sequence[tuple[str, str, str, np.ndarray]], fps: float, seconds: float,
                    rng: np.random.Generator, blend_frames: int = 8) -> Document:
    """Takes drawn at random (content first, uniformly, then a take of it) until ``seconds`` are reached."""
    by_content: dict[str, list[int]] = {}
    for i, take in enumerate(pool):
        by_content.setdefault(take[1], []).append(i)
    contents = sorted(by_content)
    chosen, total = [], 0
    while total < seconds * fps:
        content = contents[int(rng.integers(len(contents)))]
        take = pool[by_content[content][int(rng.integers(len(by_content[content])))]]
        chosen.append(take)
        total += take[3].shape[0] + blend_frames
    return join_takes(chosen, fps, blend_frames)


def partition_documents(pool: Sequence[tuple[str, str, str, np.ndarray]], fps: float, seconds: float,
                        rng: np.random.Generator, blend_frames: int = 8) -> list[Document]:
    """Every take of ``pool`` exactly once, in an order drawn with ``rng``, cut into documents of at least
    ``seconds`` (takes are added until a document is that long; a shorter remainder joins the last one)."""
    if not pool:
        raise ValueError("no takes to build documents from")
    order = rng.permutation(len(pool))
    groups: list[list[tuple[str, str, str, np.ndarray]]] = [[]]
    total = 0
    for i in order:
        if total >= seconds * fps:
            groups.append([])
            total = 0
        groups[-1].append(pool[int(i)])
        total += pool[int(i)][3].shape[0] + blend_frames
    if len(groups) > 1 and total < seconds * fps:
        groups[-2].extend(groups.pop())
    return [join_takes(group, fps, blend_frames) for group in groups]


def part_scores(document: Document, predicted: Sequence[str]) -> list[dict[str, float | str]]:
    """Per take of ``document``: ``recall`` (fraction of its frames labelled with its content) and
    ``precision`` (fraction of its labelled frames that carry its content; 0 where none is labelled)."""
    labels = np.asarray(list(predicted), dtype=object)
    if labels.shape[0] != len(document.labels):
        raise ValueError(f"{labels.shape[0]} predicted labels for a document of {len(document.labels)} frames")
    out = []
    for name, content, _style, start, end in document.parts:
        span = labels[start:end]
        right, labelled = int((span == content).sum()), int((span != "").sum())
        out.append({"take": name, "content": content, "recall": right / max(end - start, 1),
                    "precision": right / labelled if labelled else 0.0})
    return out
