"""One evaluation: models × real data → the plain-valued results a report is written from.

:func:`evaluate_models` takes :class:`~stylemotion.evaluation.sources.EvalModel`s (loaded from
checkpoints or any :class:`~stylemotion.evaluation.sources.SampleSource`), the dataset they were
trained on and the autoencoder they share, and computes per primitive:

* Table 5.1 (:mod:`.tables`) on ``table_samples`` samples per model;
* Tables 5.2/5.3 on ``variance_samples`` samples per model, plus the training data and every real
  style for reference;
* the style classifier's held-out accuracy and confusion, and the share of each model's samples
  it assigns to the model's style (:mod:`.classifier`);
* Fréchet distance, diversity, foot skating and nearest-training-clip distance on
  ``metric_samples`` samples per model (:mod:`.metrics`), each against the model's ground truth
  (:meth:`.reference.PrimitiveData.ground_truth`);

and, once, the autoencoder's reconstruction error on the data's test split. Every model is sampled
with the same seed. The result is a JSON-able dict (see :mod:`.report` for its layout).
"""

from __future__ import annotations

import logging
import time
from collections import defaultdict
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import torch

from stylemotion.datamodules.features import encode_examples
from stylemotion.datamodules.windows import MotionWindowDataModule
from stylemotion.datasets import TakeSet
from stylemotion.evaluation.classifier import StyleClassifier, predicted_shares
from stylemotion.evaluation.metrics import (
    SKATE_SPEED_MPS,
    diversity,
    foot_skating,
    frechet_distance,
    nearest_distances,
    pooled_skating,
    pose_sequences,
)
from stylemotion.evaluation.reference import PrimitiveData, primitive_data
from stylemotion.evaluation.sources import (
    NEUTRAL,
    EvalModel,
    MissingExampleError,
    check_one_autoencoder,
    motions_from_clips,
)
from stylemotion.evaluation.tables import diagonal_minima, distance_table, example_gram, mean_motion, variance_stats
from stylemotion.models.autoencoder import local_mpjpe, mpjpe
from stylemotion.models.style import mean_gram
from stylemotion.sampling import MotionSamples

log = logging.getLogger(__name__)

#: Largest relative Frobenius difference accepted between a style model's recorded example Gram and
#: the Gram of its example clip recomputed from the evaluation data.
GRAM_TOLERANCE = 1e-3


@dataclass
class EvalSettings:
    """Sample counts and metric settings of an evaluation.

    Attributes:
        seed: sampling seed (every model is sampled with it) and classifier seed.
        table_samples: N of Table 5.1 (1000 in the thesis).
        variance_samples: samples per model for Tables 5.2/5.3 (10,000 in the thesis).
        metric_samples: samples per model for classifier, Fréchet, diversity, skating, nearest clip.
        neutral_style: the data's neutral style label.
        classifier_components: PCA dimensions of the classifier's feature space.
        classifier_c: inverse regularization strength of its logistic regression.
        skate_speed: planted-point speed above which a contact foot skates, m/s.
        diversity_items: rows used at most by the diversity.
        chunk: motions encoded at once for Gram matrices.
        ae_window_frames, ae_stride: test windows of the autoencoder's reconstruction error.
        segment: segmentation overrides (as for training).
    """

    seed: int = 0
    table_samples: int = 1000
    variance_samples: int = 10000
    metric_samples: int = 1000
    neutral_style: str = "normal"
    classifier_components: int = 32
    classifier_c: float = 1.0
    skate_speed: float = SKATE_SPEED_MPS
    diversity_items: int = 2000
    chunk: int = 256
    ae_window_frames: int = 60
    ae_stride: int = 30
    segment: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if min(self.table_samples, self.variance_samples, self.metric_samples) < 2:
            raise ValueError("every sample count must be ≥ 2")


def evaluate_models(models: Sequence[EvalModel], takeset: TakeSet, autoencoder, settings: EvalSettings | None = None,
                    split: Mapping[str, Any] | None = None, autoencoder_info: Mapping[str, Any] | None = None,
                    progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Evaluate models against real data (see the module doc).

    Args:
        models: the models; at most one per (primitive, name).
        takeset: the dataset they were trained on.
        autoencoder: the frozen autoencoder they share (``encode``/``decode``, ``hparams``).
        settings: sample counts and metric settings.
        split: the data's split settings (as for training).
        autoencoder_info: ``path``/``fingerprint`` of the autoencoder (checked against the models).
        progress: called with a line of text as each step starts.

    Returns:
        The results (JSON-able), without ``meta``.

    Raises:
        ValueError: no model, two models of one primitive and name, a style not in the data, or
            different timelines within one primitive.
        MixedAutoencodersError: models trained on different autoencoders.
        MissingExampleError: a style model without (or with a mismatching) example clip.
    """
    settings = settings or EvalSettings()
    say = progress or log.info
    if not models:
        raise ValueError("no model to evaluate")
    fp = None if autoencoder_info is None else autoencoder_info.get("fingerprint")
    check_one_autoencoder(models, fp)
    by_primitive: dict[str, list[EvalModel]] = defaultdict(list)
    for m in models:
        if any(o.name == m.name for o in by_primitive[m.primitive]):
            raise ValueError(f"two models of {m.label}: evaluate one model per primitive and style")
        if m.dataset is not None and m.dataset != takeset.name:
            raise ValueError(f"{m.checkpoint or m.label} was trained on dataset {m.dataset!r}, not {takeset.name!r}")
        by_primitive[m.primitive].append(m)
    results: dict[str, Any] = {key: {} for key in (
        "table_5_1", "variance", "variance_ratio", "variance_real", "frechet", "frechet_reference", "diversity",
        "foot_skating_detail", "nearest_training")}
    recognition: dict[str, Any] = {"per_primitive": {}, "per_model_detail": {}}
    skating: dict[str, list] = defaultdict(list)
    skating_real: dict[str, list] = defaultdict(list)
    shares: dict[str, list[tuple[float, int]]] = defaultdict(list)
    say("autoencoder: reconstruction error on the test split")
    results["autoencoder"] = autoencoder_test_error(autoencoder, takeset, split, settings)
    if autoencoder_info is not None:
        results["autoencoder"].update(path=autoencoder_info.get("path"),
                                      fingerprint=autoencoder_info.get("fingerprint"))
    for primitive in sorted(by_primitive):
        group = by_primitive[primitive]
        out = _evaluate_primitive(primitive, group, takeset, autoencoder, settings, split, say)
        for key in results:
            if key in out:
                results[key][primitive] = out[key]
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
    results["models"] = [{"name": m.name, "primitive": m.primitive, "style": m.style, "checkpoint": m.checkpoint,
                          "examples": m.examples} for p in sorted(by_primitive) for m in by_primitive[p]]
    return results


@torch.no_grad()
def autoencoder_test_error(autoencoder, takeset: TakeSet, split: Mapping[str, Any] | None,
                           settings: EvalSettings) -> dict[str, Any]:
    """MPJPE (m) of the autoencoder's reconstructions of the test split's windows.

    ``test_mpjpe_m``: positions integrated from the origin for both (root drift counts);
    ``test_local_mpjpe_m``: root-local poses only (see :mod:`stylemotion.models.autoencoder`).
    """
    dm = MotionWindowDataModule(takeset=takeset, window_frames=settings.ae_window_frames, stride=settings.ae_stride,
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
            "window_frames": settings.ae_window_frames, "data": takeset.name}


def _order(models: Sequence[EvalModel], styles: Sequence[str]) -> list[EvalModel]:
    """Neutral first, then style models in the data's style order."""
    rank = {s: i for i, s in enumerate(styles)}
    return sorted(models, key=lambda m: (m.name != NEUTRAL, rank.get(m.style, len(rank)), m.name))


def _example_clips(data: PrimitiveData, model: EvalModel) -> list:
    if model.name == NEUTRAL:
        return []
    if not model.examples:
        raise MissingExampleError(f"style model {model.checkpoint or model.label} records no style example clip, so "
                                  "Table 5.1 has no column for it; was it trained as a StyleCVAE with a style?")
    return [data.find_example(record) for record in model.examples]


def _example_gram(autoencoder, data: PrimitiveData, model: EvalModel, clips: list) -> torch.Tensor:
    if model.name == NEUTRAL:
        return example_gram(autoencoder, [mean_motion(motions_from_clips(data.training_data(),
                                                                         data.length).normalized_frames.numpy())])
    # encoded exactly as for training: resampled to the canonical length unless recorded "natural"
    length = None if model.example_length == "natural" else int(model.examples[0].get("encoded_frames") or data.length)
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


def _evaluate_primitive(primitive: str, models: list[EvalModel], takeset: TakeSet, autoencoder,
                        settings: EvalSettings, split: Mapping[str, Any] | None,
                        say: Callable[[str], None]) -> dict[str, Any]:
    lengths = {m.timeline_frames for m in models if m.timeline_frames is not None}
    if len(lengths) > 1:
        raise ValueError(f"the models of {primitive} use different canonical timelines {sorted(lengths)}: they were "
                         "trained on different data")
    length = lengths.pop() if lengths else None
    say(f"{primitive}: real clips")
    if length is None:  # sources without a recorded timeline: the median neutral train clip
        probe = primitive_data(takeset, primitive, 2, settings.neutral_style, settings.segment, split)
        length = int(round(float(np.median([c.num_frames for c in probe.training_data()]))))
    data = primitive_data(takeset, primitive, length, settings.neutral_style, settings.segment, split)
    for m in models:
        if m.style not in data.styles:
            raise MissingExampleError(f"{m.checkpoint or m.label} models style {m.style!r}, which dataset "
                                      f"{takeset.name!r} does not have (styles: {data.styles}): no example, no "
                                      "ground truth")
    models = _order(models, data.styles)
    names = [m.name for m in models]
    examples = {m.name: _example_clips(data, m) for m in models}
    grams = torch.stack([_example_gram(autoencoder, data, m, examples[m.name]) for m in models])

    say(f"{primitive}: style classifier on {len(data.split('train'))} real train clips")
    train = motions_from_clips(data.split("train"), length)
    classifier = StyleClassifier(settings.classifier_components, settings.classifier_c, settings.seed)
    classifier.fit(train.normalized_frames.numpy(), train.duration_s.numpy(), [c.style for c in data.split("train")])
    held = data.heldout()
    held_m = motions_from_clips(held, length)
    rep = classifier.evaluate(held_m.normalized_frames.numpy(), held_m.duration_s.numpy(), [c.style for c in held])
    classifier_out = {"heldout_accuracy": rep.accuracy, "heldout_clips": rep.clips, "train_clips": len(train),
                      "styles": rep.styles, "confusion": rep.confusion.tolist(), "recall": rep.recall,
                      "chance": 1.0 / len(rep.styles), "components": classifier.pca.n_components_}

    def feats(m: MotionSamples) -> np.ndarray:
        return classifier.features(m.normalized_frames.numpy(), m.duration_s.numpy())

    training = motions_from_clips(data.training_data(), length)
    train_poses = pose_sequences(training.normalized_frames.numpy())
    heldout_neutral = motions_from_clips(data.heldout(settings.neutral_style), length)
    out: dict[str, Any] = {"variance": {"training_data": variance_stats(training.frames.numpy(),
                                                                       training.positions.numpy(),
                                                                       training.num_frames.numpy())},
                           "frechet": {}, "frechet_reference": {}, "diversity": {}, "foot_skating_detail": {},
                           "nearest_training": {}, "recognition": {}, "skating": {}, "classifier": classifier_out}
    out["variance_real"] = {}
    for style in data.styles:
        real = motions_from_clips(data.style_clips(style), length)
        out["variance_real"][style] = variance_stats(real.frames.numpy(), real.positions.numpy(),
                                                     real.num_frames.numpy())
    table_frames = []
    neutral_feats = None
    n_draw = max(settings.table_samples, settings.variance_samples, settings.metric_samples)
    for m in models:
        t0 = time.perf_counter()
        say(f"{primitive}: {m.name}: {n_draw} samples")
        samples = m.source.sample(n_draw, seed=settings.seed)
        table_frames.append(samples.normalized_frames[:settings.table_samples].numpy())
        v = samples.subset(slice(0, settings.variance_samples))
        out["variance"][m.name] = variance_stats(v.frames.numpy(), v.positions.numpy(), v.num_frames.numpy())
        s = samples.subset(slice(0, settings.metric_samples))
        del samples, v
        f_s = feats(s)
        if m.name == NEUTRAL:
            neutral_feats = f_s
        truth_clips = data.ground_truth(m, examples[m.name])
        if len(truth_clips) < 2:
            raise ValueError(f"{m.label}: fewer than 2 real clips of style {m.style!r} besides its example; the "
                             "metrics need ground truth")
        truth = motions_from_clips(truth_clips, length)
        f_t = feats(truth)
        predicted = classifier.predict_features(f_s)
        share = float((predicted == m.style).mean())
        out["recognition"][m.name] = {"target_style": m.style, "share": share, "samples": len(s),
                                      "predicted": predicted_shares(predicted, classifier.styles),
                                      "real_share": float((classifier.predict_features(f_t) == m.style).mean())}
        out["frechet"][m.name] = frechet_distance(f_s, f_t)
        out["frechet_reference"][m.name] = _frechet_reference(data, m, examples[m.name], feats, length, f_t,
                                                              neutral_feats)
        out["diversity"][m.name] = {"samples": diversity(f_s, settings.diversity_items),
                                    "real": diversity(f_t, settings.diversity_items), "real_clips": len(truth_clips)}
        sk = foot_skating(s.positions.numpy(), s.num_frames.numpy(), s.fps, data.rest_heights, data.stance_foot,
                          settings.skate_speed)
        sk_real = foot_skating(truth.positions.numpy(), truth.num_frames.numpy(), truth.fps, data.rest_heights,
                               data.stance_foot, settings.skate_speed)
        out["skating"][m.name] = {"samples": sk, "real": sk_real}
        out["foot_skating_detail"][m.name] = {"samples": sk.as_dict(), "real": sk_real.as_dict()}
        out["nearest_training"][m.name] = _nearest(train_poses, examples[m.name], s, truth, heldout_neutral, length)
        log.debug("%s/%s evaluated in %.1f s", primitive, m.name, time.perf_counter() - t0)
    say(f"{primitive}: Table 5.1 ({len(models)} × {len(models)}, {settings.table_samples} samples per model)")
    table = distance_table(autoencoder, table_frames, grams, settings.chunk)
    out["table_5_1"] = {"models": names, "examples": names, "distance": table.tolist(),
                        "diagonal": diagonal_minima(table, names), "samples": settings.table_samples,
                        "example_clips": {m.name: ("mean motion of the neutral training clips"
                                                   if m.name == NEUTRAL else [c.describe() for c in examples[m.name]])
                                          for m in models}}
    base = out["variance"]["training_data"]
    out["variance_ratio"] = {row: {k: stats[k] / base[k] if base[k] else float("nan")
                                   for k in ("pose_sd", "v_sd", "step_sd")} for row, stats in out["variance"].items()}
    return out


def _frechet_reference(data: PrimitiveData, model: EvalModel, examples: list, feats, length: int, f_truth: np.ndarray,
                       neutral_feats: np.ndarray | None) -> dict[str, Any]:
    """Neutral-model samples against the same ground truth, and the real-vs-real floor (train-split
    clips of the style against its val+test clips, examples left out)."""
    ref: dict[str, Any] = {"ground_truth_clips": len(f_truth)}
    if neutral_feats is not None:
        ref["neutral_samples"] = frechet_distance(neutral_feats, f_truth)
    skip = {(c.take, c.start) for c in examples}
    a = [c for c in data.split("train", model.style) if (c.take, c.start) not in skip]
    b = [c for c in data.heldout(model.style) if (c.take, c.start) not in skip]
    if len(a) >= 2 and len(b) >= 2:
        ref["real_floor"] = frechet_distance(feats(motions_from_clips(a, length)), feats(motions_from_clips(b, length)))
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
