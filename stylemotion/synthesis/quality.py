"""Figures of merit of a synthesized walk (what ``stylemotion-generate`` writes to ``summary.json``).

* **Path deviation**: distance from the root's ground track (Hips projected on the floor) to the
  path polyline, metres — mean and maximum over frames — and the *final* deviation, the distance
  from the last root position to the path's end point.
* **Duration and speed**: seconds, walked distance (length of the root track, m) and mean speed
  (distance / duration, m/s).
* **Foot skating**: :func:`stylemotion.primitives.skating.foot_skating` on the whole motion, with
  the resting foot heights of the motion itself (as for a real take); compare with the same ratio
  of real clips of the style (``stylemotion-reproduce``'s ``report.json``, ``foot_skating_real``).
  Measured on the motion as given (after :mod:`stylemotion.synthesis.cleanup` if it was applied).
  A walk without a planted foot (no foot-frame in contact, e.g. a very short one) has no ratio: NaN here,
  ``null`` in ``summary.json`` (:mod:`stylemotion.io.jsonfile`), "n/a" on the terminal.
* **Transitions**: :func:`stylemotion.synthesis.stitching.transition_speed_ratio`.
* **Latent norms**: the mean ‖z‖ of the chosen codes next to √latent_dim, the radius around which
  prior draws concentrate (how far the path pulled the codes from typical samples).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from stylemotion.primitives.contacts import foot_signals
from stylemotion.primitives.skating import foot_skating
from stylemotion.synthesis.controller import SynthesizedMotion
from stylemotion.synthesis.stitching import transition_speed_ratio


def path_deviation(motion: SynthesizedMotion) -> dict[str, float]:
    """``mean_m``, ``max_m`` (root track to path) and ``final_m`` (last root to path end), metres."""
    _, dist = motion.path.project(motion.root_xz)
    return {"mean_m": float(dist.mean()), "max_m": float(dist.max()),
            "final_m": float(np.linalg.norm(motion.root_xz[-1] - motion.path.end))}


def skating(positions: np.ndarray, fps: float) -> tuple[float, float]:
    """Foot-skating ratio and contact share of one motion ``(frames, 21, 3)`` (its own resting heights)."""
    positions = np.asarray(positions, dtype=np.float64)
    result = foot_skating(positions[None], np.array([len(positions)]), fps, foot_signals(positions, fps).rest_heights)
    return result.ratio, result.contact_share


def walk_figures(motion: SynthesizedMotion) -> dict[str, Any]:
    """All figures of the module doc as a JSON-friendly dict."""
    positions = motion.positions.astype(np.float64)
    duration = (len(positions) - 1) / motion.fps
    walked = float(np.linalg.norm(np.diff(motion.root_xz, axis=0), axis=1).sum())
    skating_ratio, contact_share = skating(positions, motion.fps)
    return {
        "style": motion.style,
        "path_length_m": motion.path.length,
        "deviation": path_deviation(motion),
        "duration_s": duration,
        "walked_m": walked,
        "mean_speed_mps": walked / duration,
        "steps": len(motion.steps),
        "latent_norm_mean": float(np.mean([np.linalg.norm(s.latent) for s in motion.steps])),
        "latent_norm_typical": float(np.sqrt(len(motion.steps[0].latent))),
        "frames": len(positions),
        "fps": motion.fps,
        "foot_skating_ratio": skating_ratio,
        "foot_contact_share": contact_share,
        "transitions": transition_speed_ratio(positions, motion.fps, motion.junctions),
        "synthesis_seconds": motion.seconds,
        "warnings": list(motion.warnings),
    }
