"""A second layer over the template annotation: classes that differ by how the body turns or how fast it travels
(Krüger §3.3's idea of a coarse layer refined into sub-classes, with the turning rate and the ground speed as the
refining measures).

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
* **Ground speed**: the same for the root's ground speed (m/s; ``model.json``'s ``speed``): a walk whose template
  matched a run's (walk and run match each other at τ = 0.08 on Bandai) is told from it by its speed, in a pass
  before the turning rate's (:func:`refine_labels`).
* **Refinement** (:func:`refine_by_rate`; :func:`refine_by_turning`, :func:`refine_by_speed`): each labelled run
  whose class has family members is cut into pieces of about ``window`` frames (equal parts; the whole run when
  ``window`` is 0 — a run may hold several motions of one family, a straight walk and a turn). Only family members
  whose rate differs from the class's compete: those whose mean rate lies at least ``z`` times the sum of the two
  sds from the class's (walk and walk-turn-left, not raise-up-left-hand and wave-left-hand, which both stand
  still). A piece moves to the competitor whose mean rate is nearest its own rate, if nearer than its class's mean
  (the boundary between a straight walk and a turn is half way between their mean rates); among competitors whose
  rates are alike, the one whose template matched the piece best (the least ``Δ`` ending in it).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import replace

import numpy as np

from stylemotion.annotate.annotation import Annotation, ClassDistances
from stylemotion.annotate.subsequence import subsequence_dtw
from stylemotion.annotate.templates import MotionTemplate, local_cost
from stylemotion.representation import facing_yaw

#: The least sd a class's turning rate is given (rad/s), so a class whose takes all walk straight does not
#: refuse every run that turns a little.
MIN_SD = 0.02
#: The least sd of a class's ground speed (m/s).
MIN_SPEED_SD = 0.05


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


def ground_speed(track: np.ndarray, fps: float) -> float:
    """Mean ground speed (m/s) of a root track ``(frames, 2)`` (x, z metres): its length over its duration; 0 for
    fewer than two frames."""
    track = np.asarray(track, dtype=np.float64)
    if len(track) < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(track, axis=0), axis=-1).sum() * fps / (len(track) - 1))


def root_track(positions: np.ndarray) -> np.ndarray:
    """``(frames, 2)`` the root's ground track (x, z metres) of ``(frames, 21, 3)`` positions."""
    return np.asarray(positions, dtype=np.float64)[:, 0, [0, 2]]


def _statistics(rates_by_class: Mapping[str, Sequence[float]], least_sd: float) -> dict[str, dict[str, float]]:
    out = {}
    for label, rates in rates_by_class.items():
        rates = np.asarray(rates, dtype=np.float64)
        if rates.size:
            out[label] = {"mean": float(rates.mean()), "sd": float(max(rates.std(), least_sd)),
                          "takes": int(rates.size)}
    return out


def turning_statistics(takes_by_class: Mapping[str, Sequence[np.ndarray]], fps: float
                       ) -> dict[str, dict[str, float]]:
    """``{class: {"mean", "sd", "takes"}}`` of the turning rates of each class's ``(frames, 21, 3)`` takes (sd at
    least :data:`MIN_SD`)."""
    return _statistics({c: [turning_rate(t, fps) for t in takes] for c, takes in takes_by_class.items()}, MIN_SD)


def speed_statistics(takes_by_class: Mapping[str, Sequence[np.ndarray]], fps: float
                     ) -> dict[str, dict[str, float]]:
    """The same for the takes' ground speeds (m/s; sd at least :data:`MIN_SPEED_SD`)."""
    return _statistics({c: [ground_speed(root_track(t), fps) for t in takes] for c, takes in takes_by_class.items()},
                       MIN_SPEED_SD)


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


def refine_by_rate(labels: np.ndarray, classes: Sequence[str], delta: np.ndarray, rate_of: Callable[[int, int], float],
                   statistics: Mapping[str, Mapping[str, float]], families: Mapping[str, set[str]],
                   z: float, window: int = 0, tie: Callable[[str, int, int], float] | None = None) -> np.ndarray:
    """``labels`` ``(frames,)`` (indices into ``classes``, -1 = none) with each run (or piece of about ``window``
    frames) relabelled by a rate of the body's motion (module doc); a copy. ``tie(class, first, stop)``: how badly
    a class fits the stretch by another measure, which decides first among rivals alike in this one (then the
    template's ``Δ``).

    Args:
        delta: ``(classes, frames)`` each class's subsequence DTW cost ending at each frame.
        rate_of: ``(first, stop)`` frames → the rate of that stretch (e.g. its turning rate).
        statistics: each class's ``mean`` and ``sd`` of the rate; a class without an entry is never relabelled nor
            chosen.
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
            rate = rate_of(int(a), int(b))
            nearest = min(rivals, key=lambda m: abs(rate - statistics[m]["mean"]))
            if abs(rate - statistics[nearest]["mean"]) >= abs(rate - own["mean"]):
                continue
            alike = [m for m in rivals if not _apart(statistics[m], statistics[nearest], z)]
            best = min(alike, key=lambda m: (tie(m, a, b) if tie else 0.0, float(np.min(delta[index[m], a:b]))))
            out[a:b] = index[best]
    return out


def refine_by_turning(labels: np.ndarray, classes: Sequence[str], delta: np.ndarray, yaw: np.ndarray, fps: float,
                      statistics: Mapping[str, Mapping[str, float]], families: Mapping[str, set[str]],
                      z: float, window: int = 0, tie: Callable[[str, int, int], float] | None = None) -> np.ndarray:
    """:func:`refine_by_rate` with the turning rate of the document's unwrapped facing ``yaw`` ``(frames,)``."""
    return refine_by_rate(labels, classes, delta, lambda a, b: yaw_rate(yaw[a:b], fps), statistics, families, z,
                          window, tie)


def refine_by_speed(labels: np.ndarray, classes: Sequence[str], delta: np.ndarray, track: np.ndarray, fps: float,
                    statistics: Mapping[str, Mapping[str, float]], families: Mapping[str, set[str]],
                    z: float, window: int = 0, tie: Callable[[str, int, int], float] | None = None) -> np.ndarray:
    """:func:`refine_by_rate` with the ground speed of the root's track ``(frames, 2)`` (x, z metres)."""
    return refine_by_rate(labels, classes, delta, lambda a, b: ground_speed(track[a:b], fps), statistics, families,
                          z, window, tie)


def _misfit(statistics: Mapping[str, Mapping[str, float]] | None, rate_of: Callable[[int, int], float]
            ) -> Callable[[str, int, int], float] | None:
    """How many sd a stretch's rate lies from a class's mean (0 for a class without statistics); None without
    statistics."""
    if not statistics:
        return None

    def misfit(name: str, a: int, b: int) -> float:
        stats = statistics.get(name)
        return 0.0 if stats is None else abs(rate_of(a, b) - stats["mean"]) / stats["sd"]

    return misfit


def refine_labels(labels: np.ndarray, classes: Sequence[str], delta: np.ndarray, yaw: np.ndarray, track: np.ndarray,
                  fps: float, families: Mapping[str, set[str]], turning: Mapping[str, Mapping[str, float]] | None,
                  speed: Mapping[str, Mapping[str, float]] | None, z: float, window: int = 0) -> np.ndarray:
    """The layer's two passes over ``labels``: by ground speed (``track`` ``(frames, 2)``), then by turning rate
    (``yaw`` ``(frames,)``); among rivals alike in one measure, the other decides (a straight 1 m/s walk labelled
    walk-turn-right goes to walk, not to run, which turns as little); a pass without statistics is skipped."""
    def turn(a: int, b: int) -> float:
        return yaw_rate(yaw[a:b], fps)

    def go(a: int, b: int) -> float:
        return ground_speed(track[a:b], fps)

    if speed:
        labels = refine_by_rate(labels, classes, delta, go, speed, families, z, window, _misfit(turning, turn))
    if turning:
        labels = refine_by_rate(labels, classes, delta, turn, turning, families, z, window, _misfit(speed, go))
    return labels


def refine_annotation(annotation: Annotation, distances: ClassDistances, positions: np.ndarray, fps: float,
                      templates: Sequence[MotionTemplate], statistics: Mapping[str, Mapping[str, float]] | None,
                      tau: float, z: float, window_s: float = 0.0,
                      speed: Mapping[str, Mapping[str, float]] | None = None) -> Annotation:
    """``annotation`` after the layer (:func:`refine_labels`, families at ``tau``, pieces of ``window_s`` seconds;
    ``statistics``: the turning rates, ``speed``: the ground speeds); itself when ``z`` ≤ 0 or the model has no
    statistics (a templates folder written before this layer)."""
    if z <= 0 or not (statistics or speed):
        return annotation
    labels = refine_labels(annotation.labels, distances.classes, distances.delta, document_yaw(positions, fps),
                           root_track(positions), fps, template_families(templates, tau), statistics, speed, z,
                           int(round(window_s * fps)))
    return replace(annotation, labels=labels)
