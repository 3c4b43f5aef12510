"""A second layer over the template annotation: classes that differ by how the body turns (Krüger §3.3's idea of
a coarse layer refined into sub-classes, with the turning rate as the refining measure).

Relational features see the pose, not where the body heads: a straight walk and a walk turning left fill
nearly the same boolean features, so their templates match each other (walk-turn-left's template inside walk's
at a masked cost of 0.02 on Bandai) and a 2-s walk of another capture comes out as ``walk-turn-left``. The
turning rate separates them: Bandai's straight walks turn within ±0.05 rad/s, its turning walks 0.25–0.45
rad/s.

* **Families** (:func:`template_families`): classes whose templates match each other within ``τ`` (the annotation's
  own threshold: classes it cannot tell apart), joined transitively. Each template is matched, as a whole, inside
  the other's rounded features by the annotation's subsequence DTW.
* **Turning statistics** (:func:`turning_statistics`): per class, the mean and sd of the turning rate of its
  train takes (rad/s, the slope of the heading; left positive), stored with the templates (``model.json``'s
  ``turning``).
* **Refinement** (:func:`refine_by_turning`): each labelled run whose class has family members is cut into pieces
  of about ``window`` frames (equal parts; the whole run when ``window`` is 0 — a run may hold several motions
  of one family, a straight walk and a turn). Only family members that turn unlike the class compete: those
  whose mean rate lies at least ``z`` times the sum of the two sds from the class's (walk and walk-turn-left, not
  raise-up-left-hand and wave-left-hand, which both stand still). A piece moves to the competitor whose mean
  rate is nearest its own rate, if nearer than its class's mean (the boundary between a straight walk and a turn
  is half way between their mean rates); among competitors that turn alike, the one whose template matched the
  piece best (the least ``Δ`` ending in it).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np

from stylemotion.annotate.annotation import Annotation, ClassDistances
from stylemotion.annotate.subsequence import subsequence_dtw
from stylemotion.annotate.templates import MotionTemplate, local_cost
from stylemotion.representation import facing_yaw

#: The least sd a class's turning rate is given (rad/s), so a class whose takes all walk straight does not
#: refuse every run that turns a little.
MIN_SD = 0.02


def document_yaw(positions: np.ndarray, fps: float) -> np.ndarray:
    """``(frames,)`` the unwrapped facing (rad) of ``(frames, 21, 3)`` positions."""
    return np.unwrap(facing_yaw(np.asarray(positions, dtype=np.float64)[None], fps)[0])


def yaw_rate(yaw: np.ndarray, fps: float) -> float:
    """The least-squares slope (rad/s) of an unwrapped heading ``(frames,)``; 0 for fewer than two frames. A slope
    over every frame, not the end points: the facing's smoothing bends the first and last few frames."""
    yaw = np.asarray(yaw, dtype=np.float64)
    if len(yaw) < 2:
        return 0.0
    t = np.arange(len(yaw)) - (len(yaw) - 1) / 2.0
    return float((t @ (yaw - yaw.mean())) / (t @ t) * fps)


def turning_rate(positions: np.ndarray, fps: float) -> float:
    """Heading change per second (rad/s; positive: from +Z towards +X, the body's left, as Bandai's
    ``walk-turn-left`` takes turn) of ``(frames, 21, 3)`` positions: :func:`yaw_rate` of the body's smoothed facing
    (:func:`stylemotion.representation.facing_yaw`)."""
    positions = np.asarray(positions, dtype=np.float64)
    if len(positions) < 2:
        return 0.0
    return yaw_rate(document_yaw(positions, fps), fps)


def turning_statistics(takes_by_class: Mapping[str, Sequence[np.ndarray]], fps: float
                       ) -> dict[str, dict[str, float]]:
    """``{class: {"mean", "sd", "takes"}}`` of the turning rates of each class's ``(frames, 21, 3)`` takes (sd at
    least :data:`MIN_SD`)."""
    out = {}
    for label, takes in takes_by_class.items():
        rates = np.array([turning_rate(t, fps) for t in takes])
        if rates.size:
            out[label] = {"mean": float(rates.mean()), "sd": float(max(rates.std(), MIN_SD)), "takes": int(rates.size)}
    return out


def template_families(templates: Sequence[MotionTemplate], tau: float) -> dict[str, set[str]]:
    """Class → the other classes of its family (module doc): ``a`` and ``b`` are linked when either's template,
    matched as a whole inside the other's features rounded to booleans, costs less than ``tau``."""
    labels = [t.label for t in templates]
    parent = {label: label for label in labels}

    def root(x: str) -> str:
        while parent[x] != x:
            x = parent[x]
        return x

    for a in templates:
        for b in templates:
            if a is b or b.num_frames < (a.num_frames + 1) // 2:
                continue
            delta, _ = subsequence_dtw(local_cost(a, b.values > 0.5))
            if float(np.min(delta)) < tau:
                parent[root(a.label)] = root(b.label)
    return {label: {other for other in labels if other != label and root(other) == root(label)} for label in labels}


def _apart(a: Mapping[str, float], b: Mapping[str, float], z: float) -> bool:
    """Whether two classes' turning rates are told apart: means at least ``z`` × (sd_a + sd_b) apart."""
    return abs(a["mean"] - b["mean"]) >= z * (a["sd"] + b["sd"])


def refine_by_turning(labels: np.ndarray, classes: Sequence[str], delta: np.ndarray, yaw: np.ndarray, fps: float,
                      statistics: Mapping[str, Mapping[str, float]], families: Mapping[str, set[str]],
                      z: float, window: int = 0) -> np.ndarray:
    """``labels`` ``(frames,)`` (indices into ``classes``, -1 = none) with each run relabelled by its turning rate
    (module doc); a copy.

    Args:
        delta: ``(classes, frames)`` each class's subsequence DTW cost ending at each frame.
        yaw: ``(frames,)`` the document's unwrapped facing (rad).
        statistics: :func:`turning_statistics`; a class without an entry is never relabelled nor chosen.
        families: :func:`template_families`.
        z: how far apart (in sums of sd) two classes' mean rates must be for the layer to choose between them.
        window: frames per piece a run is decided in (about; 0: the whole run).
    """
    out = np.array(labels, dtype=np.int64)
    index = {c: i for i, c in enumerate(classes)}
    edges = np.flatnonzero(np.diff(np.r_[-2, out, -2]) != 0)
    for start, stop in zip(edges[:-1], edges[1:]):
        label = int(labels[start])
        if label < 0 or stop - start < 2 or classes[label] not in statistics:
            continue
        own = statistics[classes[label]]
        rivals = [m for m in families.get(classes[label], ()) if m in statistics and m in index
                  and _apart(own, statistics[m], z)]
        if not rivals:
            continue
        pieces = max(1, int(round((stop - start) / window))) if window > 0 else 1
        bounds = np.linspace(start, stop, pieces + 1).round().astype(int)
        for a, b in zip(bounds[:-1], bounds[1:]):
            if b - a < 2:
                continue
            rate = yaw_rate(yaw[a:b], fps)
            nearest = min(rivals, key=lambda m: abs(rate - statistics[m]["mean"]))
            if abs(rate - statistics[nearest]["mean"]) >= abs(rate - own["mean"]):
                continue
            alike = [m for m in rivals if not _apart(statistics[m], statistics[nearest], z)]
            best = min(alike, key=lambda m: float(np.min(delta[index[m], a:b])))
            out[a:b] = index[best]
    return out


def refine_annotation(annotation: Annotation, distances: ClassDistances, positions: np.ndarray, fps: float,
                      templates: Sequence[MotionTemplate], statistics: Mapping[str, Mapping[str, float]] | None,
                      tau: float, z: float, window_s: float = 0.0) -> Annotation:
    """``annotation`` after the turning layer (:func:`refine_by_turning`, families at ``tau``, pieces of
    ``window_s`` seconds); itself when ``z`` ≤ 0 or the model has no turning statistics (a templates folder
    written before this layer)."""
    if z <= 0 or not statistics:
        return annotation
    labels = refine_by_turning(annotation.labels, distances.classes, distances.delta, document_yaw(positions, fps),
                               fps, statistics, template_families(templates, tau), z,
                               int(round(window_s * fps)))
    return replace(annotation, labels=labels)
