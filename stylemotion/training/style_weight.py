"""Choosing the style CVAE's style weight α on validation clips (Du ch. 5, eq. 5.9–5.11).

α trades the style term against the rest: a larger α pulls the decoded clips towards the style example's Gram
matrix (``val/style`` falls), away from the content of the neutral clips they encode (``val/mpjpe`` rises) and, at
the thesis' α = 200, every sample onto the example (the samples' spread collapses). Three figures, none read on a
test clip, measure these:

* ``val/style`` and ``val/mpjpe``: the **validation** clips at the epoch of the best ``val/loss`` (what
  :func:`stylemotion.training.fit.objective` returns for ``sweep_objective: [val/style, val/mpjpe]``);
* ``samples/pose_across_sd`` (cm): the spread of prior samples of the best checkpoint across samples at aligned
  frames (:func:`stylemotion.evaluation.tables.across_sample_sd`; no data read), which ``val/mpjpe`` — a
  reconstruction through the encoder — cannot see.

No α is best on all three, so the rule is scale-free: per style each figure is divided by its best value over the
candidates (the smallest distance or error, the largest spread), and α minimizes the mean over styles of

    log(val/style ÷ min) + log(val/mpjpe ÷ min) + log(max ÷ samples/pose_across_sd)

(the geometric balance of the three relative costs). A candidate with a missing or non-finite value for any style
(a failed training) scores +inf: a failure is never chosen. Ties go to the smaller α.

The spread term was added after the first candidates' validation figures showed ``val/mpjpe`` flat across α
(no test figure had been computed with any candidate).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

#: The figures the rule balances, each with whether smaller (True) or larger (False) is better.
METRICS: dict[str, bool] = {"val/style": True, "val/mpjpe": True, "samples/pose_across_sd": False}
#: The figures for candidates that differ in what the style term sees (``style_latents``, ``style_term``): their
#: ``val/style`` is logged on what each one's term sees (posterior, prior or both decodes), so it does not compare
#: across them; ``samples/style`` (the Gram distance of the same 256 prior samples to the example) does.
SAMPLE_METRICS: dict[str, bool] = {"samples/style": True, "val/mpjpe": True, "samples/pose_across_sd": False}


def _finite(value: object) -> float | None:
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return None
    return number if math.isfinite(number) and number > 0 else None


def style_weight_scores(values: Mapping[Any, Mapping[str, Mapping[str, object]]],
                        metrics: Mapping[str, bool] = METRICS) -> dict[Any, float]:
    """The rule's score of each α (lower is better; module doc), or of any candidates with ``metrics``.

    Args:
        values: α → style → {``val/style``: Gram distance, ``val/mpjpe``: metres, ``samples/pose_across_sd``:
            cm} (:data:`METRICS`; or the figures of ``metrics``, e.g. :data:`SAMPLE_METRICS`).
        metrics: figure → whether smaller is better.

    Returns:
        α → mean over styles of the summed log ratios to the per-style best values; +inf for a failed candidate.
    """
    alphas = sorted(values)
    styles = sorted({s for per_style in values.values() for s in per_style})
    if not alphas or not styles:
        raise ValueError("no candidates: pass α → style → validation metrics")
    best: dict[tuple[str, str], float] = {}
    for style in styles:
        for metric, smaller in metrics.items():
            seen = [v for a in alphas if (v := _finite(values[a].get(style, {}).get(metric))) is not None]
            if seen:
                best[(style, metric)] = min(seen) if smaller else max(seen)
    scores: dict[float, float] = {}
    for a in alphas:
        total = 0.0
        for style in styles:
            for metric, smaller in metrics.items():
                v = _finite(values[a].get(style, {}).get(metric))
                if v is None:
                    total = math.inf
                    break
                ratio = v / best[(style, metric)]
                total += math.log(ratio if smaller else 1.0 / ratio)
            if math.isinf(total):
                break
        scores[a] = total / len(styles) if math.isfinite(total) else math.inf
    return scores


def choose_style_weight(values: Mapping[Any, Mapping[str, Mapping[str, object]]],
                        metrics: Mapping[str, bool] = METRICS) -> Any:
    """The α (or candidate) of the lowest :func:`style_weight_scores` (the smaller one on a tie).

    Raises:
        ValueError: every candidate failed.
    """
    scores = style_weight_scores(values, metrics)
    best = min(sorted(scores), key=lambda a: scores[a])
    if math.isinf(scores[best]):
        raise ValueError("every candidate failed (a missing or non-finite validation metric)")
    return best


def prior_sample_spread(checkpoint: str | Path, samples: int = 256, seed: int = 0) -> float:
    """``samples/pose_across_sd``: pose_across_SD (cm) of ``samples`` prior samples (``z ~ N(0, I)``, seeded) of a
    VAE/CVAE checkpoint, on the canonical timeline (:func:`stylemotion.evaluation.tables.across_sample_sd`)."""
    return prior_sample_figures(checkpoint, samples, seed)["samples/pose_across_sd"]


def prior_sample_figures(checkpoint: str | Path, samples: int = 256, seed: int = 0) -> dict[str, float]:
    """``samples/pose_across_sd`` (:func:`prior_sample_spread`, cm) and, for a style CVAE, ``samples/style``: the
    mean Gram distance of the same samples' features to the example's Gram (``StyleCVAE.style_distance``, the
    distance its style term measures), from one draw of ``samples`` prior samples (seeded)."""
    import torch

    from stylemotion.evaluation.tables import across_sample_sd
    from stylemotion.models.loading import load_generative

    model = load_generative(checkpoint)
    drawn = model.sample(samples, seed=seed)
    out = {"samples/pose_across_sd": across_sample_sd(drawn.normalized_frames.detach().cpu().numpy())}
    if hasattr(model, "style_distance"):
        with torch.no_grad():
            out["samples/style"] = float(model.style_distance(drawn.features).mean())
    return out
