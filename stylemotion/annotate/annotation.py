"""Annotation of a document by class motion templates (Krüger §3.2.2; Müller, Baak & Seidel 2009).

For each class ``p`` the subsequence DTW cost ``Δ_p(ℓ)`` of its template against the document's features
(:mod:`stylemotion.annotate.subsequence`) is turned into a frame-wise ``Δ̄_p^τ`` iteratively: take the
smallest ``Δ_p(ℓ*) < τ``, mark its segment ``[start(ℓ*), ℓ*]`` (the frames not yet marked get the value
``Δ_p(ℓ*)``), forbid every later hit whose segment overlaps a marked one, repeat until no value is below ``τ``.
Each frame then gets the class of the smallest ``Δ̄_p^τ`` (eqs. 3.1–3.2), or none where all are ``inf``.

Beyond the thesis, labelled runs shorter than ``min_run`` frames are left unlabelled afterwards.

Sub-templates (§3.3's ``M_p``): with ``sub_frames`` > 0 each class template is cut into windows of that many frames
(:func:`~.templates.sub_templates`, half overlapping) and ``Δ_p(ℓ)`` is the least over the class's windows of their
subsequence DTW costs, with that window's start. A document part shorter than half a whole template (a 2-s walk
against a 7-s walk template) can then still be matched, and one window of a class's cycle stands for the class.

Key-frame preselection: a class's key frames are a few columns of its quantized template (spread over its
length, each the column with most consistent entries in its neighbourhood). A hit survives only when the
document has frames matching its key frames (at most ``keyframe_tolerance`` of their consistent entries
contradicted) in the right order inside the hit's segment.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from stylemotion.annotate.feature_sets import FeatureSetError, same_feature_set
from stylemotion.annotate.settings import AnnotateSettings, KeyframeSettings
from stylemotion.annotate.subsequence import subsequence_dtw
from stylemotion.annotate.templates import MotionTemplate, local_cost, sub_templates
from stylemotion.io.errors import UserInputError

#: Matching threshold τ: ``stylemotion-annotate``'s ``tau`` (:class:`AnnotateSettings`, where it is set and why).
DEFAULT_TAU: float = AnnotateSettings.tau


class AnnotationInputError(UserInputError, ValueError):
    """A document or template set the annotation cannot use; the message names the value."""


@dataclass(frozen=True)
class Hit:
    """A document segment matched by a class: frames ``start``–``end`` (inclusive), cost ``Δ_p(end)``."""

    label: str
    start: int
    end: int
    cost: float

    def record(self) -> dict[str, object]:
        return {"label": self.label, "start": self.start, "end": self.end, "cost": round(self.cost, 5)}


@dataclass(frozen=True)
class Annotation:
    """Frame labels and the hits they came from.

    Attributes:
        labels: ``(frames,)`` int, index into ``classes`` or -1 for none.
        distance: ``(frames,)`` ``Δ^min``, ``inf`` where unlabelled.
        classes: class names.
        hits: the accepted hits of every class, by start frame.
    """

    labels: np.ndarray
    distance: np.ndarray
    classes: tuple[str, ...]
    hits: tuple[Hit, ...]

    def label_names(self) -> list[str]:
        """Per frame the class name, ``""`` where none."""
        return ["" if i < 0 else self.classes[i] for i in self.labels]


def keyframe_columns(template: MotionTemplate, count: int = 3) -> np.ndarray:
    """Indices of ``count`` key frames of a template: in each of ``count`` equal parts of its length, the
    column with the most consistent entries (the first such)."""
    consistent = template.mask.sum(1)
    edges = np.linspace(0, template.num_frames, count + 1).round().astype(int)
    return np.array([a + int(np.argmax(consistent[a:b])) for a, b in zip(edges[:-1], edges[1:]) if b > a])


def keyframe_matches(template: MotionTemplate, document: np.ndarray, keys: np.ndarray,
                     tolerance: float) -> np.ndarray:
    """``(keys, frames)`` bool: document frame matches key frame (≤ ``tolerance`` of its consistent entries
    contradicted)."""
    key_template = MotionTemplate(template.label, template.values[keys], template.examples, template.delta,
                                  template.feature_set)
    return local_cost(key_template, document) <= tolerance


def keys_in_order(matches: np.ndarray, start: np.ndarray) -> np.ndarray:
    """``(frames,)`` bool: for the segment ``[start[e], e]`` ending at each frame ``e``, whether every key frame
    has a matching frame in it, each no earlier than the previous key's (``start`` -1: no segment)."""
    keys, n = matches.shape
    big = n                                                       # "no match at or after t"
    t = np.where(start >= 0, start, big).astype(np.int64)
    for row in matches:
        nxt = np.full(n + 1, big, dtype=np.int64)                 # first matching frame ≥ t
        idx = np.flatnonzero(row)
        pos = np.searchsorted(idx, np.arange(n))
        nxt[:n] = np.where(pos < idx.size, idx[np.minimum(pos, max(idx.size - 1, 0))] if idx.size else big, big)
        t = nxt[np.minimum(t, n)]
    return t <= np.arange(n)


def class_hits(delta: np.ndarray, start: np.ndarray, tau: float, label: str,
               keep: np.ndarray | None = None) -> tuple[list[Hit], np.ndarray]:
    """Iterative hits of one class and its frame-wise ``Δ̄^τ`` ``(frames,)`` (see the module docstring).

    Args:
        delta, start: ``Δ_p`` and its start frames, ``(frames,)``.
        keep: optional ``(frames,)`` bool, whether a hit ending at that frame passes preselection; hits
            failing it are dropped without marking frames.
    """
    n = delta.shape[0]
    bar = np.full(n, np.inf)
    covered = np.zeros(n, dtype=bool)
    hits: list[Hit] = []
    order = np.argsort(delta, kind="stable")
    for end in order:
        cost = float(delta[end])
        if not cost < tau:
            break
        a = int(start[end])
        if a < 0:
            continue
        if covered[a:end + 1].any():
            continue
        if keep is not None and not keep[end]:
            continue
        hits.append(Hit(label, a, int(end), cost))
        bar[a:end + 1] = np.minimum(bar[a:end + 1], cost)
        covered[a:end + 1] = True
    return hits, bar


@dataclass(frozen=True)
class AnnotationSettings:
    """``tau``: matching threshold; ``keyframes``: use key-frame preselection; ``keyframe_count`` key frames
    per class; ``keyframe_tolerance``: fraction of a key frame's consistent entries a matching frame may
    contradict; ``min_run``: shortest labelled run kept, frames (shorter slivers, where one class's hit
    overlays another's, are left unlabelled; 30 = 1 s at 30 fps; 0 disables it).

    ``sub_frames``: frames of the sub-templates cut from each class template (module doc; 0: whole templates).
    ``turning_z``: how far apart two classes' turning rates must be for the turning layer to choose between them
    (:mod:`.turning`; 0: off); ``turning_window_s``: the
    seconds of the pieces it decides runs in (0: whole runs).

    ``tau``, ``keyframes``, ``keyframe_tolerance``, ``min_run`` and ``sub_frames`` were chosen on documents of
    Bandai val takes (suite ``annotate``); ``keyframe_count`` is not tuned. The defaults are
    ``stylemotion-annotate``'s (:class:`AnnotateSettings`)."""

    tau: float = DEFAULT_TAU
    keyframes: bool = KeyframeSettings.use
    keyframe_count: int = KeyframeSettings.count
    keyframe_tolerance: float = KeyframeSettings.tolerance
    min_run: int = AnnotateSettings.min_run
    sub_frames: int = AnnotateSettings.sub_frames
    turning_z: float = AnnotateSettings.turning_z
    turning_window_s: float = AnnotateSettings.turning_window_s


@dataclass(frozen=True)
class ClassDistances:
    """``Δ_p`` and its starts for every class of a document, computed once and re-thresholded cheaply."""

    classes: tuple[str, ...]
    delta: np.ndarray          # (classes, frames)
    start: np.ndarray          # (classes, frames)
    keep: np.ndarray           # (classes, frames) bool: the hit ending there passes key-frame preselection


def class_distances(document: np.ndarray, templates: Sequence[MotionTemplate],
                    settings: AnnotationSettings | None = None) -> ClassDistances:
    """Subsequence-DTW distance functions of every template over a document's ``(frames, features)`` features.

    Raises:
        AnnotationInputError: no template, feature counts that differ, or a document shorter than the
            shortest template's minimum match (half its length).
    """
    settings = settings or AnnotationSettings()
    doc = np.asarray(document)
    if not templates:
        raise AnnotationInputError("no class templates to annotate with")
    try:
        same_feature_set((t.feature_set for t in templates), "the templates")
    except FeatureSetError as exc:
        raise AnnotationInputError(str(exc)) from None
    if doc.ndim != 2 or any(t.values.shape[1] != doc.shape[1] for t in templates):
        raise AnnotationInputError(f"document features {doc.shape} do not fit the templates' "
                                   f"{sorted({t.values.shape[1] for t in templates})} features")
    if settings.sub_frames < 0:
        raise AnnotationInputError(f"sub_frames={settings.sub_frames} must be ≥ 0 (0: whole templates)")
    windows = [sub_templates(t, settings.sub_frames) for t in templates]
    shortest = min((w for ws in windows for w in ws), key=lambda t: t.num_frames)
    if doc.shape[0] < (shortest.num_frames + 1) // 2:
        raise AnnotationInputError(f"the document has {doc.shape[0]} frames, shorter than any template can match "
                                   f"(the shortest, {shortest.label!r}, has {shortest.num_frames} frames and needs "
                                   f"≥ {(shortest.num_frames + 1) // 2})")
    deltas, starts, keeps = [], [], []
    for parts in windows:
        best_d = np.full(doc.shape[0], np.inf)
        best_s = np.full(doc.shape[0], -1, dtype=np.int64)
        best_keep = np.ones(doc.shape[0], dtype=bool)
        for template in parts:
            d, s = subsequence_dtw(local_cost(template, doc))
            keep = np.ones(doc.shape[0], dtype=bool)
            if settings.keyframes:
                keys = keyframe_columns(template, settings.keyframe_count)
                matches = keyframe_matches(template, doc, keys, settings.keyframe_tolerance)
                keep = keys_in_order(matches, s) & np.isfinite(d)
            better = d < best_d
            best_d, best_s, best_keep = (np.where(better, d, best_d), np.where(better, s, best_s),
                                         np.where(better, keep, best_keep))
        deltas.append(best_d)
        starts.append(best_s)
        keeps.append(best_keep)
    return ClassDistances(tuple(t.label for t in templates), np.stack(deltas), np.stack(starts), np.stack(keeps))


def annotate_distances(distances: ClassDistances, tau: float, keyframes: bool, min_run: int = 0) -> Annotation:
    """Frame labels from precomputed class distances at threshold ``tau`` (eqs. 3.1–3.2); runs of one label
    shorter than ``min_run`` frames are then left unlabelled (0: the thesis' procedure as is)."""
    bars, hits = [], []
    for p, label in enumerate(distances.classes):
        h, bar = class_hits(distances.delta[p], distances.start[p], tau, label,
                            distances.keep[p] if keyframes else None)
        bars.append(bar)
        hits.extend(h)
    bar = np.stack(bars)
    best = np.argmin(bar, axis=0)
    minimum = bar[best, np.arange(bar.shape[1])]
    labels = drop_short_runs(np.where(np.isfinite(minimum), best, -1), min_run)
    minimum = np.where(labels >= 0, minimum, np.inf)
    return Annotation(labels, minimum, distances.classes, tuple(sorted(hits, key=lambda h: (h.start, h.label))))


def drop_short_runs(labels: np.ndarray, min_run: int) -> np.ndarray:
    """``labels`` ``(frames,)`` int (-1 = none) with every labelled run shorter than ``min_run`` frames set to
    -1 (a copy; ``min_run`` ≤ 1 changes nothing)."""
    labels = np.array(labels, dtype=np.int64)
    if min_run > 1 and labels.size:
        edges = np.flatnonzero(np.diff(np.r_[-2, labels, -2]) != 0)
        lengths = np.diff(edges)
        short = (lengths < min_run) & (labels[edges[:-1]] >= 0)
        labels[np.repeat(short, lengths)] = -1
    return labels


def with_keyframes(distances: ClassDistances, document: np.ndarray, templates: Sequence[MotionTemplate],
                   count: int, tolerance: float) -> ClassDistances:
    """``distances`` with the key-frame preselection redone for ``count`` key frames at ``tolerance`` (the
    subsequence DTW is reused; ``document``: the ``(frames, features)`` features it was computed from)."""
    by_label = {t.label: t for t in templates}
    keeps = []
    for p, label in enumerate(distances.classes):
        template = by_label[label]
        matches = keyframe_matches(template, np.asarray(document), keyframe_columns(template, count), tolerance)
        keeps.append(keys_in_order(matches, distances.start[p]) & np.isfinite(distances.delta[p]))
    return ClassDistances(distances.classes, distances.delta, distances.start, np.stack(keeps))


def annotate_features(document: np.ndarray, templates: Sequence[MotionTemplate],
                      settings: AnnotationSettings | None = None) -> Annotation:
    """Annotate a document given as ``(frames, features)`` relational features."""
    settings = settings or AnnotationSettings()
    return annotate_distances(class_distances(document, templates, settings), settings.tau, settings.keyframes,
                              settings.min_run)


def segments(labels: Sequence[str] | np.ndarray) -> list[tuple[int, int, str]]:
    """Maximal runs of one non-empty label: ``(start, end_exclusive, label)``."""
    names = ["" if lab is None else str(lab) for lab in labels]
    if not names:
        return []
    values, codes = np.unique(np.asarray(names, dtype=object), return_inverse=True)
    edges = np.flatnonzero(np.diff(np.r_[-1, codes, -1]) != 0)
    return [(int(a), int(b), str(values[codes[a]])) for a, b in zip(edges[:-1], edges[1:]) if values[codes[a]] != ""]


def frame_scores(truth: Sequence[str], predicted: Sequence[str]) -> dict[str, float | int]:
    """Frame-level precision/recall/F (P1, R1, F1) of labelled frames; ``""`` means unlabelled. Also the
    counts behind the misses: ``unlabelled1`` (frames of a class left without a label), ``confused1`` (given
    another class) and ``spurious1`` (frames of no class, e.g. blends, given one)."""
    t, p = np.asarray(list(truth), dtype=object), np.asarray(list(predicted), dtype=object)
    if t.shape != p.shape:
        raise ValueError(f"truth has {t.shape[0]} frames, prediction {p.shape[0]}")
    relevant, retrieved = t != "", p != ""
    correct = int((relevant & retrieved & (t == p)).sum())
    return {**_prf(correct, int(retrieved.sum()), correct, int(relevant.sum()), "1"),
            "unlabelled1": int((relevant & ~retrieved).sum()),
            "confused1": int((relevant & retrieved & (t != p)).sum()),
            "spurious1": int((~relevant & retrieved).sum())}


def segment_scores(truth: Sequence[str], predicted: Sequence[str]) -> dict[str, float | int]:
    """Segment-level P2/R2/F2: a segment counts when it overlaps a segment of the other side with its label."""
    ts, ps = segments(truth), segments(predicted)

    def overlaps(seg: tuple[int, int, str], others: list[tuple[int, int, str]]) -> bool:
        return any(o[2] == seg[2] and o[0] < seg[1] and seg[0] < o[1] for o in others)

    good_p = sum(overlaps(s, ts) for s in ps)
    good_t = sum(overlaps(s, ps) for s in ts)
    return _prf(good_p, len(ps), good_t, len(ts), "2")


def _prf(hit_p: int, n_p: int, hit_r: int, n_r: int, suffix: str) -> dict[str, float | int]:
    precision = hit_p / n_p if n_p else 0.0
    recall = hit_r / n_r if n_r else 0.0
    f = 2 * precision * recall / (precision + recall) if precision + recall else 0.0
    return {f"P{suffix}": precision, f"R{suffix}": recall, f"F{suffix}": f, f"retrieved{suffix}": n_p,
            f"relevant{suffix}": n_r}


