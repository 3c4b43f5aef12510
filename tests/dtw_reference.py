"""A plain-Python subsequence DTW (a double loop over the cells, no code shared with stylemotion.search): the
independent reference of the LNG tests (tests/search/test_lng_brute_force.py, tests/search/test_growth.py)."""

from __future__ import annotations

import math

import numpy as np

#: The thesis' steps (diagonal, horizontal, vertical) written out here, in the order ties are broken.
THESIS = ((1, 1), (0, 1), (1, 0))


def brute_dtw(cost: np.ndarray, lengths: list[int], steps: tuple[tuple[int, int], ...] = THESIS,
              skip: float = 0.0) -> tuple[float, int, int]:
    """Best subsequence DTW path over ``steps`` inside one take by a double loop over the cells; a step of ``dq``
    query frames pays ``skip`` for each of the ``dq - 1`` it skips; inf cells are no nodes. ``(cost, start, end)``
    in global frames, ``(inf, -1, -1)`` without a path; ties: lowest cost, then lowest end frame."""
    m, n = cost.shape
    take = np.repeat(np.arange(len(lengths)), lengths)
    acc = [[math.inf] * n for _ in range(m)]
    start = [[-1] * n for _ in range(m)]
    for i in range(m):
        for g in range(n):
            c = float(cost[i, g])
            if not math.isfinite(c):
                continue
            options = [(0.0, g)] if i == 0 else []
            for dq, dg in steps:
                pi, pg = i - dq, g - dg
                if pi < 0 or pg < 0 or take[pg] != take[g] or not math.isfinite(acc[pi][pg]):
                    continue
                penalty = 0.0
                for _ in range(dq - 1):
                    penalty += skip
                options.append((acc[pi][pg] + penalty, start[pi][pg]))
            if options:
                best = min(o[0] for o in options)
                acc[i][g] = c + best
                start[i][g] = next(s for a, s in options if a == best)
    ends = [(acc[m - 1][g], g) for g in range(n) if math.isfinite(acc[m - 1][g])]
    if not ends:
        return math.inf, -1, -1
    total, end = min(ends)
    return total, start[m - 1][end], end
