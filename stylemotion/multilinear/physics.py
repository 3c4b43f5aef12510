"""Physics-based motion features for time warping (Krüger §4.1.3): the whole-body centre-of-mass (COM)
acceleration and the angular momenta of chosen body segments.

Segments run from a proximal to a distal canonical joint; each has a mass (fraction of body mass) and a COM at a
fraction of the way from its proximal joint (de Leva 1996's adjustment of Zatsiorsky–Seluyanov's tables for
men, the kind of anthropometric table [RW03] gives; the hands are a point mass at the Hand joint). The body COM is
the mass-weighted mean of the segment COMs; its second time derivative is the COM acceleration (m/s²). A
segment's angular momentum about its proximal joint is ``m r × v`` with ``r`` the proximal joint → segment COM
vector and ``v`` its time derivative (the segment's rotation about that joint), per unit body mass
(m²/s · mass fraction). Every vector is expressed in the body's facing frame
(:func:`stylemotion.representation.facing_yaw`), so the features do not change under a global translation or a
turn about the vertical. Derivatives are central differences (``numpy.gradient``) at the take's fps.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from stylemotion.geometry import rotate_yaw
from stylemotion.representation import facing_yaw
from stylemotion.skeleton import JOINT_INDEX, NUM_JOINTS

#: name → (proximal joint, distal joint or None for a point mass, mass fraction, COM fraction from proximal).
SEGMENTS: dict[str, tuple[str, str | None, float, float]] = {
    "head": ("Neck", "Head", 0.0694, 0.50),
    "trunk": ("Hips", "Neck", 0.4346, 0.50),
    "upper_arm_l": ("UpperArm_L", "LowerArm_L", 0.0271, 0.5772),
    "forearm_l": ("LowerArm_L", "Hand_L", 0.0162, 0.4574),
    "hand_l": ("Hand_L", None, 0.0061, 0.0),
    "upper_arm_r": ("UpperArm_R", "LowerArm_R", 0.0271, 0.5772),
    "forearm_r": ("LowerArm_R", "Hand_R", 0.0162, 0.4574),
    "hand_r": ("Hand_R", None, 0.0061, 0.0),
    "thigh_l": ("UpperLeg_L", "LowerLeg_L", 0.1416, 0.4095),
    "shank_l": ("LowerLeg_L", "Foot_L", 0.0433, 0.4459),
    "foot_l": ("Foot_L", "Toes_L", 0.0137, 0.4415),
    "thigh_r": ("UpperLeg_R", "LowerLeg_R", 0.1416, 0.4095),
    "shank_r": ("LowerLeg_R", "Foot_R", 0.0433, 0.4459),
    "foot_r": ("Foot_R", "Toes_R", 0.0137, 0.4415),
}

#: Angular-momentum segments of the walking features (the thesis' Fig. 4.2: hands and feet; a hand is a point
#: mass here, so the forearm carries the hand's swing).
LOCOMOTION_SEGMENTS: tuple[str, ...] = ("forearm_l", "forearm_r", "foot_l", "foot_r", "shank_l", "shank_r")


def _check_positions(positions: np.ndarray) -> np.ndarray:
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim != 3 or p.shape[1:] != (NUM_JOINTS, 3) or p.shape[0] < 3:
        raise ValueError(f"positions must be (frames ≥ 3, {NUM_JOINTS}, 3), got {p.shape}")
    return p


def segment_coms(positions: np.ndarray, names: Sequence[str] = tuple(SEGMENTS)) -> np.ndarray:
    """``(frames, segments, 3)`` COM positions (metres) of the named segments of ``(frames, 21, 3)``."""
    p = np.asarray(positions, dtype=np.float64)
    out = []
    for name in names:
        prox, dist, _, at = SEGMENTS[name]
        a = p[..., JOINT_INDEX[prox], :]
        out.append(a if dist is None else a + at * (p[..., JOINT_INDEX[dist], :] - a))
    return np.stack(out, axis=-2)


def body_com(positions: np.ndarray) -> np.ndarray:
    """``(frames, 3)`` whole-body COM (metres): the mass-weighted mean of every segment's COM."""
    mass = np.array([SEGMENTS[n][2] for n in SEGMENTS])
    return np.einsum("...sk,s->...k", segment_coms(positions), mass / mass.sum())


def physics_features(positions: np.ndarray, fps: float,
                     segments: Sequence[str] = LOCOMOTION_SEGMENTS) -> np.ndarray:
    """``(frames, 3 + 3 · len(segments))``: the COM acceleration (m/s²), then each segment's angular momentum about
    its proximal joint per unit body mass, all in the facing frame; ``positions`` ``(frames ≥ 3, 21, 3)``
    metres, Y up, at ``fps``."""
    p = _check_positions(positions)
    unknown = [s for s in segments if s not in SEGMENTS or SEGMENTS[s][1] is None]
    if unknown:
        raise ValueError(f"segments {unknown} have no extent; choose among "
                         f"{[s for s in SEGMENTS if SEGMENTS[s][1] is not None]}")
    dt = 1.0 / float(fps)
    acc = np.gradient(np.gradient(body_com(p), dt, axis=0), dt, axis=0)
    parts = [acc]
    for name in segments:
        prox, _, mass, _ = SEGMENTS[name]
        r = segment_coms(p, [name])[:, 0] - p[:, JOINT_INDEX[prox]]
        parts.append(mass * np.cross(r, np.gradient(r, dt, axis=0)))
    yaw = facing_yaw(p, fps)
    return np.concatenate([rotate_yaw(v, -yaw) for v in parts], axis=1)


def balanced(features: np.ndarray, group: int = 3) -> np.ndarray:
    """``features`` ``(frames, 3k)`` with each 3-vector group divided by its RMS norm over the frames, so that
    the COM acceleration (m/s²) and the far smaller momenta weigh alike in the cosine cost; a group that is zero
    throughout stays zero."""
    f = np.asarray(features, dtype=np.float64)
    g = f.reshape(f.shape[0], -1, group)
    rms = np.sqrt(np.mean(np.sum(g ** 2, axis=2), axis=0))
    return (g / np.where(rms > 0, rms, 1.0)[None, :, None]).reshape(f.shape)
