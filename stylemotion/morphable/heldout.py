"""Held-out measures of a Morphable Graph primitive: reductions scored on clips they were not fitted to, keyframe
solves over a set of targets, and the choice of a setting on validation data.

* :func:`compare_reductions` — FPCA / normalized FPCA / SFPCA fitted on the training clips' coefficient vectors,
  their joint-space RMSE on the training clips and on held-out parts (``val``, ``test``). Held-out clips are
  aligned by DTW to the training reference clip (the one :func:`~stylemotion.morphable.model.functional_data`
  aligns the training clips to), encoded with the training channels and the same spline basis, projected and
  reconstructed. SFPCA's weights are optimized on the training clips only; with a ``val`` part, the weights kept
  are those of {its start (FPCA or normalized), L-BFGS-B's best on train} with the lower validation error
  (:func:`~stylemotion.morphable.fpca.fit_reduction`'s ``selection_error``), so no figure on ``test`` chose them.
* :func:`keyframe_errors` — the hand (any joint) driven to position targets at the primitive's last frame by
  :func:`~stylemotion.morphable.synthesis.solve_constraints`: error after MAP per target, failures (missed by more
  than the solver's tolerance, or met by a code less likely than 99 % of the mixture's own samples) counted.
* :func:`choose_constraint_scale` — ``σ_c`` candidates scored on validation targets (fewest failures — missed, or
  met by a code off the model —, ties by the median error after MAP), the choice reported on test targets.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.morphable.bspline import SplineBasis
from stylemotion.morphable.fpca import METHODS, FunctionalPCA, fit_reduction
from stylemotion.morphable.heldout_vectors import HeldOutVectors, encode_heldout, heldout_error_function
from stylemotion.morphable.model import (
    MorphableModel,
    choose_coefficients,
    coefficient_vectors,
    functional_data,
    joint_error_function,
)
from stylemotion.primitives.segmentation import Clip
from stylemotion.skeleton import CANONICAL_JOINTS

__all__ = ["HeldOutVectors", "encode_heldout", "heldout_error_function", "compare_reductions", "keyframe_errors",
           "choose_constraint_scale", "off_model_threshold", "user_motion_clips"]


def _selection(vectors: np.ndarray, error):
    """SFPCA's ``selection_error``: a PCA's ``reconstruct ∘ project`` → its error on ``vectors``."""
    def select(rebuild) -> float:
        return error(rebuild(vectors))

    return select


def compare_reductions(train: Sequence[Clip], heldout: Mapping[str, Sequence[Clip]], dims: Sequence[int],
                       methods: Sequence[str] = METHODS, num_coefficients: int | None = None,
                       rmse_cutoff_m: float = 0.01, iterations: int = 30, representation: str = "quaternion",
                       given: Mapping[str, FunctionalPCA] | None = None, per_clip: bool = False) -> dict[str, Any]:
    """Joint-space RMSE (m) of each reduction at each latent size, on ``train`` and on each held-out part.

    Args:
        train: clips the reductions are fitted to.
        heldout: ``{part: clips}`` (e.g. ``val``, ``test``); a ``val`` part also chooses SFPCA's kept weights.
        dims: latent sizes (each below ``len(train)``).
        num_coefficients: ``K``, or None for the 1 cm cut-off on the training clips.
        iterations: SFPCA's L-BFGS-B iterations.
        given: ``{method: reduction}`` already fitted to the same training clips with the same ``K`` (e.g. a
            model's), scored at its own latent size instead of being fitted again.

    Returns:
        ``{"K", "timeline", "clips": {part: n}, "rows": [{"dims", "method", "rmse_m": {part: m}, "sfpca": record}]}``
        (rows also hold ``rmse_per_clip_m`` with ``per_clip``).
    """
    data = functional_data(train, representation)
    k = num_coefficients or choose_coefficients(data, rmse_cutoff_m)[0]
    basis = SplineBasis(k)
    vectors, groups, _ = coefficient_vectors(data, basis)
    errors = {"train": joint_error_function(data, basis, vectors)}
    held = {part: encode_heldout(data, train[data.reference], basis, clips) for part, clips in heldout.items() if clips}
    for part, h in held.items():
        errors[part] = heldout_error_function(data, basis, h)
    def scored(pca: FunctionalPCA) -> dict[str, Any]:
        rmse = {"train": float(np.sqrt(errors["train"](pca.reconstruct(pca.project(vectors)))))}
        rebuilt = {part: pca.reconstruct(pca.project(h.vectors)) for part, h in held.items()}
        rmse.update({part: float(np.sqrt(errors[part](r))) for part, r in rebuilt.items()})
        if not per_clip:
            return {"rmse_m": rmse}
        return {"rmse_m": rmse, "rmse_per_clip_m": {part: np.sqrt(errors[part](r, per_clip=True)).tolist()
                                                    for part, r in rebuilt.items()}}

    rows = []
    for d in dims:
        for method in methods:
            select = _selection(held["val"].vectors, errors["val"]) if method == "sfpca" and "val" in held else None
            pca, record = fit_reduction(vectors, groups, d, method, errors["train"], iterations,
                                        selection_error=select)
            rows.append({"dims": int(d), "method": method, **scored(pca),
                         **({"sfpca": record} if method == "sfpca" else {})})
    for method, pca in (given or {}).items():
        rows.append({"dims": pca.latent_dim, "method": method, **scored(pca), "given": True})
    return {"K": k, "timeline": data.length, "clips": {"train": len(train), **{p: len(c) for p, c in heldout.items()}},
            "rows": rows}


def off_model_threshold(model: MorphableModel, samples: int = 10_000, seed: int = 0, percentile: float = 99.0
                        ) -> float:
    """``−ln p(s)`` above which a code is *off the model*: the ``percentile`` of the mixture's own samples."""
    return float(np.percentile(-model.gmm.log_prob(model.gmm.sample(samples, seed)), percentile))


def keyframe_errors(model: MorphableModel, targets: np.ndarray, joint: str, constraint_scale_m: float,
                    off_model: float | None = None, **settings: Any) -> dict[str, Any]:
    """``joint`` driven to each of ``targets`` ``(n, 3)`` (m, the primitive's own frame) at the last frame.

    Returns ``{"errors_m": [n], "tree_errors_m": [n], "neg_log_prior": [n], "missed": k, "off_model": k,
    "failures": k}``: the error after the MAP solve and of the tree's candidate per target, and ``−ln p`` of the
    solution. A failure is a target still missed by more than the solver's ``tolerance_m`` (``missed``), or met
    by a code less likely than ``off_model`` (default :func:`off_model_threshold`: a motion the model does not
    hold — a small σ_c reaches far targets by leaving the mixture).
    """
    from stylemotion.morphable.constraints import KeyframeConstraint
    from stylemotion.morphable.synthesis import MapSettings, UnreachableConstraintWarning, solve_constraints

    map_settings = MapSettings(constraint_scale_m=constraint_scale_m, **settings)
    limit = off_model_threshold(model) if off_model is None else float(off_model)
    errors, tree, prior, missed, off = [], [], [], 0, 0
    for target in np.asarray(targets, dtype=np.float64):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UnreachableConstraintWarning)
            result = solve_constraints(model, [KeyframeConstraint("position", target, joint=joint)], map_settings)
        errors.append(float(result.errors_m[0]))
        tree.append(float(result.start_errors_m[0]))
        prior.append(float(result.neg_log_prior))
        missed += bool(result.unreachable)
        off += (not result.unreachable) and result.neg_log_prior > limit
    return {"errors_m": errors, "tree_errors_m": tree, "neg_log_prior": prior, "missed": missed, "off_model": off,
            "failures": missed + off, "off_model_threshold": limit}


def choose_constraint_scale(model: MorphableModel, val_targets: np.ndarray, candidates: Sequence[float],
                            joint: str) -> dict[str, Any]:
    """The ``σ_c`` of ``candidates`` (m) with the fewest failures on ``val_targets`` (missed by more than the
    tolerance, or met off the model: :func:`keyframe_errors`), ties by the lower median error after MAP, then the
    larger σ_c. Returns ``{"candidates": [{"scale_m", "median_m", "p95_m", "max_m", "missed", "off_model",
    "failures"}], "chosen_m"}``."""
    if joint not in CANONICAL_JOINTS:
        raise ValueError(f"unknown joint {joint!r}; one of {CANONICAL_JOINTS}")
    limit = off_model_threshold(model)
    scores = []
    for scale in candidates:
        found = keyframe_errors(model, val_targets, joint, float(scale), off_model=limit)
        e = np.asarray(found["errors_m"])
        scores.append({"scale_m": float(scale), "median_m": float(np.median(e)), "p95_m": float(np.percentile(e, 95)),
                       "max_m": float(e.max()), "missed": int(found["missed"]), "off_model": int(found["off_model"]),
                       "failures": int(found["failures"])})
    best = min(scores, key=lambda s: (s["failures"], round(s["median_m"], 5), -s["scale_m"]))
    return {"candidates": scores, "chosen_m": best["scale_m"], "off_model_threshold": limit}


def user_motion_clips(files: Sequence[str | Path], takeset, action: str = "walk", content: str = "walk",
                      fps: float = 30.0) -> list[Clip]:
    """Primitive clips of recordings from other captures: each BVH file read by the one reader of user motion
    (:mod:`stylemotion.datasets.user_motion`: any skeleton a joint map names, resampled to ``fps``), put on
    ``takeset``'s skeleton (:func:`~stylemotion.datasets.user_motion.on_run_skeleton`) and segmented as the data
    sets are (:func:`~stylemotion.primitives.segmentation.segment_takes`), labelled ``content``, style ``other``."""
    from stylemotion.datasets.base import Take
    from stylemotion.datasets.loading import ConversionSettings
    from stylemotion.datasets.user_motion import convert_example, on_run_skeleton, parse_example
    from stylemotion.io.outputs import safe_name
    from stylemotion.primitives.segmentation import segment_takes

    takes = []
    for i, file in enumerate(files):
        example = on_run_skeleton(convert_example(parse_example(str(file)), ConversionSettings(fps=fps)), takeset)
        name = safe_name(f"other_{content}_{Path(file).stem}")
        takes.append(Take(name, np.asarray(example.positions, np.float32), fps,
                          {"content": content, "style": "other", "take": f"{i:03d}"}, str(file)))
    return segment_takes(takes).select(action)
