"""What the reconstruction benchmark (suite ``reconstruct``, ``scripts/suites/reconstruct.py``) measures, as
functions a notebook can call: seeded query choice, noisy markers, per-joint error figures with percentiles,
key pairs and their outcome (joined or not), and the choice of a setting on validation scores.

The split itself is :meth:`~stylemotion.datasets.base.TakeSet.split` (train = the database, val = choosing,
test = reporting); :func:`benchmark_split` is the older two-way split that ``scripts/bench_style_transfer.py``
still uses.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from stylemotion.datasets import Take, TakeSet, load_dataset, spread_over_styles
from stylemotion.reconstruct.keyframes import HIPS, DynamicMotionGraph, Keyframe, NoConnectionError
from stylemotion.reconstruct.markers import tracks_from_positions
from stylemotion.search.database import MotionDatabase
from stylemotion.skeleton import CANONICAL_JOINTS


def benchmark_split(data: str, root: str | None = None, seed: int = 0, workers: int = 1,
                    synthetic_takes: int = 1) -> tuple[TakeSet, list[Take], list[Take]]:
    """``(dataset, train takes, test takes)``: ``data="bandai"`` (``root`` or ``$STYLEMOTION_DATA``/
    ``../shared/data``, 10 % test per content and style) or ``"synthetic"`` (``synthetic_takes`` takes per content
    and style, 15 % test per content). No validation part: for choosing settings use ``TakeSet.split``."""
    if data == "synthetic":
        takeset = load_dataset("synthetic", takes_per_pair=synthetic_takes)
        parts = takeset.split(seed, 0.0, 0.15, group_by=("content",))
    elif data == "bandai":
        root = root or os.path.join(os.environ.get("STYLEMOTION_DATA", "../shared/data"), "bandai-namco-motion-2",
                                    "data.zip")
        takeset = load_dataset("bandai", root=root, workers=workers)
        parts = takeset.split(seed, 0.0, 0.1, group_by=("content", "style"))
    else:
        raise ValueError(f"data={data!r}: the benchmarks run on 'bandai' or 'synthetic'")
    return takeset, parts["train"], parts["test"]


def database_of(name: str, takes: Sequence[Take], fps: float) -> MotionDatabase:
    """The motion database of ``takes`` (all at ``fps``)."""
    return MotionDatabase.from_takeset(TakeSet(name, list(takes), fps))


def choose_queries(takes: Sequence[Take], contents: Sequence[str], per_content: int,
                   rng: np.random.Generator) -> list[Take]:
    """``per_content`` takes of each content drawn at random (``rng``), in turn from each style so that the
    queries cover the styles; ValueError naming a content without takes."""
    missing = sorted(set(contents) - {t.content for t in takes})
    if missing:
        raise ValueError(f"no take of content(s) {missing}; the takes' contents: {sorted({t.content for t in takes})}")
    return spread_over_styles(takes, contents, per_content, rng)


def noisy_markers(positions: np.ndarray, joints: Sequence[str], noise_mm: float, rng: np.random.Generator,
                  fps: float = 30.0) -> np.ndarray:
    """The markers ``joints`` of a motion ``(frames, 21, 3)`` m with uniform noise of ± ``noise_mm`` mm (the
    thesis' 1 mm) → ``(frames, markers, 3)`` metres."""
    markers = tracks_from_positions(positions, joints, fps).positions
    return markers + rng.uniform(-1.0, 1.0, markers.shape) * noise_mm / 1000.0


def joint_error_table(positions: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Euclidean error of every joint in every frame, ``(frames, 21)`` cm (``positions``, ``truth``: ``(frames, 21,
    3)`` metres)."""
    return np.linalg.norm(np.asarray(positions, np.float64) - np.asarray(truth, np.float64), axis=-1) * 100.0


def error_figures(errors: np.ndarray | Sequence[np.ndarray]) -> dict[str, Any]:
    """Mean, 95th percentile and maximum (cm) of per-joint errors ``(frames, 21)`` (or a list of such tables,
    pooled), over all joints and frames and per joint name."""
    table = np.concatenate([np.asarray(e, np.float64) for e in errors]) if isinstance(errors, (list, tuple)) \
        else np.asarray(errors, np.float64)
    per_joint = {j: {"mean_cm": float(table[:, i].mean()), "p95_cm": float(np.percentile(table[:, i], 95)),
                     "max_cm": float(table[:, i].max())} for i, j in enumerate(CANONICAL_JOINTS)}
    return {"frames": int(table.shape[0]), "mean_cm": float(table.mean()),
            "p95_cm": float(np.percentile(table, 95)), "max_cm": float(table.max()), "per_joint": per_joint}


def choose_setting(scores: Mapping[Any, float | None]) -> Any:
    """The candidate with the lowest validation score (the first listed on a tie); a None or non-finite score
    never wins; ValueError when no candidate has a score."""
    best, best_score = None, math.inf
    for candidate, score in scores.items():
        if score is not None and math.isfinite(score) and score < best_score:
            best, best_score = candidate, float(score)
    if best is None:
        raise ValueError(f"no candidate of {list(scores)} has a finite validation score")
    return best


def choose_smallest_within(scores: Mapping[float, float | None], tolerance: float) -> float:
    """The smallest candidate whose validation score is at most ``(1 + tolerance)`` × the lowest score: the
    cheapest setting as good as the best up to ``tolerance`` (a fraction, e.g. 0.01), for a setting whose cost grows
    with its value (k neighbours) and whose score flattens. A None or non-finite score never qualifies; ValueError
    when no candidate has a score or ``tolerance`` is negative."""
    if not tolerance >= 0:
        raise ValueError(f"tolerance must be >= 0, got {tolerance}")
    best = choose_setting(scores)
    limit = float(scores[best]) * (1.0 + tolerance)  # type: ignore[arg-type]
    return min(c for c, s in scores.items() if s is not None and math.isfinite(s) and s <= limit)


def key_pairs(positions: np.ndarray, fps: float, spacing_s: float, start_s: float = 0.2,
              ) -> list[tuple[Keyframe, Keyframe]]:
    """Consecutive key pairs of a motion ``(frames, 21, 3)`` m: a key every ``spacing_s`` s from ``start_s`` to its
    end (times relative to the first key); [] when the motion holds no two keys that far apart."""
    positions = np.asarray(positions, dtype=np.float64)
    first, step = int(round(start_s * fps)), spacing_s * fps
    frames = []
    i = 0
    while first + int(round(i * step)) < len(positions):
        frames.append(first + int(round(i * step)))
        i += 1
    keys = [Keyframe(round(i * spacing_s, 6), positions[f]) for i, f in enumerate(frames)]
    return list(zip(keys[:-1], keys[1:]))


def pair_outcome(graph: DynamicMotionGraph, first: Keyframe, second: Keyframe, quality: bool = False
                 ) -> dict[str, Any]:
    """One key pair joined by ``graph`` (no cleaning): ``joined``, and when joined the ``duration_error_s`` of the
    path (its frames − the keys' frames, / fps; before retiming), ``key_error_cm`` (mean per-joint distance of the
    path's first and last frames to their keys, averaged) and ``frames``; ``seconds`` either way. A pair whose
    trees do not meet (:class:`NoConnectionError`) is ``joined: False``: a failure, counted, never dropped; a
    joined one also has ``met_at_iteration`` (the search's first iteration with a connection). ``quality``: also
    ``skating`` (foot-skating ratio of the joined path, before cleaning:
    :func:`stylemotion.synthesis.quality.skating`) and ``end_gap_cm`` (the path's last Hips to the second key's,
    on the ground)."""
    started = time.perf_counter()
    record: dict[str, Any] = {"spacing_s": round(second.time_s - first.time_s, 6)}
    try:
        pair = graph.connect(first, second)
    except NoConnectionError:
        record.update(joined=False, seconds=round(time.perf_counter() - started, 3))
        return record
    path = pair.positions
    target = int(round((second.time_s - first.time_s) * graph.fps)) + 1
    key_error = 0.5 * (np.linalg.norm(path[0] - first.pose, axis=-1).mean()
                       + np.linalg.norm(path[-1] - second.pose, axis=-1).mean()) * 100.0
    record.update(joined=True, frames=int(len(path)), duration_error_s=round((len(path) - target) / graph.fps, 4),
                  key_error_cm=round(float(key_error), 3), met_at_iteration=pair.figures["met_at_iteration"],
                  seconds=round(time.perf_counter() - started, 3))
    if quality:
        from stylemotion.synthesis.quality import skating

        gap = (path[-1, HIPS] - np.asarray(second.pose)[HIPS])[[0, 2]]
        record.update(skating=round(float(skating(path, graph.fps)[0]), 4),
                      end_gap_cm=round(float(np.linalg.norm(gap)) * 100.0, 3))
    return record


def pairs_score(outcomes: Sequence[Mapping[str, Any]]) -> float:
    """Validation score of key-pair outcomes (lower is better): the mean over attempted pairs of |duration error|
    in seconds, a pair that was not joined counting its whole key spacing (as if the path missed by all of it)."""
    if not outcomes:
        return math.nan
    return float(np.mean([abs(o["duration_error_s"]) if o["joined"] else o["spacing_s"] for o in outcomes]))


def pairs_figures(outcomes: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """Joined / attempted and, over the joined pairs, |duration error| (mean, p95, max, s) and key error (mean, cm)."""
    joined = [o for o in outcomes if o["joined"]]
    out: dict[str, Any] = {"attempted": len(outcomes), "joined": len(joined), "failed": len(outcomes) - len(joined)}
    if joined:
        dur = np.abs([o["duration_error_s"] for o in joined])
        out.update(duration_error_s={"mean": float(dur.mean()), "p95": float(np.percentile(dur, 95)),
                                     "max": float(dur.max())},
                   key_error_cm=float(np.mean([o["key_error_cm"] for o in joined])))
    return out


def skin_marker_noise(markers: np.ndarray, rng: np.random.Generator, placement_mm: float = 10.0,
                      jitter_mm: float = 1.0) -> np.ndarray:
    """Virtual skin markers ``(frames, m, 3)`` metres with the suite ``markers``' noise model: each marker placed
    off its nominal spot by a constant drawn once per recording (uniform ± ``placement_mm`` per axis: where a
    person sticks it) plus per-frame jitter (uniform ± ``jitter_mm`` per axis: the thesis' ± 1 mm)."""
    markers = np.asarray(markers, np.float64)
    placement = rng.uniform(-1.0, 1.0, (1,) + markers.shape[1:]) * placement_mm / 1000.0
    return markers + placement + rng.uniform(-1.0, 1.0, markers.shape) * jitter_mm / 1000.0


def bone_length_spread_cm(positions: np.ndarray) -> dict[str, float]:
    """How much a motion's bones change length over time: per bone the standard deviation over frames (cm), and
    its mean and maximum over bones; and the largest change of any bone (max − min over frames, cm)."""
    from stylemotion.bones import BONE_JOINTS
    from stylemotion.skeleton import bone_lengths

    lengths = bone_lengths(np.asarray(positions, np.float64))[:, list(BONE_JOINTS)] * 100.0
    sd = lengths.std(axis=0)
    return {"mean_sd_cm": float(sd.mean()), "max_sd_cm": float(sd.max()),
            "max_range_cm": float((lengths.max(axis=0) - lengths.min(axis=0)).max())}
