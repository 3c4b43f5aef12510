"""The settings of ``stylemotion-annotate``: every key of ``configs/annotate.yaml`` and its one default.

``configs/annotate.yaml`` takes :class:`AnnotateSettings` as its structured config (``- schema@_here_: annotate``,
:mod:`stylemotion.cli.schemas`) and repeats no value; the library's defaults read it
(:class:`stylemotion.annotate.annotation.AnnotationSettings`, :func:`stylemotion.annotate.command.learn`). This
module imports no numpy or torch, so ``stylemotion-annotate --help`` stays fast.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from stylemotion.config import MotionFileKeys


@dataclass(frozen=True)
class KeyframeSettings:
    """Key-frame preselection (drops hits without the class's key poses in order).

    ``use``: on or off; on documents of Bandai val takes off ties with on at tolerance 0.2, and the simpler
    setting wins. ``count``: key frames per class (not tuned). ``tolerance``: fraction of a key frame's
    consistent features a matching frame may contradict (the best on val among the tolerances with key frames
    on)."""

    use: bool = False
    count: int = 3
    tolerance: float = 0.2


@dataclass(frozen=True)
class AnnotateSettings(MotionFileKeys):
    """Every key of ``stylemotion-annotate`` (besides ``data``), with its default.

    ``document``: ``<BVH>[:start-end]`` (frames of the file's rate; also ``archive.zip::member.bvh``); None =
    learn templates from ``data`` into ``out``. ``templates``: a folder written by the learning run (needed
    with ``document``).

    Learning: ``per_class``: train takes per content averaged into its template (thesis: 9); ``seed``: which
    train takes are drawn; ``tensors``: also build a class motion tensor per content (styles × repetitions);
    ``repetitions``: train takes per style in a tensor (drawn with ``seed``), None = as many as every style has
    (chosen on Bandai val walk takes by ``python scripts/benchmarks.py run annotate``).

    Annotating (``tau``, ``keyframes.use``/``tolerance``, ``min_run``, ``sub_frames``, ``turning_z`` and
    ``turning_window_s`` chosen together on documents of Bandai val takes, whole and cut to 2–3 s, by
    ``python scripts/benchmarks.py run annotate``; benchmarks/annotate.md has the test figures):
    ``tau``: matching threshold τ of the masked template distance (the thesis used 0.13 with its features; our
    masked costs are smaller); ``keyframes``: :class:`KeyframeSettings`; ``min_run``: labelled runs shorter than
    this (frames) are left unlabelled, 0 = the thesis as is; ``sub_frames``: each class template is matched as
    half-overlapping windows of this many frames (§3.3's sub-templates), so parts shorter than half a template
    (a 2-s walk) can be found; 0 = whole templates; ``turning_z``: the turning layer (``stylemotion.annotate.turning``):
    a run goes to the class of its template family whose train takes' mean turning rate is nearest its own, among
    the classes whose mean rates lie at least ``turning_z`` × (sd + sd) from its class's (a straight walk labelled
    ``walk-turn-left`` becomes ``walk``); 0 = off; ``turning_window_s``: the layer decides runs in pieces of about
    this many seconds (0: whole runs).

    ``feature_set``: the relational features of the templates (:mod:`stylemotion.annotate.feature_sets`):
    ``ours`` (42 features, :mod:`~stylemotion.annotate.features`) or ``mueller_roeder`` (Müller & Röder's 39 with
    hysteresis, and Krüger's root angular velocity); None = ``ours`` when learning and the templates folder's set
    when annotating (naming another set than the folder's is refused). benchmarks/annotate.md compares the two.

    ``joint_map``, ``unit_scale``, ``up_axis``: the document's (:class:`~stylemotion.config.MotionFileKeys`).
    ``out``: a new folder (an existing one is refused unless ``force``).
    """

    document: str | None = None
    templates: str | None = None
    per_class: int = 9
    seed: int = 0
    tensors: bool = True
    repetitions: int | None = None
    tau: float = 0.08
    keyframes: KeyframeSettings = field(default_factory=KeyframeSettings)
    min_run: int = 30
    sub_frames: int = 0
    turning_z: float = 1.0
    turning_window_s: float = 4.0
    feature_set: str | None = None
    out: str = "runs/annotate/${now:%Y-%m-%d_%H-%M-%S}"
    force: bool = False
