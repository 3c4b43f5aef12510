"""One evaluation: models × real data → the plain-valued results a report is written from.

:func:`evaluate_models` takes :class:`~stylemotion.models.loading.EvalModel`s (loaded from
checkpoints or any :class:`~stylemotion.models.loading.SampleSource`), the dataset they were
trained on and the autoencoder they share, and computes per primitive:

* Table 5.1 (:mod:`.tables`) on ``samples.table_5_1`` samples per model;
* Tables 5.2/5.3 on ``samples.variance`` samples per model, plus the training data and every real
  style for reference;
* the style classifier's held-out accuracy and confusion, and the share of each model's samples
  it assigns to the model's style (:mod:`.classifier`);
* Fréchet distance, diversity, foot skating and nearest-training-clip distance on
  ``samples.metrics`` samples per model (:mod:`.metrics`), each against the model's ground truth
  (:meth:`.reference.PrimitiveData.ground_truth`);

and, once, the autoencoder's reconstruction error on the data's test split. With ``settings.shift_baseline`` and
a neutral VAE, each style example (Table 5.1 column) adds the row ``shift:<column>`` (:class:`ShiftBaseline`).
``extra_rows`` adds row-only
sources (e.g. the Morphable Graph's neutral models): sampled like the models, they get rows in Tables
5.2/5.3 and a row of distances to the models' examples in Table 5.1 (``table_5_1.<p>.extra_rows``), no column
and no other metric. Every model is sampled
once, with the same seed, and that draw serves every metric. Per primitive the data is segmented
and split once (:func:`real_side`: clips, classifier, ground truths), then each metric family is
one function returning a small dataclass (:func:`real_variance`, :func:`recognition`,
:func:`distribution`, :func:`skating`, :func:`style_table`). The result is a JSON-able dict
(layout: ``docs/report.md``).
"""

from __future__ import annotations

import logging
import math
import time
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import torch

from stylemotion.datamodules.features import encode_examples, encode_frames
from stylemotion.datamodules.windows import MotionWindowDataModule
from stylemotion.datasets import TakeSet
from stylemotion.evaluation.classifier import StyleClassifier, predicted_shares
from stylemotion.evaluation.metrics import (
    FootSkating,
    diversity,
    foot_skating,
    frechet_distance,
    nearest_distances,
    pooled_skating,
    pose_sequences,
)
from stylemotion.evaluation.reference import PrimitiveData, primitive_data
from stylemotion.evaluation.settings import EvalSettings
from stylemotion.evaluation.sources import (
    EvaluationInputError,
    MissingExampleError,
    check_one_autoencoder,
    motions_from_clips,
)
from stylemotion.evaluation.tables import diagonal_minima, distance_table, example_gram, mean_motion, variance_stats
from stylemotion.models.autoencoder import local_mpjpe, mpjpe
from stylemotion.models.loading import NEUTRAL, EvalModel
from stylemotion.models.sampling import MotionSamples, decode_features
from stylemotion.models.style import mean_gram
from stylemotion.primitives.actions import segment_action
from stylemotion.primitives.segmentation import Segmentation, parse_primitive, time_normalize
from stylemotion.primitives.stance import stance_travel

log = logging.getLogger(__name__)

#: Largest relative Frobenius difference accepted between a style model's recorded example Gram and
#: the Gram of its example clip recomputed from the evaluation data.
GRAM_TOLERANCE = 1e-3


def evaluate_models(models: Sequence[EvalModel], takeset: TakeSet, autoencoder, settings: EvalSettings | None = None,
                    split: Mapping[str, Any] | None = None, autoencoder_info: Mapping[str, Any] | None = None,
                    extra_rows: Mapping[str, Mapping[str, Any]] | None = None) -> dict[str, Any]:
    """Evaluate models against real data (see the module doc).

    Args:
        models: the models; at most one per (primitive, name).
        takeset: the dataset they were trained on.
        autoencoder: the frozen autoencoder they share (``encode``/``decode``, ``hparams``).
        settings: sample counts and metric settings.
        split: the data's split settings (as for training).
        autoencoder_info: ``path``/``fingerprint`` of the autoencoder (checked against the models).
        extra_rows: ``{primitive: {row name: SampleSource}}`` rows of Tables 5.1–5.3 only (module doc).

    Returns:
        The results (JSON-able), without ``meta``.

    Raises:
        ValueError: no model, two models of one primitive and name, a style not in the data, or
            different timelines within one primitive.
        MixedAutoencodersError: models trained on different autoencoders.
        MissingExampleError: a style model without (or with a mismatching) example clip.
    """
    settings = settings or EvalSettings()
    if not models:
        raise EvaluationInputError("no model to evaluate")
    fp = None if autoencoder_info is None else autoencoder_info.get("fingerprint")
    check_one_autoencoder(models, fp)
    by_primitive: dict[str, list[EvalModel]] = defaultdict(list)
    for m in models:
        if any(o.name == m.name for o in by_primitive[m.primitive]):
            raise EvaluationInputError(f"two models of {m.label}: evaluate one model per primitive and style")
        if m.dataset is not None and m.dataset != takeset.name:
            raise EvaluationInputError(f"{m.checkpoint or m.label} was trained on dataset {m.dataset!r}, "
                                       f"not {takeset.name!r}")
        by_primitive[m.primitive].append(m)
    extra_rows = {p: dict(rows) for p, rows in (extra_rows or {}).items() if rows}
    for p, rows in extra_rows.items():
        clash = sorted(set(rows) & ({m.name for m in by_primitive.get(p, [])} | {"training_data"}))
        if p not in by_primitive or clash:
            raise EvaluationInputError(f"extra rows {sorted(rows)} of {p}: " + (
                f"names {clash} are taken" if clash else
                "no VAE/CVAE of that primitive is evaluated (such rows stand beside one)"))
    results: dict[str, Any] = {key: {} for key in (
        "table_5_1", "variance", "variance_ratio", "variance_real", "variation_vs_style", "frechet",
        "frechet_reference", "diversity", "foot_skating_detail", "stance_travel", "nearest_training")}
    recognition: dict[str, Any] = {"per_primitive": {}, "per_model_detail": {}}
    skating: dict[str, list] = defaultdict(list)
    skating_real: dict[str, list] = defaultdict(list)
    shares: dict[str, list[tuple[float, int]]] = defaultdict(list)
    log.info("autoencoder: reconstruction error on the test split")
    results["autoencoder"] = autoencoder_test_error(autoencoder, takeset, split, settings)
    if autoencoder_info is not None:
        results["autoencoder"].update(path=autoencoder_info.get("path"),
                                      fingerprint=autoencoder_info.get("fingerprint"))
    segmentations: dict[str, Segmentation] = {}  # the takes of each action are segmented once
    for primitive in sorted(by_primitive):
        action = parse_primitive(primitive)[0]
        if action not in segmentations:
            segmentations[action] = segment_action(takeset.takes, action, settings.segment)
        out = _evaluate_primitive(primitive, by_primitive[primitive], takeset, autoencoder, settings, split,
                                  segmentations[action], extra_rows.get(primitive))
        for key in results:
            if key in out:
                results[key][primitive] = out[key]
        if out["extra_rows"]:
            results.setdefault("extra_rows", {})[primitive] = out["extra_rows"]
        recognition["per_primitive"][primitive] = out["classifier"]
        recognition["per_model_detail"][primitive] = out["recognition"]
        for name, rec in out["recognition"].items():
            shares[name].append((rec["share"], rec["samples"]))
        for name, rec in out["skating"].items():
            skating[name].append(rec["samples"])
            skating_real[name].append(rec["real"])
    correct = sum(r["heldout_accuracy"] * r["heldout_clips"] for r in recognition["per_primitive"].values())
    total = sum(r["heldout_clips"] for r in recognition["per_primitive"].values())
    recognition["classifier_heldout_accuracy"] = correct / total if total else float("nan")
    recognition["chance"] = float(np.mean([r["chance"] for r in recognition["per_primitive"].values()]))
    recognition["per_model"] = {n: sum(s * k for s, k in v) / sum(k for _, k in v) for n, v in shares.items()}
    results["style_recognition"] = recognition
    results["foot_skating"] = {n: pooled_skating(v).ratio for n, v in skating.items()}
    results["foot_skating_real"] = {n: pooled_skating(v).ratio for n, v in skating_real.items()}
    results["primitives"] = sorted(by_primitive)
    extra = results.pop("extra_rows", {})
    if extra:
        results["extra_rows"] = extra
    results["models"] = [{"name": m.name, "primitive": m.primitive, "style": m.style, "kind": m.kind,
                          "checkpoint": m.checkpoint, "examples": m.examples}
                         for p in sorted(by_primitive) for m in by_primitive[p]]
    return results


@torch.no_grad()
def autoencoder_test_error(autoencoder, takeset: TakeSet, split: Mapping[str, Any] | None,
                           settings: EvalSettings) -> dict[str, Any]:
    """MPJPE (m) of the autoencoder's reconstructions of the test split's windows.

    ``test_mpjpe_m``: positions integrated from the origin for both (root drift counts);
    ``test_local_mpjpe_m``: root-local poses only (see :mod:`stylemotion.models.autoencoder`).
    """
    windows = settings.autoencoder_test
    dm = MotionWindowDataModule(takeset=takeset, window_frames=windows.window_frames, stride=windows.stride,
                                split=dict(split or {}), eval_batch_size=256)
    dm.setup("test")
    fps = float(takeset.fps)
    total = local = 0.0
    count = 0
    for batch in dm.test_dataloader():
        recon = autoencoder(batch)
        total += float(mpjpe(recon, batch, fps)) * len(batch)
        local += float(local_mpjpe(recon, batch)) * len(batch)
        count += len(batch)
    return {"test_mpjpe_m": total / count, "test_local_mpjpe_m": local / count, "test_windows": count,
            "window_frames": settings.autoencoder_test.window_frames, "data": takeset.name}


def _segment_values(settings: EvalSettings) -> dict[str, Any]:
    """The evaluation's segmentation settings as plain values (what the DataModules take)."""
    return asdict(settings.segment)


def _order(models: Sequence[EvalModel], styles: Sequence[str]) -> list[EvalModel]:
    """Neutral first, then style models in the data's style order (per style a CVAE before a zero-shot network)."""
    rank = {s: i for i, s in enumerate(styles)}
    return sorted(models, key=lambda m: (m.name != NEUTRAL, rank.get(m.style, len(rank)), m.kind == "zero_shot",
                                         m.name))


def _example_clips(data: PrimitiveData, model: EvalModel) -> list:
    if model.name == NEUTRAL:
        return []
    if model.example_clips is not None:  # a user's recording, not a clip of the data
        return list(model.example_clips)
    if not model.examples:
        raise MissingExampleError(f"style model {model.checkpoint or model.label} records no style example clip, so "
                                  "Table 5.1 has no column for it; was it trained as a StyleCVAE with a style?")
    return [data.find_example(record) for record in model.examples]


# ---------------------------------------------------------------------------------------------
# The real side of one primitive, prepared once


@dataclass
class RealSide:
    """Everything real that the metrics of one primitive compare with, converted once.

    Attributes:
        data: the primitive's segmented, split clips.
        models: the models, neutral first, then in the data's style order.
        examples: each model's style example clips (empty for the neutral model).
        classifier: the style classifier fitted on the train split of every style.
        classifier_result: its held-out accuracy and confusion (``report.json`` layout).
        training: the neutral train-split clips (the training data).
        heldout_neutral: the neutral held-out clips (``settings.heldout_splits``: val + test by default).
        truth: each model's ground truth clips (its style, never seen by it).
    """

    data: PrimitiveData
    models: list[EvalModel]
    examples: dict[str, list]
    classifier: StyleClassifier
    classifier_result: dict[str, Any]
    training: MotionSamples
    heldout_neutral: MotionSamples
    truth: dict[str, MotionSamples]

    @property
    def length(self) -> int:
        return self.data.length

    def features(self, motions: MotionSamples) -> np.ndarray:
        """``(n, d)`` the classifier's feature space of ``motions``."""
        return self.classifier.features(motions.normalized_frames.numpy(), motions.duration_s.numpy())


def _canonical_length(primitive: str, models: Sequence[EvalModel], takeset: TakeSet, settings: EvalSettings,
                      split: Mapping[str, Any] | None, segmentation: Segmentation | None = None) -> int:
    """The models' (one) canonical timeline; for sources without one, the median neutral train clip."""
    lengths = {m.timeline_frames for m in models if m.timeline_frames is not None}
    if len(lengths) > 1:
        raise EvaluationInputError(f"the models of {primitive} use different canonical timelines {sorted(lengths)}: "
                                   "they were trained on different data")
    if lengths:
        return lengths.pop()
    probe = primitive_data(takeset, primitive, 2, settings.neutral_style, _segment_values(settings), split,
                           segmentation)
    return int(round(float(np.median([c.num_frames for c in probe.training_data()]))))


def real_side(primitive: str, models: Sequence[EvalModel], takeset: TakeSet, settings: EvalSettings,
              split: Mapping[str, Any] | None, segmentation: Segmentation | None = None) -> RealSide:
    """Split the (segmented) data for ``primitive``, fit the style classifier, gather the ground truths.

    ``segmentation``: the primitive's action already segmented with ``settings.segment``
    (:func:`stylemotion.primitives.actions.segment_action`), shared by the primitives of one evaluation;
    None segments here.

    Raises:
        MissingExampleError: a model's style is not in the data, or its example clip is missing.
        ValueError: a model has fewer than 2 ground-truth clips.
    """
    length = _canonical_length(primitive, models, takeset, settings, split, segmentation)
    log.info(f"{primitive}: real clips")
    data = primitive_data(takeset, primitive, length, settings.neutral_style, _segment_values(settings), split,
                          segmentation, settings.heldout_splits, settings.style_truth)
    for m in models:
        if m.style not in data.styles:
            raise MissingExampleError(f"{m.checkpoint or m.label} models style {m.style!r}, which dataset "
                                      f"{takeset.name!r} does not have (styles: {data.styles}): no example, no "
                                      "ground truth")
    ordered = _order(models, data.styles)
    examples = {m.name: _example_clips(data, m) for m in ordered}
    for m in ordered:  # a zero-shot network samples once bound to the clips found here
        m.bind(examples[m.name])
    truth = {}
    for m in ordered:
        clips = data.ground_truth(m, examples[m.name])
        if len(clips) < 2:
            raise EvaluationInputError(f"{m.label}: fewer than 2 real clips of style {m.style!r} besides its example; "
                                       "the metrics need ground truth")
        truth[m.name] = motions_from_clips(clips, length)
    log.info(f"{primitive}: style classifier on {len(data.split('train'))} real train clips")
    classifier, result = fit_style_classifier(data, settings)
    return RealSide(data, ordered, examples, classifier, result, motions_from_clips(data.training_data(), length),
                    motions_from_clips(data.heldout(settings.neutral_style), length), truth)


# ---------------------------------------------------------------------------------------------
# Metric families: each returns a small dataclass; ``as_dict`` is its report.json layout


def fit_style_classifier(data: PrimitiveData, settings: EvalSettings) -> tuple[StyleClassifier, dict[str, Any]]:
    """The style classifier fitted on the train split of every style, and its held-out result."""
    train_clips, held = data.split("train"), data.heldout()
    train = motions_from_clips(train_clips, data.length)
    classifier = StyleClassifier(settings.classifier.components, settings.classifier.C, settings.seed)
    classifier.fit(train.normalized_frames.numpy(), train.duration_s.numpy(), [c.style for c in train_clips])
    held_m = motions_from_clips(held, data.length)
    rep = classifier.evaluate(held_m.normalized_frames.numpy(), held_m.duration_s.numpy(), [c.style for c in held])
    return classifier, {"heldout_accuracy": rep.accuracy, "heldout_clips": rep.clips, "train_clips": len(train),
                        "styles": rep.styles, "confusion": rep.confusion.tolist(), "recall": rep.recall,
                        "chance": 1.0 / len(rep.styles), "components": classifier.pca.n_components_}


def _variance(motions: MotionSamples) -> dict[str, float]:
    return variance_stats(motions.frames.numpy(), motions.positions.numpy(), motions.num_frames.numpy(),
                          motions.normalized_frames.numpy())


#: What :func:`variation_vs_style` compares with the real clips of a model's own style.
VARIATION_KEYS = ("pose_across_sd", "v_sd", "step_sd", "diversity")


def variation_vs_style(variance: Variance, diversity_rows: Mapping[str, Mapping[str, float]],
                       models: Sequence[EvalModel]) -> dict[str, dict[str, float]]:
    """Each model's variation as a share of the real clips of its own style (``style``): pose_across_SD,
    V_SD and step_SD over the style's clips (:func:`real_variance`), diversity over its ground truth.

    Beyond the thesis, which divides by the neutral training data: a style model that copies its one
    example keeps its style's pose_SD but scores near 0 here.
    """
    out = {}
    for m in models:
        real = variance.real.get(m.style)
        if real is None:
            continue
        row, div = variance.rows[m.name], diversity_rows[m.name]
        ratios = {k: row[k] / real[k] if real[k] else float("nan") for k in VARIATION_KEYS[:-1]}
        ratios["diversity"] = div["samples"] / div["real"] if div["real"] else float("nan")
        out[m.name] = {"style": m.style, **ratios}
    return out


@dataclass
class Variance:
    """Tables 5.2/5.3 of one primitive: pose_SD, V_SD, step_SD per row (training data, models) and per real style."""

    rows: dict[str, dict[str, float]]
    real: dict[str, dict[str, float]]

    @property
    def ratio(self) -> dict[str, dict[str, float]]:
        """Every row divided by the training data's."""
        base = self.rows["training_data"]
        return {row: {k: stats[k] / base[k] if base[k] else float("nan") for k in ("pose_sd", "v_sd", "step_sd")}
                for row, stats in self.rows.items()}


def real_variance(real: RealSide) -> Variance:
    """The reference rows of Tables 5.2/5.3: the training data, and the real clips of every style that has
    clips of this primitive."""
    clips = {style: real.data.style_clips(style) for style in real.data.styles}
    return Variance({"training_data": _variance(real.training)},  # a style without clips of the primitive has no row
                    {style: _variance(motions_from_clips(c, real.length)) for style, c in clips.items() if c})


@dataclass
class Recognition:
    """How the style classifier labels a model's samples (and its real ground truth)."""

    target_style: str
    share: float
    samples: int
    predicted: dict[str, float]
    real_share: float


def recognition(real: RealSide, model: EvalModel, sample_features: np.ndarray,
                truth_features: np.ndarray) -> Recognition:
    """Share of the samples (and of the ground truth) the classifier assigns to the model's style."""
    predicted = real.classifier.predict_features(sample_features)
    return Recognition(model.style, float((predicted == model.style).mean()), len(sample_features),
                       predicted_shares(predicted, real.classifier.styles),
                       float((real.classifier.predict_features(truth_features) == model.style).mean()))


@dataclass
class Distribution:
    """Fréchet distance and diversity of a model's samples against its ground truth, in classifier features."""

    frechet: float
    frechet_reference: dict[str, Any]
    diversity: dict[str, Any]


def distribution(real: RealSide, model: EvalModel, sample_features: np.ndarray, truth_features: np.ndarray,
                 neutral_features: np.ndarray | None, settings: EvalSettings) -> Distribution:
    """Fréchet distance with its references (neutral samples, the real-vs-real floor) and diversity."""
    return Distribution(
        frechet_distance(sample_features, truth_features),
        _frechet_reference(real, model, truth_features, neutral_features),
        {"samples": diversity(sample_features, settings.diversity_items),
         "real": diversity(truth_features, settings.diversity_items), "real_clips": len(real.truth[model.name])})


@dataclass
class Skating:
    """Foot skating of a model's samples and of its real ground truth."""

    samples: FootSkating
    real: FootSkating

    def as_dict(self) -> dict[str, Any]:
        return {"samples": self.samples.as_dict(), "real": self.real.as_dict()}


def skating(real: RealSide, model: EvalModel, samples: MotionSamples, settings: EvalSettings) -> Skating:
    """Share of contact foot-frames whose planted point moves faster than ``settings.skate_speed_mps``."""
    data, truth = real.data, real.truth[model.name]
    return Skating(
        foot_skating(samples.positions.numpy(), samples.num_frames.numpy(), samples.fps, data.rest_heights,
                     data.stance_foot, settings.skate_speed_mps),
        foot_skating(truth.positions.numpy(), truth.num_frames.numpy(), truth.fps, data.rest_heights,
                     data.stance_foot, settings.skate_speed_mps))


def stance(real: RealSide, model: EvalModel, samples: MotionSamples) -> dict[str, Any]:
    """Root travel against the stance leg's sweep (:func:`stylemotion.primitives.stance.stance_travel`) of a model's
    samples and of its real ground truth (``report.json`` ``stance_travel.<primitive>.<model>``)."""
    truth, foot = real.truth[model.name], real.data.stance_foot
    return {"samples": stance_travel(samples.positions.numpy(), samples.num_frames.numpy(), samples.fps,
                                     foot).as_dict(),
            "real": stance_travel(truth.positions.numpy(), truth.num_frames.numpy(), truth.fps, foot).as_dict()}


@dataclass
class StyleTable:
    """Table 5.1 of one primitive: ``distance[i][j]`` = D(models[i], examples[j]).

    ``shared_columns``: rows of models whose example is another model's column (a zero-shot network bound to a
    CVAE's example), in ``extra_rows``, → that column's name.
    """

    models: list[str]
    distance: np.ndarray
    samples: int
    example_clips: dict[str, Any]
    extra_rows: dict[str, list[float]] = field(default_factory=dict)
    shared_columns: dict[str, str] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        out = {"models": self.models, "examples": self.models, "distance": self.distance.tolist(),
               "diagonal": diagonal_minima(self.distance, self.models), "samples": self.samples,
               "example_clips": self.example_clips}
        if self.extra_rows:
            out["extra_rows"] = self.extra_rows
        if self.shared_columns:
            out["shared_columns"] = {
                name: {"column": column, "row_argmin": self.models[int(np.argmin(self.extra_rows[name]))],
                       "own_column_is_minimum": self.models[int(np.argmin(self.extra_rows[name]))] == column}
                for name, column in self.shared_columns.items()}
        return out


def column_owners(real: RealSide) -> tuple[list[EvalModel], dict[str, str]]:
    """Table 5.1's columns: the models whose example clip(s) no model before them (``real.models`` order) has,
    and, for each other model, the name of the column of its example (two columns of one example would tie in
    every row)."""
    owners: list[EvalModel] = []
    shared: dict[str, str] = {}
    seen: dict[tuple, str] = {}
    for m in real.models:
        key = ((NEUTRAL,) if m.name == NEUTRAL else
               tuple((c.take, c.start, c.stop, c.primitive) for c in real.examples[m.name]))
        if key in seen:
            shared[m.name] = seen[key]
        else:
            seen[key] = m.name
            owners.append(m)
    return owners, shared


def style_table(real: RealSide, autoencoder, model_frames: Sequence[np.ndarray], settings: EvalSettings,
                extra_frames: Mapping[str, np.ndarray] | None = None) -> StyleTable:
    """Table 5.1 from each model's first ``samples.table_5_1`` normalized sample frames (in ``real.models`` order);
    a model whose example is an earlier model's column (:func:`column_owners`) is a row against the columns, and
    so are ``extra_frames`` (row name → frames)."""
    owners, shared = column_owners(real)
    frames = dict(zip([m.name for m in real.models], model_frames))
    grams = torch.stack([example_column_gram(autoencoder, real, m) for m in owners])
    table = distance_table(autoencoder, [frames[m.name] for m in owners], grams, settings.gram_chunk)
    rows = {**{name: frames[name] for name in shared}, **dict(extra_frames or {})}
    extra = {name: distance_table(autoencoder, [f], grams, settings.gram_chunk)[0].tolist()
             for name, f in rows.items()}
    clips = {m.name: ("mean motion of the neutral training clips" if m.name == NEUTRAL
                      else [c.describe() for c in real.examples[m.name]]) for m in owners}
    return StyleTable([m.name for m in owners], table, settings.samples.table_5_1, clips, extra, shared)


def example_column_gram(autoencoder, real: RealSide, model: EvalModel) -> torch.Tensor:
    """Gram of the model's column: its example clip(s), or the mean neutral training motion."""
    if model.name == NEUTRAL:
        return example_gram(autoencoder, [mean_motion(real.training.normalized_frames.numpy())])
    clips = real.examples[model.name]
    # encoded exactly as for training: resampled to the canonical length unless recorded "natural"
    length = None if model.example_length == "natural" else int(model.examples[0].get("encoded_frames") or real.length)
    g = mean_gram(encode_examples(autoencoder, clips, length)).float()
    if model.target_gram is not None:
        target = model.target_gram.float()
        rel = float(torch.linalg.matrix_norm(g - target) / torch.linalg.matrix_norm(target).clamp_min(1e-12))
        if rel > GRAM_TOLERANCE:
            raise MissingExampleError(
                f"the style example of {model.checkpoint or model.label} ({[c.describe() for c in clips]}) has a "
                f"different Gram matrix in this data than the one the model was trained on (relative difference "
                f"{rel:.2g}): evaluate with the data and autoencoder the model was trained on")
    return g


# ---------------------------------------------------------------------------------------------
# One primitive


def _evaluate_primitive(primitive: str, models: list[EvalModel], takeset: TakeSet, autoencoder,
                        settings: EvalSettings, split: Mapping[str, Any] | None,
                        segmentation: Segmentation | None = None,
                        extra_rows: Mapping[str, Any] | None = None) -> dict[str, Any]:
    real = real_side(primitive, models, takeset, settings, split, segmentation)
    variance = real_variance(real)
    train_poses = pose_sequences(real.training.normalized_frames.numpy())
    out: dict[str, Any] = {"frechet": {}, "frechet_reference": {}, "diversity": {}, "foot_skating_detail": {},
                           "stance_travel": {}, "nearest_training": {}, "recognition": {}, "skating": {},
                           "classifier": real.classifier_result}
    table_frames = []
    neutral_features = None
    n_draw = max(settings.samples.table_5_1, settings.samples.variance, settings.samples.metrics)
    for m in real.models:
        t0 = time.perf_counter()
        log.info(f"{primitive}: {m.name}: {n_draw} samples")
        samples = m.source.sample(n_draw, seed=settings.seed)  # one draw serves every family
        table_frames.append(samples.normalized_frames[:settings.samples.table_5_1].numpy())
        variance.rows[m.name] = _variance(samples.subset(slice(0, settings.samples.variance)))
        s = samples.subset(slice(0, settings.samples.metrics))
        del samples
        f_s, f_t = real.features(s), real.features(real.truth[m.name])
        if m.name == NEUTRAL:
            neutral_features = f_s
        out["recognition"][m.name] = asdict(recognition(real, m, f_s, f_t))
        dist = distribution(real, m, f_s, f_t, neutral_features, settings)
        out["frechet"][m.name] = dist.frechet
        out["frechet_reference"][m.name] = dist.frechet_reference
        out["diversity"][m.name] = dist.diversity
        sk = skating(real, m, s, settings)
        out["skating"][m.name] = {"samples": sk.samples, "real": sk.real}
        out["foot_skating_detail"][m.name] = sk.as_dict()
        if real.data.stance_foot is not None:
            out["stance_travel"][m.name] = stance(real, m, s)
        out["nearest_training"][m.name] = _nearest(train_poses, real.examples[m.name], s, real.truth[m.name],
                                                   real.heldout_neutral, real.length)
        log.debug("%s/%s evaluated in %.1f s", primitive, m.name, time.perf_counter() - t0)
    n_models, n_table = len(real.models), settings.samples.table_5_1
    extra_frames = {}
    rows = {**(shift_baselines(real, autoencoder) if settings.shift_baseline else {}), **dict(extra_rows or {})}
    out["extra_rows"] = sorted(rows)
    for name, source in rows.items():
        log.info(f"{primitive}: {name} (Tables 5.1–5.3 row): {max(n_table, settings.samples.variance)} samples")
        samples = source.sample(max(n_table, settings.samples.variance), seed=settings.seed)
        variance.rows[name] = _variance(samples.subset(slice(0, settings.samples.variance)))
        frames = samples.normalized_frames[:n_table].numpy()
        extra_frames[name] = (frames if frames.shape[1] == real.length
                              else np.stack([time_normalize(f, real.length) for f in frames]))
    log.info(f"{primitive}: Table 5.1 ({n_models} × {n_models}, {n_table} samples per model)")
    out["table_5_1"] = style_table(real, autoencoder, table_frames, settings, extra_frames).as_dict()
    out["variance"] = variance.rows
    out["variance_real"] = variance.real
    out["variance_ratio"] = variance.ratio
    out["variation_vs_style"] = variation_vs_style(variance, out["diversity"], real.models)
    return out


class ShiftBaseline:
    """The shift baseline of a style example (issue 27): a neutral model's sample plus (example − neutral mean) in the
    autoencoder's feature space — what any style model has to beat.

    Sample ``i`` of seed ``s`` is the neutral model's sample ``i`` of seed ``s`` (raw features ``F_i`` ``(C, T')``,
    duration ``d_i``), moved by the example's offset from the neutral training clips::

        F_i + mean_k Φ(x_k) − mean_j Φ(n_j)          d_i · exp(mean_k log d(x_k) − mean_j log d(n_j))

    (``Φ``: the autoencoder's features of a clip resampled to the canonical ``length``; ``x``: the example clip(s),
    ``n``: the neutral train clips; the duration moves in log space, as the models standardize it), decoded by the
    autoencoder as the models' samples are.

    Args:
        neutral: the neutral model's source (samples carry ``features`` ``(n, C, T')``).
        autoencoder: the models' autoencoder.
        examples: the example clip(s).
        training: the neutral train clips as motions (``normalized_frames`` on the canonical timeline, ``duration_s``).
        length: the canonical timeline, frames.
    """

    def __init__(self, neutral: Any, autoencoder, examples: Sequence, training: MotionSamples, length: int):
        self.neutral, self.autoencoder, self.length = neutral, autoencoder, int(length)
        with torch.no_grad():
            example = torch.stack(encode_examples(autoencoder, examples, self.length)).mean(0)
            base = encode_frames(autoencoder, training.normalized_frames.float()).mean(0)
        self.shift = (example - base).float().cpu()  # (C, T')
        self.log_duration_shift = (float(np.mean(np.log([c.duration_s for c in examples])))
                                   - float(training.duration_s.double().log().mean()))

    @torch.no_grad()
    def sample(self, n: int, seed: int | None = None) -> MotionSamples:
        """``n`` motions: the neutral model's ``n`` samples of ``seed``, shifted (class doc)."""
        drawn = self.neutral.sample(n, seed=seed)
        return decode_features(self.autoencoder, drawn.features + self.shift,
                               drawn.duration_s * math.exp(self.log_duration_shift), self.length, drawn.fps)


def shift_baselines(real: RealSide, autoencoder) -> dict[str, ShiftBaseline]:
    """``shift:<column>`` → the :class:`ShiftBaseline` of each style column of Table 5.1 (:func:`column_owners`), when
    the neutral model is a VAE (its samples carry features); else none."""
    neutral = next((m for m in real.models if m.name == NEUTRAL), None)
    if neutral is None or getattr(neutral.source, "autoencoder", None) is None:
        return {}
    owners, _ = column_owners(real)
    return {f"shift:{m.name}": ShiftBaseline(neutral.source, autoencoder, real.examples[m.name], real.training,
                                             real.length)
            for m in owners if m.name != NEUTRAL}


def _frechet_reference(real: RealSide, model: EvalModel, f_truth: np.ndarray,
                       neutral_features: np.ndarray | None) -> dict[str, Any]:
    """Neutral-model samples against the same ground truth, and the real-vs-real floor (train-split
    clips of the style against its held-out clips, examples left out)."""
    ref: dict[str, Any] = {"ground_truth_clips": len(f_truth)}
    if neutral_features is not None:
        ref["neutral_samples"] = frechet_distance(neutral_features, f_truth)
    skip = {(c.take, c.start) for c in real.examples[model.name]}
    a = [c for c in real.data.split("train", model.style) if (c.take, c.start) not in skip]
    b = [c for c in real.data.heldout(model.style) if (c.take, c.start) not in skip]
    if len(a) >= 2 and len(b) >= 2:
        ref["real_floor"] = frechet_distance(real.features(motions_from_clips(a, real.length)),
                                             real.features(motions_from_clips(b, real.length)))
    return ref


def _nearest(train_poses: np.ndarray, examples: list, samples: MotionSamples, truth: MotionSamples,
             heldout_neutral: MotionSamples, length: int) -> dict[str, Any]:
    """Nearest-training-clip distances (RMS joint distance, metres; see :func:`.metrics.nearest_distances`).

    The training set is the neutral train clips plus the model's example clip(s). ``samples_median_m``
    against ``heldout_neutral_median_m`` (real neutral clips the models never saw) and
    ``ground_truth_median_m`` (the model's real ground truth): samples much closer than real unseen
    clips are copies. For style models, ``to_example_median_m`` (samples to the example) against
    ``ground_truth_to_example_median_m``.
    """
    reference = train_poses
    if examples:
        ex = pose_sequences(motions_from_clips(examples, length).normalized_frames.numpy())
        reference = np.concatenate([train_poses, ex])
    s_poses = pose_sequences(samples.normalized_frames.numpy())
    t_poses = pose_sequences(truth.normalized_frames.numpy())
    out = {"samples_median_m": float(np.median(nearest_distances(s_poses, reference))),
           "heldout_neutral_median_m": float(np.median(nearest_distances(
               pose_sequences(heldout_neutral.normalized_frames.numpy()), reference))),
           "ground_truth_median_m": float(np.median(nearest_distances(t_poses, reference))),
           "training_clips": int(len(reference))}
    if examples:
        out["to_example_median_m"] = float(np.median(nearest_distances(s_poses, ex)))
        out["ground_truth_to_example_median_m"] = float(np.median(nearest_distances(t_poses, ex)))
    return out
