"""Numerical and logical similarity searches (Krüger §2.5.1, after Kovar and Gleicher 2004).

* **Numerical**: the database segments most similar to a query, ranked by the LNG's global distance —
  :func:`numerical_search`, one :func:`~stylemotion.search.matching.search_motion`.
* **Logical**: "use the set of found similar motion segments as queries for new iterations of similarity
  searches" — :func:`logical_search`. Round 0 is the numerical search; in each later round every segment
  first found in the round before is a query (its features are the database's own,
  ``index.features[global_start:global_end]``); what they find is added to the union. Two segments of the
  same take count as one when they overlap by at least ``same_overlap`` of the shorter one, so near copies
  of a known segment add nothing. The search stops at a fixed point (a round adds nothing), after
  ``rounds`` rounds, or when ``max_segments`` are known. Each round's record says which queries ran and what
  they added.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from stylemotion.search.index import FrameIndex
from stylemotion.search.matching import DEFAULT_K, SegmentMatch, search_features, search_motion


def numerical_search(positions: np.ndarray, index: FrameIndex, top: int = 10, k: int = DEFAULT_K,
                     **options: Any) -> list[SegmentMatch]:
    """The ``top`` database segments most similar to a query motion ``(m, 21, 3)`` (metres, the index's fps),
    best first (see :func:`~stylemotion.search.matching.search_features` for ``options``)."""
    return search_motion(positions, index, k, top, **options).matches


@dataclass(frozen=True)
class Found:
    """A segment of the logical search: the match, the round that found it, and which segment's query did
    (``None`` for the user's query)."""

    match: SegmentMatch
    round: int
    found_by: int | None


@dataclass
class LogicalResult:
    """Union of all rounds: ``segments`` in the order found; ``rounds``: per round ``{"round", "queries",
    "found", "added"}`` (``added``: indices into ``segments``); ``stopped``: ``"fixed point"``, ``"rounds"`` or
    ``"max_segments"``."""

    segments: list[Found] = field(default_factory=list)
    rounds: list[dict[str, Any]] = field(default_factory=list)
    stopped: str = ""

    def records(self) -> list[dict[str, Any]]:
        """JSON-ready: each segment's match record plus ``round`` and ``found_by``."""
        return [{**f.match.record(), "round": f.round, "found_by": f.found_by} for f in self.segments]


def same_segment(a: SegmentMatch, b: SegmentMatch, overlap: float) -> bool:
    """Whether two segments are one: same take and an overlap of at least ``overlap`` × the shorter length."""
    if a.take != b.take:
        return False
    shared = min(a.end, b.end) - max(a.start, b.start)
    return shared > 0 and shared >= overlap * min(a.frames, b.frames)


def logical_search(positions: np.ndarray, index: FrameIndex, top: int = 10, k: int = DEFAULT_K, *,
                   rounds: int = 3, max_segments: int = 200, same_overlap: float = 0.5,
                   **options: Any) -> LogicalResult:
    """Iterated similarity search from a query motion ``(m, 21, 3)`` (see the module docstring).

    ``top``/``k``/``options``: of every numerical search; ``rounds``: at most this many rounds (round 0 is the
    user's query); ``max_segments``: stop once this many segments are known; ``same_overlap`` in (0, 1].
    """
    if isinstance(rounds, bool) or not isinstance(rounds, int) or rounds < 1:
        raise ValueError(f"rounds must be a whole number ≥ 1, got {rounds!r}")
    if isinstance(max_segments, bool) or not isinstance(max_segments, int) or max_segments < 1:
        raise ValueError(f"max_segments must be a whole number ≥ 1, got {max_segments!r}")
    if not 0 < same_overlap <= 1:
        raise ValueError(f"same_overlap must be in (0, 1], got {same_overlap!r}")
    result = LogicalResult()
    queries: list[int | None] = [None]
    for r in range(rounds):
        added: list[int] = []
        found = 0
        for q in queries:
            if q is None:
                matches = search_motion(positions, index, k, top, **options).matches
            else:
                seg = result.segments[q].match
                features = index.features[seg.global_start:seg.global_end]
                matches = search_features(features, index, k, top, **options).matches
            found += len(matches)
            for match in matches:
                if len(result.segments) >= max_segments:
                    break
                if not any(same_segment(match, f.match, same_overlap) for f in result.segments):
                    result.segments.append(Found(match, r, q))
                    added.append(len(result.segments) - 1)
        result.rounds.append({"round": r, "queries": [q for q in queries], "found": found, "added": added})
        if not added:
            result.stopped = "fixed point"
            return result
        if len(result.segments) >= max_segments:
            result.stopped = "max_segments"
            return result
        queries = list(added)
    result.stopped = "rounds"
    return result
