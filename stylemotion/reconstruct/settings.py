"""The settings of ``stylemotion-reconstruct``, ``stylemotion-texture`` and ``stylemotion-keyframes``: every key
of ``configs/{reconstruct,texture,keyframes}.yaml`` and its one default.

Each YAML takes its dataclass as its structured config (``- schema@_here_: reconstruct``,
:mod:`stylemotion.cli.schemas`) and repeats no value; the library's defaults read them (the keyword defaults of
:class:`~stylemotion.reconstruct.sparse.SparseReconstructor`, :class:`~stylemotion.reconstruct.texture.MotionTexturer`,
:class:`~stylemotion.reconstruct.keyframes.DynamicMotionGraph` and of the three command functions). This module
imports no numpy or torch, so the commands' ``--help`` stays fast.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from omegaconf import MISSING

from stylemotion.config import MotionFileKeys

#: The local model's prior weight for markers at the joint centres: suite ``reconstruct``'s choice, with k, on Bandai
#: val takes among 1, 3, 10, 30 (set on synthetic data before; benchmarks/reconstruct.md, block ``reconstruct/choice``).
JOINT_CENTRE_PRIOR_WEIGHT = 1.0
#: The same for skin-marker sets: suite ``markers``' choice on the val takes of a style left out of the database
#: (benchmarks/reconstruct.md, ``benchmarks/results/markers.json``).
SKIN_PRIOR_WEIGHT = 30.0


@dataclass(frozen=True)
class SparseModelSettings:
    """The pose model of ``stylemotion-reconstruct`` (:class:`~stylemotion.reconstruct.sparse.SparseReconstructor`).

    ``variance``: fraction of the neighbours' spread the local PCA keeps; ``marker_sd``: metres a marker may miss
    by; ``smooth_sd``: metres a joint may move between frames (body frame); ``prior_weight``: weight of the
    Mahalanobis prior of the local PCA; ``iterations``: k-NN searches per frame for E30/E39/pca* (searched
    around the synthesized pose); ``weighted``: neighbours weighted by ``1/(feature distance + marker_sd)^2``;
    ``hold_bones``: every output frame's bones set to the subject's lengths (constant over time).
    ``prior_weight`` None: :data:`JOINT_CENTRE_PRIOR_WEIGHT` for markers at the joint centres,
    :data:`SKIN_PRIOR_WEIGHT` for skin-marker sets.
    """

    variance: float = 0.99
    marker_sd: float = 0.002
    smooth_sd: float = 0.1
    prior_weight: float | None = None
    iterations: int = 1
    weighted: bool = True
    hold_bones: bool = True


@dataclass(frozen=True)
class ReconstructSettings(MotionFileKeys):
    """Every key of ``stylemotion-reconstruct`` (besides ``data``), with its default.

    ``markers``: ``BVH[:start-end]`` | NPZ (as ``stylemotion-convert`` writes) | CSV of marker tracks
    (``frame,<marker>_x,<marker>_y,<marker>_z,…`` metres, Y up, any rate: resampled) | C3D | a take of the
    dataset. ``joints``: the markers at joint centres; None = ``[Hand_L,Hand_R,Foot_L,Foot_R,Head,Hips]`` (a CSV:
    its columns). ``marker_set``: None/``joints`` (markers at the joint centres ``joints``), ``skin`` (the default
    skin-marker set, docs/reconstruct.md) or a CSV ``name,segment,x,y,z``; a C3D needs a skin set, a BVH/NPZ/take
    gets the set's markers put on virtually. ``marker_names``: set marker → the file's label (C3D, default the
    same name). ``markers_fps``: a CSV's rate when it has no ``# fps:`` line (default the dataset's).
    ``markers_up_axis``: a C3D's up axis (``z`` or ``y``). ``subject``: whose bones the database is put on and the
    output holds: ``database`` (its own), ``markers`` (scaled to the subject from the markers) or a BVH of the
    subject's skeleton (bone lengths, rigid bones and feet measured on it: a calibration). ``features``: k-NN
    feature set (E15 E30 E39 E15x3 E15x5 pca8 pca16 pca25). ``k``: neighbours of the local linear model per
    frame; chosen on Bandai val takes (suite reconstruct, docs/reconstruct.md). ``noise_mm``: uniform noise of
    ± ``noise_mm`` millimetres added to the markers (thesis: 1); ``seed``: of that noise.
    ``exclude_markers_take``: markers= a take of the dataset: leave it out of the database.
    ``model``: :class:`SparseModelSettings`.
    ``joint_map``, ``unit_scale``, ``up_axis``: a BVH's (:class:`~stylemotion.config.MotionFileKeys`). ``out``:
    a new folder (an existing one is refused unless ``force``). ``gif``: also ``out/motion.gif`` (the stick
    figure along its ground track).
    """

    markers: str = MISSING
    joints: list[str] | None = None
    marker_set: str = "joints"
    marker_names: dict[str, str] | None = None
    markers_fps: float | None = None
    markers_up_axis: str = "z"
    subject: str = "database"
    features: str = "E15"
    k: int = 512
    noise_mm: float = 0.0
    seed: int = 0
    exclude_markers_take: bool = True
    model: SparseModelSettings = field(default_factory=SparseModelSettings)
    out: str = "runs/reconstruct/${now:%Y-%m-%d_%H-%M-%S}"
    force: bool = False
    gif: bool = True


@dataclass(frozen=True)
class TextureModelSettings:
    """The texturer of ``stylemotion-texture`` (:class:`~stylemotion.reconstruct.texture.MotionTexturer`).

    ``top``: LNG segments per frame in the prior; ``lng_window``: frames of the online LNG's window;
    ``samples``: feature window samples; ``feature_seconds``: feature window length; ``distance_sd``: metres
    added to a segment's mean feature distance in its weight; ``cleanup``: foot-skating clean-up at the end;
    ``weights``: pose/motion/smooth/control (the defaults per mode are ``texture.DEFAULT_WEIGHTS``).
    """

    top: int = 2
    lng_window: int = 8
    samples: int = 3
    feature_seconds: float = 0.2
    distance_sd: float = 0.002
    cleanup: bool = True
    weights: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class TextureSettings(MotionFileKeys):
    """Every key of ``stylemotion-texture`` (besides ``data``), with its default.

    ``motion``: ``BVH[:start-end]`` | NPZ (as ``stylemotion-convert`` writes; NaN allowed in untrusted joints for
    complete) | a take of the dataset. ``mode``: complete (synthesize the untrusted joints) | texture (weak
    control on all joints). ``joints``: trusted joints; None = hips and legs (complete) / every joint (texture).
    ``k``: nearest database frames per frame fed to the online LNG. ``exclude_motion_take``: motion= a take of
    the dataset: leave it out of the database. ``model``: :class:`TextureModelSettings`. ``joint_map``,
    ``unit_scale``, ``up_axis``: a BVH's. ``out``: a new folder (an existing one is refused unless ``force``).
    ``gif``: also ``out/motion.gif`` (the stick figure along its ground track).
    """

    motion: str = MISSING
    mode: str = "complete"
    joints: list[str] | None = None
    k: int = 32
    exclude_motion_take: bool = True
    model: TextureModelSettings = field(default_factory=TextureModelSettings)
    out: str = "runs/texture/${now:%Y-%m-%d_%H-%M-%S}"
    force: bool = False
    gif: bool = True


@dataclass(frozen=True)
class DynamicGraphSettings:
    """The dynamic motion graph of ``stylemotion-keyframes``
    (:class:`~stylemotion.reconstruct.keyframes.DynamicMotionGraph`).

    ``k``: nearest database frames per expanded node (E15); ``b``: nodes expanded per tree and iteration;
    ``max_iterations``: iterations before two keys are given up; ``voxel_m``: spatial hash voxel of the Hips
    (thesis: 10 cm); ``min_segment_frames``: shortest segment (a segment runs to the next change of foot
    contact); ``max_segment_s``: longest segment; ``max_turn_deg``: connection: facings within this;
    ``max_pose_m``: connection: body-frame hands, feet and head within this (mean); ``max_velocity_m_s``:
    connection: body-frame root velocities within this; ``blend_frames``: frames blended at a connection;
    ``duration_weight``: price of a frame of timing error, in median frames of motion (0: thesis), chosen on
    Bandai val key pairs (suite reconstruct, docs/reconstruct.md); ``facing_weight_m``: D_node's facing term,
    metres per radian (0: thesis); ``turn_radius_m``: D_node measures the way from an outgoing node to an incoming
    one as the shortest forward walk turning no tighter than this radius, metres (0: eq. 4.12, the thesis, with the
    facing term); chosen with ``max_iterations`` on Bandai val takes' turned keys (suite moved_keys,
    docs/reconstruct.md); ``facing_first_iterations``: with ``turn_radius_m > 0``, iterations of eq. 4.12's search
    (with the facing term) tried first, the turn-aware search only when its trees do not meet (0: the turn-aware
    search alone); chosen on Bandai val takes' turned and straight keys (suite moved_keys); ``retime``: resample
    each key pair to the keys' times; ``clean``: motion texturing of the result with the keys pinned (§4.3.4).
    """

    k: int = 16
    b: int = 4
    max_iterations: int = 24
    voxel_m: float = 0.1
    min_segment_frames: int = 4
    max_segment_s: float = 1.0
    max_turn_deg: float = 30.0
    max_pose_m: float = 0.15
    max_velocity_m_s: float = 0.6
    blend_frames: int = 10
    duration_weight: float = 30.0
    facing_weight_m: float = 1.0
    turn_radius_m: float = 1.0
    facing_first_iterations: int = 12
    retime: bool = True
    clean: bool = True


@dataclass(frozen=True)
class KeyframesSettings(MotionFileKeys):
    """Every key of ``stylemotion-keyframes`` (besides ``data``), with its default.

    ``keys``: a JSON file ``{"keys": [{"time": s, "take"|"motion": ..., "frame": i} | {"time": s, "positions":
    [[x,y,z] x 21]}, ...]}`` or ``{"motion": ..., "every_s": 2.0}``. ``exclude_key_takes``: leave the dataset
    takes the keys come from out of the database. ``model``: :class:`DynamicGraphSettings`. ``joint_map``,
    ``unit_scale``, ``up_axis``: a BVH's. ``out``: a new folder (an existing one is refused unless ``force``).
    ``gif``: also ``out/motion.gif`` (the stick figure, keys marked).
    """

    keys: str = MISSING
    exclude_key_takes: bool = True
    model: DynamicGraphSettings = field(default_factory=DynamicGraphSettings)
    out: str = "runs/keyframes/${now:%Y-%m-%d_%H-%M-%S}"
    force: bool = False
    gif: bool = True
