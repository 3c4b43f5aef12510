"""Settings of an evaluation, one dataclass per config node: the defaults live here only.

The ``evaluation`` config node (``configs/evaluation/default.yaml``) is built from
:class:`EvalSettings` (registered as a Hydra structured config by :mod:`stylemotion.config`), so its
keys are these field names, typed and checked; the YAML file holds only what differs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from stylemotion.config import ConfigError
from stylemotion.primitives.segmentation import SegmentSettings
from stylemotion.primitives.skating import SKATE_SPEED_MPS

#: The data splits that may be held out of the models (the default: both).
HELDOUT_SPLITS = ("val", "test")
#: A style model's ground truth (``EvalSettings.style_truth``): every clip of its style but its example, or the
#: held-out splits' clips only.
STYLE_TRUTHS = ("all", "heldout")


@dataclass
class SampleCounts:
    """Samples drawn per model.

    Attributes:
        table_5_1: N of Table 5.1 (eq. 5.12; 1000 in the thesis).
        variance: samples for pose_SD, V_SD, step_SD (eq. 5.13–5.15; 10,000 in the thesis).
        metrics: samples for the classifier share, Fréchet distance, diversity, foot skating and
            nearest training clip.
    """

    table_5_1: int = 1000
    variance: int = 10000
    metrics: int = 1000


@dataclass
class ClassifierSettings:
    """The style classifier (PCA + logistic regression) whose space hosts Fréchet and diversity.

    Attributes:
        components: PCA dimensions of its feature space.
        C: inverse L2 strength of the logistic regression.
    """

    components: int = 32
    C: float = 1.0


@dataclass
class WindowSettings:
    """Test windows of the autoencoder's reconstruction error.

    Attributes:
        window_frames: frames per window.
        stride: frames between window starts.
    """

    window_frames: int = 60
    stride: int = 30


@dataclass
class EvalSettings:
    """Sample counts and metric settings of an evaluation.

    Attributes:
        samples: samples per model for each table (:class:`SampleCounts`).
        neutral_style: the data's neutral style label (the neutral VAE's content).
        classifier: the style classifier (:class:`ClassifierSettings`).
        skate_speed_mps: planted-point speed above which a contact foot skates, m/s.
        diversity_items: motions used at most by the diversity (pairs grow as n²).
        gram_chunk: motions encoded at once for the Gram matrices of Table 5.1.
        autoencoder_test: windows of the autoencoder's test error (:class:`WindowSettings`).
        segment: segmentation settings, as for training.
        shift_baseline: add, per style example, the row ``shift:<style>`` to Tables 5.1–5.3: a neutral VAE sample
            plus (example − neutral mean) in the autoencoder's feature space
            (:class:`stylemotion.evaluation.pipeline.ShiftBaseline`).
        heldout_splits: the splits whose clips count as held out: the classifier's held-out accuracy, the
            neutral model's ground truth and, with the train clips, a style model's ground truth
            (:meth:`stylemotion.evaluation.reference.PrimitiveData.ground_truth`). ``[val]`` reads no test clip
            there: a choice made on the report then reads validation clips only (suite ``style_channels``).
        style_truth: a style model's ground truth: ``all`` (every clip of its style but its example: the train
            clips and the held-out splits', the thesis' way) or ``heldout`` (the held-out splits' clips only, so
            ``heldout_splits=[test]`` reads no clip a choice made on ``[val]`` read).
        seed: sampling seed (every model is sampled with it) and classifier seed; set from the
            command's top-level ``seed``.
    """

    samples: SampleCounts = field(default_factory=SampleCounts)
    neutral_style: str = "normal"
    classifier: ClassifierSettings = field(default_factory=ClassifierSettings)
    skate_speed_mps: float = SKATE_SPEED_MPS
    diversity_items: int = 2000
    gram_chunk: int = 256
    autoencoder_test: WindowSettings = field(default_factory=WindowSettings)
    segment: SegmentSettings = field(default_factory=SegmentSettings)
    shift_baseline: bool = True
    heldout_splits: list[str] = field(default_factory=lambda: list(HELDOUT_SPLITS))
    style_truth: str = "all"
    seed: int = 0

    def __post_init__(self) -> None:
        parts = list(self.heldout_splits)
        if not parts or len(set(parts)) != len(parts) or not set(parts) <= set(HELDOUT_SPLITS):
            raise ConfigError(f"evaluation.heldout_splits must be a non-empty list of distinct splits out of "
                              f"{list(HELDOUT_SPLITS)}, got {parts}")
        if self.style_truth not in STYLE_TRUTHS:
            raise ConfigError(f"evaluation.style_truth must be one of {list(STYLE_TRUTHS)}, got {self.style_truth!r}")
        counts = self.samples
        for name in ("table_5_1", "variance", "metrics"):
            value = getattr(counts, name)
            if value < 2:
                raise ConfigError(f"evaluation.samples.{name} must be at least 2 (samples per model), got {value}")
