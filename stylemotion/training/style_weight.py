"""Choosing the style CVAE's style weight α on validation clips (Du ch. 5, eq. 5.9–5.11).

α trades the style term against the reconstruction: a larger α pulls the decoded clips towards the style example's
Gram matrix (``val/style`` falls) and away from the content of the neutral clips they encode (``val/mpjpe`` rises).
Both are read on the **validation** clips at the epoch of the best ``val/loss`` (what
:func:`stylemotion.training.fit.objective` returns for ``sweep_objective: [val/style, val/mpjpe]``). Neither is
minimized by one α, so the rule, fixed before any figure was seen, is scale-free: each metric is divided by its
smallest value over the candidates (per style), and α minimizes the mean over styles of

    log(val/style ÷ its minimum) + log(val/mpjpe ÷ its minimum)

(the geometric balance of the two relative costs). A candidate with a missing or non-finite value for any style
(a failed training) scores +inf: a failure is never chosen. Ties go to the smaller α.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

#: The two validation metrics the rule balances.
METRICS = ("val/style", "val/mpjpe")


def _finite(value: object) -> float | None:
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return None
    return number if math.isfinite(number) and number > 0 else None


def style_weight_scores(values: Mapping[float, Mapping[str, Mapping[str, object]]]) -> dict[float, float]:
    """The rule's score of each α (lower is better; module doc).

    Args:
        values: α → style → {``val/style``: Gram distance, ``val/mpjpe``: metres} at the best validation epoch.

    Returns:
        α → mean over styles of the summed log ratios to the per-style minima; +inf for a failed candidate.
    """
    alphas = sorted(values)
    styles = sorted({s for per_style in values.values() for s in per_style})
    if not alphas or not styles:
        raise ValueError("no candidates: pass α → style → validation metrics")
    minima: dict[tuple[str, str], float] = {}
    for style in styles:
        for metric in METRICS:
            seen = [v for a in alphas if (v := _finite(values[a].get(style, {}).get(metric))) is not None]
            if seen:
                minima[(style, metric)] = min(seen)
    scores: dict[float, float] = {}
    for a in alphas:
        total = 0.0
        for style in styles:
            for metric in METRICS:
                v = _finite(values[a].get(style, {}).get(metric))
                if v is None:
                    total = math.inf
                    break
                total += math.log(v / minima[(style, metric)])
            if math.isinf(total):
                break
        scores[a] = total / len(styles) if math.isfinite(total) else math.inf
    return scores


def choose_style_weight(values: Mapping[float, Mapping[str, Mapping[str, object]]]) -> float:
    """The α of the lowest :func:`style_weight_scores` (the smaller α on a tie).

    Raises:
        ValueError: every candidate failed.
    """
    scores = style_weight_scores(values)
    best = min(sorted(scores), key=lambda a: scores[a])
    if math.isinf(scores[best]):
        raise ValueError("every α candidate failed (a missing or non-finite validation metric)")
    return best
