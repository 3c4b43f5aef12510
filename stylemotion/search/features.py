"""Feature sets for similarity search in motion databases (Krüger, *Synthesizing Human Motions*, §2.3.2, §2.6.1).

Every feature set maps one continuous take of canonical positions ``(frames, 21, 3)`` (metres, Y up,
:data:`stylemotion.skeleton.CANONICAL_JOINTS` order) at ``fps`` to ``(frames, d)`` float32 features,
whose Euclidean distance is the search's distance. The sets (``FEATURE_SETS``):

* ``E15``, ``E30``, ``E39``: joint positions in the body frame (thesis' F_E^15/30/39), the thesis'
  joints mapped to ours as :data:`E15_JOINTS`, :data:`E30_JOINTS`, :data:`E39_JOINTS` say;
* ``E15x3``, ``E15x5``, ``E30x3``, ``E39x3``: the frame sets sampled 3 or 5 times over the 0.3 s
  ending at each frame (see :func:`window_offsets`);
* ``pca8``, ``pca16``, ``pca25``: the first principal components of all 21 body-frame joint
  positions, fitted on the indexed database (:func:`fit_features` → :class:`FittedPCA`);
* ``EP17``, ``EP19``: ``E15`` plus physics terms from a segment mass table (:func:`physics_terms`).

**Normalization** (:data:`NORMALIZATIONS`): ``"3d"`` (default, the thesis' "normalized root
positions and orientations") expresses the joints relative to the root (Hips) in the root's own 3D
frame (:func:`root_frames`: pelvis across and lower-trunk up, so also root pitch and roll are taken
out); ``"2d"`` expresses them relative to the root's ground projection, rotated about the vertical
only, by the body's facing (:func:`stylemotion.representation.facing_yaw`, unsmoothed so that a
frame's features depend on that frame alone). Both are invariant under translating and turning a
whole motion about the vertical; ``"3d"`` also under any rotation of it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from stylemotion.geometry import EPSILON, facing_direction, rotate_yaw
from stylemotion.representation import facing_yaw
from stylemotion.skeleton import JOINT_INDEX, NUM_JOINTS, checked_positions

#: Ways to put joints into the body frame (see the module docstring).
NORMALIZATIONS = ("3d", "2d")
#: Length of the windows of the windowed sets, seconds (thesis §2.3.2).
WINDOW_SECONDS = 0.3
#: Δt of the physics terms' scaling (§2.6.1), seconds: the interval the windowed sets consider.
PHYSICS_INTERVAL_S = WINDOW_SECONDS
#: Body mass of the physics terms' momentum, kg: the mean of de Leva's (1996) male reference subjects.
PHYSICS_BODY_MASS_KG = 73.0
#: Thesis' F_E^15: the 4 end effectors (wrists, ankles — cf. its Fig. 2.1) and the head.
E15_JOINTS = ("Hand_L", "Hand_R", "Foot_L", "Foot_R", "Head")
#: F_E^30: ``E15`` plus elbows (LowerArm), knees (LowerLeg) and one chest joint (Chest).
E30_JOINTS = E15_JOINTS + ("LowerArm_L", "LowerArm_R", "LowerLeg_L", "LowerLeg_R", "Chest")
#: F_E^39: ``E30`` plus shoulders (the glenohumeral joints, UpperArm; our Shoulder_* are the
#: clavicles) and one lower-back joint (Spine).
E39_JOINTS = E30_JOINTS + ("UpperArm_L", "UpperArm_R", "Spine")


# ---------------------------------------------------------------------------------------------
# Body frame


def _check_normalization(normalization: str) -> None:
    if normalization not in NORMALIZATIONS:
        raise ValueError(f"unknown normalization {normalization!r}; valid: {list(NORMALIZATIONS)}")


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), EPSILON)


def root_frames(positions: np.ndarray) -> np.ndarray:
    """The root's 3D orientation per frame, from the pelvis.

    Args:
        positions: ``(..., 21, 3)`` canonical positions, metres, Y up.

    Returns:
        ``(..., 3, 3)`` rotations whose columns are the body's left (``UpperLeg_L − UpperLeg_R``),
        up (``Chest − Hips`` made orthogonal to left) and forward (left × up) in world coordinates —
        the frame that faces +Z with +X left and +Y up, as :mod:`stylemotion.representation` does.
    """
    left = _unit(positions[..., JOINT_INDEX["UpperLeg_L"], :] - positions[..., JOINT_INDEX["UpperLeg_R"], :])
    trunk = positions[..., JOINT_INDEX["Chest"], :] - positions[..., JOINT_INDEX["Hips"], :]
    up = _unit(trunk - np.sum(trunk * left, axis=-1, keepdims=True) * left)
    forward = np.cross(left, up)
    return np.stack([left, up, forward], axis=-1)


def body_frame_positions(positions: np.ndarray, fps: float, normalization: str = "3d") -> np.ndarray:
    """All joints in the body frame.

    Args:
        positions: ``(frames, 21, 3)`` canonical positions, metres, Y up.
        fps: frames per second (unused by the unsmoothed facing; kept for the facing helper's signature).
        normalization: ``"3d"``: relative to the Hips in :func:`root_frames`' frame; ``"2d"``: relative
            to the Hips' ground projection (y stays height), turned by ``−facing_yaw`` about +Y.

    Returns:
        ``(frames, 21, 3)`` float64, metres.
    """
    _check_normalization(normalization)
    positions = checked_positions(positions)
    root = positions[:, JOINT_INDEX["Hips"], :]
    if normalization == "3d":
        rotation = root_frames(positions)
        return np.einsum("fji,fkj->fki", rotation, positions - root[:, None, :])
    ground = root * np.array([1.0, 0.0, 1.0])
    yaw = facing_yaw(positions, fps, smooth_seconds=0.0)
    return rotate_yaw(positions - ground[:, None, :], -yaw[:, None])


def joint_features(positions: np.ndarray, fps: float, joints: Sequence[str], normalization: str = "3d") -> np.ndarray:
    """Body-frame positions of ``joints``, joint-major: ``(frames, 3·len(joints))`` float32, metres."""
    local = body_frame_positions(positions, fps, normalization)
    picked = local[:, [JOINT_INDEX[j] for j in joints], :]
    return picked.reshape(picked.shape[0], -1).astype(np.float32)


# ---------------------------------------------------------------------------------------------
# Windows


def window_offsets(samples: int, fps: float, seconds: float = WINDOW_SECONDS) -> np.ndarray:
    """Frame offsets ``(samples,)`` of a window, oldest first, ending at 0 and spanning ``round(seconds·fps)``
    frames (30 fps, 0.3 s: 3 samples → ``[-9, -4, 0]``, 5 → ``[-9, -7, -4, -2, 0]``)."""
    span = int(round(seconds * fps))
    return np.round(np.linspace(-span, 0, samples)).astype(np.int64)


def window_frames(samples: int, fps: float, seconds: float = WINDOW_SECONDS) -> int:
    """Frames a window covers: ``round(seconds·fps) + 1`` (1 for a single sample)."""
    return 1 if samples <= 1 else int(-window_offsets(samples, fps, seconds)[0]) + 1


def stack_window(frame_features: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """Per-frame features ``(frames, d)`` → ``(frames, d·len(offsets))``: frame ``t`` holds the features of
    frames ``t + offsets`` (oldest first); frames before the take's start clamp to its first frame."""
    n = frame_features.shape[0]
    rows = np.clip(np.arange(n)[:, None] + offsets[None, :], 0, n - 1)
    return frame_features[rows].reshape(n, -1)


# ---------------------------------------------------------------------------------------------
# Physics (§2.6.1)


@dataclass(frozen=True)
class Segment:
    """A body segment: its mass fraction and where its centre of mass lies on our joints.

    The COM is ``p + fraction·(d − p)`` with ``p``/``d`` the mean positions of the ``proximal``/``distal``
    joints; a fraction above 1 extrapolates past the distal joint.
    """

    name: str
    mass: float
    proximal: tuple[str, ...]
    distal: tuple[str, ...]
    fraction: float


# de Leva (1996), "Adjustments to Zatsiorsky-Seluyanov's segment inertia parameters", J. Biomech. 29(9),
# 1223–1230, Table 4, male column (a population average: college-aged adults). Mass fractions sum to 1.
# Mapping to our joints (endpoints → joints): CERV → Neck; MIDH → mid UpperLeg_L/R; SJC → UpperArm;
# EJC → LowerArm; WJC → Hand; HJC → UpperLeg; KJC → LowerLeg; AJC → Foot.
# * head (VERT–CERV, 6.94 %): the skeleton has no vertex; its COM (50.02 % from the vertex, i.e. near
#   the skull base) is put at the Head joint.
# * trunk (CERV–MIDH, 43.46 %, COM 51.38 % from CERV).
# * upper arm (SJC–EJC, 2.71 %, 57.72 %), forearm (EJC–WJC, 1.62 %, 45.74 %).
# * hand (WJC–MET3, 0.61 %, 79.00 %): no MET3 joint; the COM lies 0.79 × 8.62 cm (mean hand length)
#   past the wrist along the forearm, i.e. 1 + 0.79·8.62/26.89 (mean forearm length) along LowerArm→Hand.
# * thigh (HJC–KJC, 14.16 %, 40.95 %), shank (KJC–AJC, 4.33 %, 43.95 %).
# * foot (HEEL–TTIP, 1.37 %, 44.15 % from the heel): no heel or toe-tip joint; the COM is put midway
#   between the ankle (Foot) and the ball of the foot (Toes).
_MID_HIPS = ("UpperLeg_L", "UpperLeg_R")
SEGMENTS: tuple[Segment, ...] = (
    Segment("head", 0.0694, ("Neck",), ("Head",), 1.0),
    Segment("trunk", 0.4346, ("Neck",), _MID_HIPS, 0.5138),
    *(seg for side in ("L", "R") for seg in (
        Segment(f"upper_arm_{side}", 0.0271, (f"UpperArm_{side}",), (f"LowerArm_{side}",), 0.5772),
        Segment(f"forearm_{side}", 0.0162, (f"LowerArm_{side}",), (f"Hand_{side}",), 0.4574),
        Segment(f"hand_{side}", 0.0061, (f"LowerArm_{side}",), (f"Hand_{side}",), 1.0 + 0.79 * 8.62 / 26.89),
        Segment(f"thigh_{side}", 0.1416, (f"UpperLeg_{side}",), (f"LowerLeg_{side}",), 0.4095),
        Segment(f"shank_{side}", 0.0433, (f"LowerLeg_{side}",), (f"Foot_{side}",), 0.4395),
        Segment(f"foot_{side}", 0.0137, (f"Foot_{side}",), (f"Toes_{side}",), 0.5),
    )),
)


def _segment_matrix() -> tuple[np.ndarray, np.ndarray]:
    """``(segments, 21)`` weights turning joint positions into segment COMs, and ``(segments,)`` masses."""
    weights = np.zeros((len(SEGMENTS), NUM_JOINTS))
    for s, seg in enumerate(SEGMENTS):
        for joint in seg.proximal:
            weights[s, JOINT_INDEX[joint]] += (1.0 - seg.fraction) / len(seg.proximal)
        for joint in seg.distal:
            weights[s, JOINT_INDEX[joint]] += seg.fraction / len(seg.distal)
    return weights, np.array([seg.mass for seg in SEGMENTS])


SEGMENT_WEIGHTS, SEGMENT_MASSES = _segment_matrix()


def segment_centres(positions: np.ndarray) -> np.ndarray:
    """Segment centres of mass ``(..., segments, 3)`` of positions ``(..., 21, 3)``, metres."""
    return np.einsum("sj,...jc->...sc", SEGMENT_WEIGHTS, positions)


def centre_of_mass(positions: np.ndarray) -> np.ndarray:
    """Whole-body centre of mass ``(..., 3)`` of positions ``(..., 21, 3)``, metres (mass fractions sum to 1)."""
    return np.einsum("s,...sc->...c", SEGMENT_MASSES, segment_centres(positions))


def _per_frame_difference(x: np.ndarray) -> np.ndarray:
    """Central difference ``(x[t+1] − x[t−1]) / 2`` along axis 0 (a velocity times Δt); the ends repeat
    their neighbour's value; zeros for fewer than 3 frames."""
    out = np.zeros_like(x)
    if x.shape[0] >= 3:
        out[1:-1] = 0.5 * (x[2:] - x[:-2])
        out[0], out[-1] = out[1], out[-2]
    return out


def _second_difference(x: np.ndarray) -> np.ndarray:
    """``x[t+1] − 2x[t] + x[t−1]`` along axis 0 (an acceleration times Δt²); ends repeat; zeros below 3 frames."""
    out = np.zeros_like(x)
    if x.shape[0] >= 3:
        out[1:-1] = x[2:] - 2.0 * x[1:-1] + x[:-2]
        out[0], out[-1] = out[1], out[-2]
    return out


def heading_directions(positions: np.ndarray, fps: float, min_speed: float = 0.1) -> np.ndarray:
    """Unit horizontal direction of motion ``(frames, 3)``: the COM's ground velocity where it exceeds
    ``min_speed`` m/s, else the body's facing (:func:`stylemotion.representation.facing_yaw`, unsmoothed)."""
    velocity = _per_frame_difference(centre_of_mass(positions)) * fps
    ground = velocity * np.array([1.0, 0.0, 1.0])
    speed = np.linalg.norm(ground, axis=-1, keepdims=True)
    facing = facing_direction(facing_yaw(positions, fps, smooth_seconds=0.0))
    facing3 = np.stack([facing[:, 0], np.zeros(len(facing)), facing[:, 1]], axis=-1)
    return np.where(speed > min_speed, ground / np.maximum(speed, EPSILON), facing3)


def angular_momentum(positions: np.ndarray) -> np.ndarray:
    """Whole-body angular momentum about the COM per unit body mass, times Δt: ``(frames, 3)``, m².

    Point masses at the segment COMs (de Leva's table, :data:`SEGMENTS`); the segments' own inertia about
    their COMs is left out (a spin about a bone's long axis is not visible in joint positions).
    Velocities are central differences (:func:`_per_frame_difference`), so the value is ``L·Δt / M``.
    """
    centres = segment_centres(positions)
    com = np.einsum("s,fsc->fc", SEGMENT_MASSES, centres)
    rel = centres - com[:, None, :]
    rel_velocity = _per_frame_difference(centres) - _per_frame_difference(com)[:, None, :]
    return np.einsum("s,fsc->fc", SEGMENT_MASSES, np.cross(rel, rel_velocity))


def physics_terms(positions: np.ndarray, fps: float, terms: int = 4, interval_s: float = PHYSICS_INTERVAL_S,
                  body_mass_kg: float = PHYSICS_BODY_MASS_KG) -> np.ndarray:
    """The physics features of §2.6.1: ``(frames, terms)`` float64.

    Columns (``terms`` = 2 takes the first two, as ``EP17``; 4 all, as ``EP19``):

    0. COM acceleration along +Y (opposite to gravity) × Δt², metres — free fall gives ``−g·Δt²``;
    1. whole-body angular momentum about +Y × Δt, kg·m² — positive for a left turn (+Z towards +X,
       the project's yaw sign);
    2. COM acceleration along the horizontal direction of motion (:func:`heading_directions`) × Δt²;
    3. angular momentum about the axis ⟂ to that direction and gravity (+Y × direction, the body's left
       when it walks forwards) × Δt — positive when the body pitches forwards.

    Velocity-like terms scale with Δt and acceleration-like ones with Δt², as §2.6.1 says, with Δt =
    ``interval_s``, "the time interval under consideration": by default the 0.3 s the windowed sets look
    at, and the momentum of a ``body_mass_kg`` body (de Leva's male reference, 73 kg). With Δt = one frame and
    a unit mass the terms are ~300× smaller than an E15 coordinate's spread on Bandai walks and EP17 ranks
    exactly like E15 (docs/search.md, "Physics feature sets").
    """
    if terms not in (2, 4):
        raise ValueError(f"physics terms must be 2 or 4, got {terms}")
    for value, key in ((fps, "fps"), (interval_s, "interval_s"), (body_mass_kg, "body_mass_kg")):
        if not (np.isfinite(value) and value > 0):
            raise ValueError(f"physics terms need a positive finite {key}, got {value!r}")
    positions = checked_positions(positions)
    frames_per_interval = interval_s * fps
    acceleration = _second_difference(centre_of_mass(positions)) * frames_per_interval**2
    momentum = angular_momentum(positions) * frames_per_interval * body_mass_kg
    columns = [acceleration[:, 1], momentum[:, 1]]
    if terms == 4:
        direction = heading_directions(positions, fps)
        side = np.cross(np.array([0.0, 1.0, 0.0]), direction)
        columns += [np.sum(acceleration * direction, axis=-1), np.sum(momentum * side, axis=-1)]
    return np.stack(columns, axis=-1)


# ---------------------------------------------------------------------------------------------
# PCA of body-frame positions


@dataclass(frozen=True)
class FittedPCA:
    """A PCA of body-frame joint positions (63 values per frame, joint-major), fitted on a database.

    Attributes:
        mean: ``(63,)`` metres.  components: ``(n, 63)`` orthonormal rows.
        explained_variance: ``(n,)`` m².  normalization: the body frame it was fitted in.
    """

    mean: np.ndarray
    components: np.ndarray
    explained_variance: np.ndarray
    normalization: str = "3d"

    @property
    def n_components(self) -> int:
        return int(self.components.shape[0])

    def transform(self, flat: np.ndarray) -> np.ndarray:
        """``(frames, 63)`` → ``(frames, n)`` scores, metres."""
        return (flat - self.mean) @ self.components.T

    def inverse_transform(self, scores: np.ndarray) -> np.ndarray:
        """``(frames, n)`` scores → ``(frames, 63)`` reconstructed body-frame positions, metres."""
        return scores @ self.components + self.mean

    def to_arrays(self, prefix: str = "pca_") -> dict[str, np.ndarray]:
        """Plain arrays for an ``.npz`` (no pickle)."""
        return {f"{prefix}mean": self.mean, f"{prefix}components": self.components,
                f"{prefix}explained_variance": self.explained_variance,
                f"{prefix}normalization": np.array(self.normalization)}

    @classmethod
    def from_arrays(cls, arrays: dict[str, np.ndarray] | np.lib.npyio.NpzFile, prefix: str = "pca_") -> FittedPCA:
        """Inverse of :meth:`to_arrays`; ValueError for inconsistent shapes."""
        mean = np.asarray(arrays[f"{prefix}mean"], dtype=np.float64)
        components = np.asarray(arrays[f"{prefix}components"], dtype=np.float64)
        variance = np.asarray(arrays[f"{prefix}explained_variance"], dtype=np.float64)
        normalization = str(arrays[f"{prefix}normalization"])
        if mean.shape != (3 * NUM_JOINTS,) or components.ndim != 2 or components.shape[1] != mean.shape[0] \
                or variance.shape != components.shape[:1]:
            raise ValueError(f"inconsistent PCA arrays: mean {mean.shape}, components {components.shape}, "
                             f"variance {variance.shape}")
        _check_normalization(normalization)
        return cls(mean, components, variance, normalization)


def _flat_body_positions(positions: np.ndarray, fps: float, normalization: str) -> np.ndarray:
    local = body_frame_positions(positions, fps, normalization)
    return local.reshape(local.shape[0], 3 * NUM_JOINTS)


def fit_pca(takes: Sequence[np.ndarray], fps: float, n_components: int, normalization: str = "3d") -> FittedPCA:
    """PCA (scikit-learn) of the body-frame positions of every frame of ``takes`` (each ``(frames, 21, 3)``)."""
    from sklearn.decomposition import PCA

    data = np.concatenate([_flat_body_positions(p, fps, normalization) for p in takes])
    if data.shape[0] < n_components:
        raise ValueError(f"a {n_components}-component PCA needs at least {n_components} frames, got {data.shape[0]}")
    pca = PCA(n_components=n_components, svd_solver="auto", random_state=0).fit(data)
    return FittedPCA(pca.mean_.copy(), pca.components_.copy(), pca.explained_variance_.copy(), normalization)


# ---------------------------------------------------------------------------------------------
# Registry


@dataclass(frozen=True)
class FeatureSpec:
    """One feature set: its dimension and how it is made (joints × window samples, PCA, physics terms)."""

    name: str
    dim: int
    description: str
    joints: tuple[str, ...] = ()
    samples: int = 1
    pca_components: int = 0
    physics_terms: int = 0

    @property
    def needs_fit(self) -> bool:
        return self.pca_components > 0

    def window_frames(self, fps: float) -> int:
        """Least frames a query needs (the window's span + 1; 1 for frame sets)."""
        return window_frames(self.samples, fps)


def _joint_spec(name: str, joints: tuple[str, ...], samples: int = 1) -> FeatureSpec:
    what = f"positions of {', '.join(joints)} in the body frame"
    if samples > 1:
        what += f", {samples} samples over the {WINDOW_SECONDS} s ending at each frame"
    return FeatureSpec(name, 3 * len(joints) * samples, what, joints, samples)


FEATURE_SETS: dict[str, FeatureSpec] = {spec.name: spec for spec in (
    _joint_spec("E15", E15_JOINTS), _joint_spec("E30", E30_JOINTS), _joint_spec("E39", E39_JOINTS),
    _joint_spec("E15x3", E15_JOINTS, 3), _joint_spec("E15x5", E15_JOINTS, 5),
    _joint_spec("E30x3", E30_JOINTS, 3), _joint_spec("E39x3", E39_JOINTS, 3),
    *(FeatureSpec(f"pca{n}", n, f"first {n} principal components of the 21 body-frame joint positions",
                  pca_components=n) for n in (8, 16, 25)),
    FeatureSpec("EP17", 17, "E15 + COM acceleration along +Y (×Δt²) + angular momentum about +Y (×Δt)",
                E15_JOINTS, physics_terms=2),
    FeatureSpec("EP19", 19, "EP17 + COM acceleration along the direction of motion and angular momentum about "
                "the axis ⟂ to it and gravity", E15_JOINTS, physics_terms=4),
)}


def feature_names() -> list[str]:
    """Names of all feature sets, in registry order."""
    return list(FEATURE_SETS)


def feature_spec(name: str) -> FeatureSpec:
    """The spec of feature set ``name``; ValueError listing the valid names otherwise."""
    if name not in FEATURE_SETS:
        raise ValueError(f"unknown feature set {name!r}; valid: {feature_names()}")
    return FEATURE_SETS[name]


def fit_features(name: str, takes: Sequence[np.ndarray], fps: float, normalization: str = "3d") -> FittedPCA | None:
    """What feature set ``name`` learns from a database (a :class:`FittedPCA` for ``pca*``, else None)."""
    spec = feature_spec(name)
    return fit_pca(takes, fps, spec.pca_components, normalization) if spec.needs_fit else None


def _check_fps(fps: float) -> float:
    if isinstance(fps, bool) or not isinstance(fps, (int, float, np.number)) or not math.isfinite(fps) or fps <= 0:
        raise ValueError(f"fps must be a positive finite number, got {fps!r}")
    return float(fps)


def compute_features(
    name: str, positions: np.ndarray, fps: float, fitted: FittedPCA | None = None,
    normalization: str = "3d", allow_short: bool = False,
) -> np.ndarray:
    """Feature set ``name`` of one continuous take.

    Args:
        name: a key of :data:`FEATURE_SETS`.
        positions: ``(frames, 21, 3)`` canonical positions, metres, Y up.
        fps: frames per second of ``positions``.
        fitted: the database's :class:`FittedPCA` (required by ``pca*`` sets, ignored otherwise).
        normalization: ``"3d"`` or ``"2d"`` (module docstring); a PCA's own normalization wins.
        allow_short: accept a take shorter than a windowed set's window (its early frames clamp to the
            first frame, as every take's first frames do); off for queries, on for database takes.

    Returns:
        ``(frames, spec.dim)`` float32.

    Raises:
        ValueError: an unknown name (listing the valid ones), a query shorter than the window (naming
            both frame counts), a missing or mismatched PCA, bad shapes or fps.
    """
    spec = feature_spec(name)
    fps = _check_fps(fps)
    _check_normalization(normalization)
    positions = checked_positions(positions)
    need = spec.window_frames(fps)
    if not allow_short and positions.shape[0] < need:
        raise ValueError(f"feature set {name} needs at least {need} frames ({WINDOW_SECONDS} s at {fps:g} fps), "
                         f"the query has {positions.shape[0]}")
    return _COMPUTE[_kind(spec)](spec, positions, fps, fitted, normalization).astype(np.float32)


def _kind(spec: FeatureSpec) -> str:
    return "pca" if spec.needs_fit else "physics" if spec.physics_terms else "joints"


def _compute_joints(spec: FeatureSpec, positions: np.ndarray, fps: float, fitted: FittedPCA | None,
                    normalization: str) -> np.ndarray:
    frame = joint_features(positions, fps, spec.joints, normalization)
    return frame if spec.samples == 1 else stack_window(frame, window_offsets(spec.samples, fps))


def _compute_pca(spec: FeatureSpec, positions: np.ndarray, fps: float, fitted: FittedPCA | None,
                 normalization: str) -> np.ndarray:
    if fitted is None:
        raise ValueError(f"feature set {spec.name} needs a PCA fitted on the database (fit_features), got None")
    if fitted.n_components != spec.pca_components:
        raise ValueError(f"feature set {spec.name} needs a {spec.pca_components}-component PCA, "
                         f"got {fitted.n_components} components")
    return fitted.transform(_flat_body_positions(positions, fps, fitted.normalization))


def _compute_physics(spec: FeatureSpec, positions: np.ndarray, fps: float, fitted: FittedPCA | None,
                     normalization: str) -> np.ndarray:
    frame = joint_features(positions, fps, spec.joints, normalization)
    return np.concatenate([frame, physics_terms(positions, fps, spec.physics_terms)], axis=1)


_COMPUTE: dict[str, Callable[..., np.ndarray]] = {
    "joints": _compute_joints, "pca": _compute_pca, "physics": _compute_physics,
}
