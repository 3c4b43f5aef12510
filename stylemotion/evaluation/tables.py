"""The thesis' evaluation tables: style distances (Table 5.1, eq. 5.12) and variance (Tables 5.2/5.3,
eq. 5.13–5.15).

Table 5.1::

    D(m, s) = 1/N Σ_i ‖Gram(Φ(x_i)) − Gram(Φ(s))‖_F

``x_i`` is the i-th of N samples of model m as a motion on the primitive's canonical timeline (the
autoencoder's decoded output), re-encoded by the autoencoder ``Φ``; ``s`` is a style example
clip(s) encoded as the style model was trained on it (several examples: their Grams averaged); for
the neutral column the example is the **mean motion** of the primitive (the frame-wise mean of its
neutral training clips on the canonical timeline), as in the thesis. ``Gram`` and the distance are
:mod:`stylemotion.models.style` (Gram over time divided by the number of time steps, Frobenius
norm). Row ``m`` "has its minimum on the diagonal" when its own style's example is the closest
column; column ``s`` when its own model is the closest row.

Tables 5.2/5.3, over a set of motions (samples of a model, or real clips):

* ``pose_SD`` (eq. 5.13) = ``sqrt(Σ_i ‖p_i − p̄‖² / (N − 1))`` over **all valid frames** of all
  motions at the data's frame rate, ``p_i`` the frame's 21 joint positions relative to the root's
  ground projection, rotated to face +Z (the frame representation's joint values, so every pose has
  the same root position on the ground and the same orientation); centimetres.
* ``V_SD`` (eq. 5.14) = ``sqrt((Σ_i (v_i − v̄)² + Σ_i (ω_i − ω̄)²) / (N − 1))`` over **motions**,
  ``v_i`` the motion's mean root ground speed (m/s) and ``ω_i`` its mean yaw rate about the vertical
  (rad/s, signed), from the frames' velocity channels; the two variances are added as the thesis
  does, in m/s and rad/s.
* ``step_SD`` (eq. 5.15) = the standard deviation over **motions** of the step length ``l_i``, the
  length of the summed relative root translation on the ground (first to last frame), centimetres.

Beyond the thesis, because pose_SD is dominated by the motion within a step and stays high when a
model draws the same motion every time: ``pose_across_SD`` = ``sqrt(1/T Σ_t Σ_c Var_i(x_{i,t,c}))``,
the spread **across motions** at aligned frames of the canonical timeline (``x_{i,t,c}`` coordinate
``c`` of the 21 root-local joint positions of motion ``i`` at canonical frame ``t``; population
variance over motions), centimetres. Copies of one motion score 0 whatever their own movement.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import torch

from stylemotion.models.style import feature_style_distance, gram_factor, mean_gram
from stylemotion.representation import FRAME_DIM, JOINT_DIMS, ROOT_JOINT, VELOCITY_DIMS, YAW_RATE_DIM

#: Names of the variance statistics, in table order.
VARIANCE_KEYS = ("pose_sd", "v_sd", "step_sd")
VARIANCE_UNITS = {"pose_sd": "cm", "v_sd": "m/s ⊕ rad/s", "step_sd": "cm"}


def mean_motion(normalized_frames: np.ndarray) -> np.ndarray:
    """The frame-wise mean ``(length, 66)`` float32 of clips ``(n, length, 66)`` on one timeline."""
    f = np.asarray(normalized_frames, dtype=np.float64)
    if f.ndim != 3 or len(f) == 0:
        raise ValueError(f"need (n ≥ 1, length, {FRAME_DIM}) frames for a mean motion, got {f.shape}")
    return f.mean(0).astype(np.float32)


@torch.no_grad()
def example_gram(autoencoder, examples: Sequence[np.ndarray]) -> torch.Tensor:
    """``Gram(Φ(s))``: the mean Gram ``(C, C)`` of example clips ``(frames_i, 66)`` each (any lengths)."""
    if not examples:
        raise ValueError("no example clip")
    feats = [autoencoder.encode(torch.as_tensor(np.asarray(e), dtype=torch.float32)) for e in examples]
    return mean_gram(feats).float()


@torch.no_grad()
def style_distances(autoencoder, normalized_frames: np.ndarray | torch.Tensor, grams: torch.Tensor,
                    chunk: int = 256) -> np.ndarray:
    """``‖Gram(Φ(x_i)) − G_s‖_F`` for every motion ``x_i`` and every example Gram ``G_s``, by
    :func:`stylemotion.models.style.feature_style_distance` (no ``C × C`` matrix per motion).

    Args:
        autoencoder: has ``encode(frames (b, length, 66)) -> (b, C, T')``.
        normalized_frames: ``(n, length, 66)`` motions on the canonical timeline.
        grams: ``(examples, C, C)`` example Grams.
        chunk: motions encoded at once (a Gram is C² floats each).

    Returns:
        ``(n, examples)`` float64.
    """
    frames = torch.as_tensor(np.asarray(normalized_frames), dtype=torch.float32)
    factors = [gram_factor(g) for g in torch.as_tensor(grams, dtype=torch.float32)]
    out = []
    for i in range(0, len(frames), chunk):
        features = autoencoder.encode(frames[i:i + chunk])  # (b, C, T')
        features = features.double()  # the table's distances in float64, as the report has always given them
        out.append(torch.stack([feature_style_distance(features, target_factor=w) for w in factors], -1))
    return torch.cat(out).numpy() if out else np.zeros((0, len(factors)))


def distance_table(autoencoder, model_frames: Sequence[np.ndarray], grams: torch.Tensor,
                   chunk: int = 256) -> np.ndarray:
    """Table 5.1: ``D[m, s]``, the mean over model m's motions of the distance to example s.

    Args:
        model_frames: per model, ``(N, length, 66)`` samples on the canonical timeline.
        grams: ``(examples, C, C)``.

    Returns:
        ``(models, examples)`` float64.
    """
    return np.stack([style_distances(autoencoder, f, grams, chunk).mean(0) for f in model_frames])


def diagonal_minima(table: np.ndarray, names: Sequence[str]) -> dict[str, object]:
    """Which rows and columns of a square table have their minimum on the diagonal.

    Args:
        table: ``(k, k)``, row ``i`` and column ``i`` belong to ``names[i]``.

    Returns:
        ``rows`` and ``columns``: names whose row (column) minimum is the diagonal entry;
        ``all_rows``, ``all_columns``: whether that holds for every name; ``row_argmin``: per row
        name, the column name of its minimum.
    """
    t = np.asarray(table)
    if t.ndim != 2 or t.shape[0] != t.shape[1] or t.shape[0] != len(names):
        raise ValueError(f"need a square table with one name per row, got {t.shape} and {len(names)} names")
    idx = np.arange(len(names))
    rows = [names[i] for i in idx if t[i].argmin() == i]
    cols = [names[i] for i in idx if t[:, i].argmin() == i]
    return {"rows": rows, "columns": cols, "all_rows": len(rows) == len(names),
            "all_columns": len(cols) == len(names), "row_argmin": {names[i]: names[int(t[i].argmin())] for i in idx}}


def across_sample_sd(normalized_frames: np.ndarray) -> float:
    """pose_across_SD (cm): spread across motions at aligned canonical frames (see the module doc).

    Args:
        normalized_frames: ``(n, T, 66)`` frames of n ≥ 2 motions on one canonical timeline.
    """
    x = np.asarray(normalized_frames, dtype=np.float64)
    if x.ndim != 3 or len(x) < 2 or x.shape[-1] != FRAME_DIM:
        raise ValueError(f"need (n ≥ 2, T, {FRAME_DIM}) normalized frames, got {x.shape}")
    return float(np.sqrt(x[..., JOINT_DIMS].var(axis=0).sum(-1).mean()) * 100.0)


def variance_stats(frames: np.ndarray, positions: np.ndarray, num_frames: np.ndarray,
                   normalized_frames: np.ndarray | None = None) -> dict[str, float]:
    """pose_SD (cm), V_SD (m/s ⊕ rad/s) and step_SD (cm) of a set of motions (see the module doc).

    Args:
        frames: ``(n, frames, 66)`` padded frames at the data's fps (velocities per second).
        positions: ``(n, frames, 21, 3)`` padded positions, metres.
        num_frames: ``(n,)`` valid frames of each motion (≥ 2).
        normalized_frames: ``(n, T, 66)`` the same motions on the canonical timeline; given, the
            result adds ``pose_across_sd`` (cm, :func:`across_sample_sd`).

    Returns:
        ``pose_sd``, ``v_sd``, ``step_sd``, and for context ``speed_mean_mps``, ``yaw_rate_sd``
        (rad/s), ``step_mean_cm``, ``motions``, ``poses`` (and ``pose_across_sd``).
    """
    f = np.asarray(frames, dtype=np.float64)
    p = np.asarray(positions, dtype=np.float64)
    n_valid = np.asarray(num_frames, dtype=np.int64).reshape(-1)
    n = len(f)
    if n < 2 or p.shape[:2] != f.shape[:2] or len(n_valid) != n or n_valid.min() < 2:
        raise ValueError(f"need ≥ 2 motions with matching frames {f.shape}, positions {p.shape} and ≥ 2 valid "
                         f"frames each")
    width = f.shape[1]
    mask = np.arange(width)[None, :] < n_valid[:, None]  # valid frames
    poses = f[..., JOINT_DIMS][mask]  # (poses, 63)
    pose_sd = np.sqrt(((poses - poses.mean(0)) ** 2).sum() / (len(poses) - 1))
    moving = np.arange(width)[None, :] < (n_valid - 1)[:, None]  # forward differences of valid frames
    speed = np.linalg.norm(f[..., VELOCITY_DIMS], axis=-1)
    v = (speed * moving).sum(1) / moving.sum(1)
    w = (f[..., YAW_RATE_DIM] * moving).sum(1) / moving.sum(1)
    v_sd = np.sqrt((((v - v.mean()) ** 2).sum() + ((w - w.mean()) ** 2).sum()) / (n - 1))
    root = p[:, :, ROOT_JOINT, :][..., [0, 2]]
    last = root[np.arange(n), n_valid - 1]
    step = np.linalg.norm(last - root[:, 0], axis=-1)
    stats = {"pose_sd": float(pose_sd * 100.0), "v_sd": float(v_sd), "step_sd": float(step.std(ddof=1) * 100.0),
             "speed_mean_mps": float(v.mean()), "yaw_rate_sd": float(w.std(ddof=1)),
             "step_mean_cm": float(step.mean() * 100.0), "motions": int(n), "poses": int(len(poses))}
    if normalized_frames is not None:
        stats["pose_across_sd"] = across_sample_sd(normalized_frames)
    return stats
