"""The new style's models against the run: their Table 5.1 row, their variation and their foot skating.

Per primitive, with the evaluation library of the run's report (:mod:`stylemotion.evaluation`):

* the run's real side (:func:`stylemotion.evaluation.pipeline.real_side`: its clips split and its
  style examples found, as the run's own evaluation does);
* the columns of Table 5.1 (:func:`stylemotion.evaluation.pipeline.example_column_gram`): ``neutral`` (the
  mean motion of the neutral training clips), each of the run's styles (its example clip(s)), and the
  new style (the user's clips, encoded as its model was trained on them, checked against the Gram the
  model recorded);
* the row: D(new model, column) = mean over ``samples`` samples of the Gram distance
  (:func:`stylemotion.evaluation.tables.distance_table`), and the existing column nearest to it;
* variation (:func:`stylemotion.evaluation.tables.variance_stats`: pose_SD, V_SD, step_SD,
  pose_across_SD) and raw foot skating (:func:`stylemotion.evaluation.metrics.foot_skating`, no
  clean-up) of the samples, next to the same figures of the user's example clips (and the variation of
  the neutral training data).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Any

import torch

from stylemotion.datasets import TakeSet
from stylemotion.evaluation.markdown import DEFINITIONS, fmt, pct
from stylemotion.evaluation.pipeline import example_column_gram, real_side
from stylemotion.evaluation.settings import EvalSettings
from stylemotion.evaluation.sources import check_one_autoencoder, motions_from_clips
from stylemotion.evaluation.tables import VARIANCE_KEYS, VARIANCE_UNITS, distance_table, variance_stats
from stylemotion.io.markdown import md_table
from stylemotion.models.loading import NEUTRAL, EvalModel
from stylemotion.models.sampling import MotionSamples
from stylemotion.primitives.segmentation import Clip, Segmentation
from stylemotion.primitives.skating import FootSkating, foot_skating, pooled_skating

log = logging.getLogger(__name__)

#: Variation figures of the report, in table order.
VARIATION_KEYS = (*VARIANCE_KEYS, "pose_across_sd")


def variation(motions: MotionSamples) -> dict[str, float] | None:
    """pose_SD, V_SD, step_SD, pose_across_SD (and context figures) of ≥ 2 motions; None for one motion
    (a spread needs two)."""
    if len(motions.num_frames) < 2:
        return None
    return variance_stats(motions.frames.numpy(), motions.positions.numpy(), motions.num_frames.numpy(),
                          motions.normalized_frames.numpy())


def evaluate_primitive(primitive: str, run_models: Sequence[EvalModel], new: EvalModel, clips: Sequence[Clip],
                       takeset: TakeSet, autoencoder, settings: EvalSettings, split: dict[str, Any] | None,
                       samples: int, seed: int, segmentation: Segmentation | None = None) -> dict[str, Any]:
    """The new model of ``primitive`` against the run (see the module doc).

    Args:
        run_models: the run's models of ``primitive`` (neutral VAE, style CVAEs).
        new: the new style's model; ``new.name`` names its column.
        clips: the user's example clips its model was trained on.
        takeset, split: the run's data and split settings.
        autoencoder: the run's autoencoder.
        settings: the run's evaluation settings.
        samples: samples of the new model; ``seed`` draws them.
        segmentation: the action's takes segmented with ``settings.segment`` (None: segmented here).

    Returns:
        ``table_5_1_row`` {column: D}, ``columns`` {column: what its Gram is of}, ``nearest_existing``,
        ``new_column_is_minimum``, ``variation`` {samples, example, training_data}, ``foot_skating``
        {samples, example}, ``samples``.

    Raises:
        ValueError: the new model's timeline differs from the run's, or it was trained on other data.
        MixedAutoencodersError, MissingExampleError: another autoencoder, or an example that is not the
            one the model was trained with.
    """
    check_one_autoencoder([*run_models, new])
    real = real_side(primitive, run_models, takeset, settings, split, segmentation)
    if new.timeline_frames != real.length:
        raise ValueError(f"{new.checkpoint}: timeline of {new.timeline_frames} frames, the run's {primitive} models "
                         f"use {real.length}: it was not trained on the run's data")
    real.examples[new.name] = list(clips)  # the new column: the user's clips, as the model was trained on them
    columns = [*real.models, new]
    grams = torch.stack([example_column_gram(autoencoder, real, m) for m in columns])
    log.info(f"{primitive}: {samples} samples of {new.name}, Table 5.1 row against {len(columns)} examples")
    drawn = new.source.sample(samples, seed=seed)
    row = distance_table(autoencoder, [drawn.normalized_frames.numpy()], grams, settings.gram_chunk)[0]
    names = [m.name for m in columns]
    table_row = {name: float(d) for name, d in zip(names, row)}
    offsets = {name: float(torch.linalg.matrix_norm(g - grams[0])) for name, g in zip(names[1:], grams[1:])}
    existing = {name: d for name, d in table_row.items() if name != new.name}
    example = motions_from_clips(list(clips), real.length)
    data = real.data

    def skating(motions: MotionSamples) -> dict[str, Any]:
        return foot_skating(motions.positions.numpy(), motions.num_frames.numpy(), motions.fps, data.rest_heights,
                            data.stance_foot, settings.skate_speed_mps).as_dict()

    return {
        "table_5_1_row": table_row,
        "columns": {m.name: ("mean motion of the neutral training clips" if m.name == NEUTRAL
                             else [c.describe() for c in real.examples[m.name]]) for m in columns},
        "nearest_existing": min(existing, key=existing.get),
        "example_range": example_range(offsets.pop(new.name), offsets),
        "new_column_is_minimum": bool(table_row[new.name] <= min(existing.values())),
        "variation": {"samples": variation(drawn), "example": variation(example),
                      "training_data": variation(real.training)},
        "foot_skating": {"samples": skating(drawn), "example": skating(example)},
        "samples": int(samples),
    }


def _clips(model: dict[str, Any]) -> str:
    """A model's example clips as frames of the user's file (files, when they come from several)."""
    several = len({(c.get("file"), tuple(c.get("file_range") or ())) for c in model["examples"]}) > 1
    return ("; ".join((f"{c['file']} " if several else "") + f"{c['primitive']} {c['file_frames'][0]}–"
                      f"{c['file_frames'][1]}" for c in model["examples"])
            + (" (none of this primitive: the example's other steps)" if model["borrowed"] else ""))


def _models_section(results: dict[str, Any]) -> list[str]:
    """The lines that say where the new models come from (``method``)."""
    network = results.get("network")
    if network is None:
        return ["Models (trained as the run's CVAE stage of the primitive, conditioned on the example's clips):", "",
                md_table(["primitive", "checkpoint", "example clips (frames of the file)"],
                          [[p, f"`{m['checkpoint']}`", _clips(m)] for p, m in results["models"].items()]), ""]
    origin = (f"trained here ({network['epochs']} epochs; give `network=<this folder>/network` "
              "to later `stylemotion-style method=zero_shot` calls to reuse it)" if network["trained_here"]
              else f"taken from `{network['given']}`, not trained again")
    return [f"Models: the zero-shot network of each primitive, {origin}, bound to the example's clips — no model was "
            "trained for this style:", "",
            md_table(["primitive", "network checkpoint", "trained on styles", "example clips (frames of the file)"],
                      [[p, f"`{m['checkpoint']}`", ", ".join(network["trained_styles"][p]), _clips(m)]
                       for p, m in results["models"].items()]), ""]


#: An example whose Gram distance to the neutral column exceeds this many times the farthest of the
#: run's own examples lies outside what the autoencoder was trained on.
OUT_OF_RANGE_FACTOR = 3.0


def example_range(distance_to_neutral: float, run_examples: dict[str, float]) -> dict[str, Any]:
    """Whether the new example is within the autoencoder's range: its Gram distance to the neutral column
    against the run's own examples' (``out_of_range`` beyond :data:`OUT_OF_RANGE_FACTOR` × their largest).
    An example far outside (e.g. a skeleton whose joint conventions differ from the data's: the
    autoencoder's per-joint scales turn centimetres of convention into huge feature values) gives a model
    that cannot be faithful, whatever its Table 5.1 row says."""
    farthest = max(run_examples.values()) if run_examples else None
    return {"distance_to_neutral": distance_to_neutral, "run_examples_max": farthest,
            "out_of_range": bool(farthest is not None and distance_to_neutral > OUT_OF_RANGE_FACTOR * farthest)}


def pooled_foot_skating(per_primitive: dict[str, dict[str, Any]], kind: str) -> float:
    """The foot-skating ratio of ``kind`` (``samples`` or ``example``) pooled over primitives."""
    return pooled_skating([FootSkating(**r["foot_skating"][kind]) for r in per_primitive.values()]).ratio


def markdown(results: dict[str, Any]) -> str:
    """``report.md`` of a new style (``results``: the ``report.json`` layout, see ``docs/style.md``)."""
    meta, name = results["meta"], results["name"]
    examples = results.get("examples") or [results["example"]]
    out = [f"# New style `{name}` from {'an example' if len(examples) == 1 else f'{len(examples)} examples'}", ""]

    def described(example: dict[str, Any]) -> str:
        return (f"`{example['file']}`, frames {example['file_range'][0]}–{example['file_range'][1]} of "
                f"{example['file_frames']} at {example['file_fps']:g} fps (sha256 `{example['sha256'][:16]}…`), "
                f"converted to {example['frames']} frames at {example['fps']:g} fps")

    what = (f"Example {described(examples[0])}" if len(examples) == 1 else
            f"Examples (every model takes the clips of all): {'; '.join(described(e) for e in examples)}")
    out += [f"{what}; method `{results['method']}`. It extends the "
            f"reproduce run `{meta['run']}` (data `{meta['data_name']}`, seed {meta['train_seed']}); "
            f"{fmt(results['samples'])} samples per model (seed {meta['seed']}). Git commit "
            f"`{meta.get('git_commit', '?')}`; {fmt(meta.get('seconds'), 3)} s.", ""]
    if meta.get("command"):
        out += ["```", meta["command"], "```", ""]
    out += _models_section(results)
    if results.get("skipped"):
        out += [f"No model of {results['skipped']}: another action than the example's.", ""]
    out += ["## Table 5.1 row", "", "D(new model, example) = mean Gram distance of its samples to each example "
            "(lower = closer to that style); the run's columns as in its report, and the new example.", ""]
    for p, row in results["table_5_1_row"].items():
        low = min(row.values())
        out += [f"**{p}**", "", md_table(["model \\ example", *row],
                                          [[name] + [f"**{fmt(v)}**" if v == low else fmt(v) for v in row.values()]]),
                ""]
        nearest = results["nearest_existing_style"][p]
        verdict = "is" if results["new_column_is_minimum"][p] else "is not"
        check = results.get("example_range", {}).get(p)
        if check and check["out_of_range"]:
            out += [f"**Warning:** the example lies far outside the data the autoencoder knows: its Gram distance to "
                    f"the neutral column is {fmt(check['distance_to_neutral'])}, the run's own examples' at most "
                    f"{fmt(check['run_examples_max'])}. The new model cannot be faithful to it (check the skeleton's "
                    "joint conventions; docs/style.md).", ""]
        out += [f"Of the run's styles, the samples are nearest to **{nearest}** (D {fmt(row[nearest])}); the new "
                f"example's column {verdict} the row's minimum.", ""]
    out += ["## Variation and foot skating", "",
            "The samples next to the example's clips (a spread needs ≥ 2 clips: – otherwise) and the neutral "
            "training data; foot skating before any clean-up. "
            + ", ".join(f"{k} in {VARIANCE_UNITS[k]}" for k in VARIANCE_KEYS) + ", pose_across_sd in cm.", ""]
    for p, rows in results["variation"].items():
        skating = results["foot_skating"][p]
        body = []
        for kind, v in rows.items():
            sk = skating.get(kind)
            body.append([kind] + [fmt(None if v is None else v[k]) for k in VARIATION_KEYS]
                        + [pct(sk["ratio"]) if sk else "–", pct(sk["no_plant_share"]) if sk else "–"])
        out += [f"**{p}**", "", md_table(["motions", *VARIATION_KEYS, "foot skating", "stance foot never planted"],
                                          body), ""]
    pooled = results["foot_skating_pooled"]
    out += [f"Foot skating pooled over primitives: samples {pct(pooled['samples'])}, example clips "
            f"{pct(pooled['example'])}.", ""]
    out += ["## Definitions", ""] + [f"* **{k}**: {DEFINITIONS[k]}" for k in
                                     ("table_5_1", "pose_sd", "v_sd", "step_sd", "pose_across_sd", "foot_skating")]
    return "\n".join(out) + "\n"
