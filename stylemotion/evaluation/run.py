"""Evaluate trained primitive models and write a report folder (what ``stylemotion-eval`` runs).

    stylemotion-eval 'checkpoints=[runs/reproduce/synthetic/vae,runs/reproduce/synthetic/cvae]'
    stylemotion-eval data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right]' \\
        'checkpoints=[runs/train/primitive_vae/multirun/*/*/checkpoints/best.ckpt]' out=reports/eval/bandai
    stylemotion-eval ... evaluation.samples.variance=2000 force=true

``checkpoints`` lists PrimitiveVAE/StyleCVAE checkpoint files, glob patterns or folders (searched for
``**/checkpoints/best.ckpt``), and zero-shot network checkpoints (files or globs; a folder search skips them);
all models must share one autoencoder (``autoencoder_ckpt``, default the one they record). ``data`` must be the
data they were trained on. A zero-shot network is evaluated once per example it is bound to
(:func:`stylemotion.evaluation.sources.zero_shot_models`, rows ``zero_shot:<style>``): each style's example clip(s)
of the evaluated CVAEs of its primitive (else the ones it records), or ``example=<BVH>[:a-b]`` (one or a list)
showing the data's style ``example_style``. A Morphable Graph model (its ``model.npz`` or run folder) becomes the
row ``morphable`` (another style's: ``morphable:<style>``) of its primitive's Tables 5.1–5.3 beside the VAE/CVAEs
evaluated with it (:func:`stylemotion.evaluation.sources.morphable_rows`). The report folder ``out``
(see :mod:`stylemotion.evaluation.report`) is refused if it exists, unless ``force=true``.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf

from stylemotion.config import MotionFileKeys, build_settings
from stylemotion.datasets import build_dataset
from stylemotion.evaluation.html_report import SAMPLES_PER_MODEL
from stylemotion.evaluation.pipeline import evaluate_models
from stylemotion.evaluation.report import write_report
from stylemotion.evaluation.settings import EvalSettings
from stylemotion.evaluation.sources import (
    EvaluationInputError,
    MissingExampleError,
    check_one_autoencoder,
    is_morphable_entry,
    morphable_rows,
    read_user_example,
    zero_shot_models,
)
from stylemotion.io.outputs import check_new_output
from stylemotion.models.autoencoder import IncompatibleModelError, MotionAutoencoder
from stylemotion.models.checkpoints import autoencoder_info, find_checkpoints, load_autoencoder
from stylemotion.models.loading import EvalModel, load_model
from stylemotion.provenance import provenance

log = logging.getLogger(__name__)


def settings_from_config(node: Mapping[str, Any], seed: int) -> EvalSettings:
    """:class:`EvalSettings` from an ``evaluation`` config node (any subset of its keys; the rest
    are the dataclass' defaults), sampled with ``seed``.

    Raises:
        ConfigError: an unknown key or a value of the wrong type, named as ``evaluation.<key>``.
    """
    values = OmegaConf.to_container(node, resolve=True) if isinstance(node, DictConfig) else dict(node or {})
    values["seed"] = int(seed)
    return build_settings(EvalSettings, values, "evaluation")


def recorded_path(path: str | os.PathLike | None, root: Path) -> str | None:
    """``path`` as a report records it: relative to ``root`` when it lies inside it (so the folder can
    move), else absolute."""
    if path is None:
        return None
    path = Path(path).expanduser().resolve()
    try:
        return path.relative_to(root).as_posix()
    except ValueError:
        return str(path)


def models_autoencoder(model: EvalModel) -> tuple[MotionAutoencoder, str | None]:
    """The autoencoder a model was trained with and the file to name in the report: the recorded
    autoencoder checkpoint while it is still there (same weights), else the model's checkpoint,
    which embeds it (see :func:`stylemotion.models.checkpoints.resolve_autoencoder`)."""
    recorded = (model.autoencoder or {}).get("path")
    if recorded and Path(recorded).is_file():
        try:
            return load_autoencoder(recorded, expected=model.autoencoder), recorded
        except IncompatibleModelError:
            pass  # replaced since: the embedded one is the model's own
    autoencoder = model.source.autoencoder
    return autoencoder, model.source.autoencoder_path


def run_evaluation(data_cfg: Mapping[str, Any], checkpoints: Sequence[str], evaluation: Mapping[str, Any],
                   out: str | os.PathLike, seed: int = 0, autoencoder_ckpt: str | None = None, force: bool = False,
                   command: str = "", root: str | os.PathLike | None = None,
                   extra_rows: Mapping[str, Mapping[str, Any]] | None = None,
                   example: Any = None, example_style: str | None = None,
                   example_conversion: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Load the models and their autoencoder, evaluate them on ``data_cfg``'s data, write the report.

    The autoencoder is ``autoencoder_ckpt`` if given, else the models' own (embedded in their
    checkpoints; see :func:`stylemotion.models.checkpoints.resolve_autoencoder`). Checkpoint and
    autoencoder paths inside ``root`` (default ``out``; a ``stylemotion-reproduce`` run passes its
    run folder) are recorded relative to it, and ``meta.paths_relative_to`` says where ``root`` is
    from ``out``, so a moved folder still describes itself. ``extra_rows`` (``{primitive: {row: SampleSource}}``)
    are rows of Tables 5.1–5.3 only (:func:`~stylemotion.evaluation.pipeline.evaluate_models`). ``example`` (motion
    files ``<BVH>[:start-end]``) and ``example_style`` (the data's style they show) bind the zero-shot networks
    among the checkpoints to a user's recording (module doc), its file read with ``example_conversion``
    (``joint_map``, ``unit_scale``, ``up_axis``; None values auto-detected, as ``stylemotion-style`` reads it).

    Returns:
        The results as written to ``report.json`` (with ``meta``).

    Raises:
        OutputExistsError: ``out`` exists and ``force`` is off (checked before any work).
        MixedAutoencodersError, MissingExampleError, FileNotFoundError, ValueError: bad input.
    """
    started = time.perf_counter()
    out = check_new_output(Path(out).expanduser(), force)
    base = Path(root if root is not None else out).expanduser().resolve()
    settings = settings_from_config(evaluation, seed)
    data_cfg = OmegaConf.to_container(data_cfg, resolve=True) if isinstance(data_cfg, DictConfig) else dict(data_cfg)
    morphable = [str(c) for c in checkpoints if is_morphable_entry(str(c))]
    rest = [c for c in checkpoints if str(c) not in morphable]
    if not rest:
        raise EvaluationInputError("checkpoints= is empty: name VAE/CVAE checkpoints or run folders" if not morphable
                                   else "checkpoints= holds Morphable Graph models only: they are rows beside a "
                                   "VAE/CVAE of their primitive (e.g. the run's vae folder), which brings the "
                                   "autoencoder, the classifier and the style columns")
    paths = find_checkpoints(rest)
    models = [load_model(p, settings.neutral_style, zero_shot=True) for p in paths]
    if autoencoder_ckpt:
        autoencoder = load_autoencoder(autoencoder_ckpt)
        info = autoencoder_info(autoencoder, autoencoder_ckpt)
        check_one_autoencoder(models, info["fingerprint"])
    else:
        check_one_autoencoder(models)
        autoencoder, path = models_autoencoder(models[0])
        info = autoencoder_info(autoencoder, path)
    for m in models:
        m.source.attach_autoencoder(autoencoder)
    info = {**info, "path": recorded_path(info["path"], base)}
    takeset = build_dataset(data_cfg)
    user = None
    if example is not None:
        user = read_user_example(example, example_style or "", takeset,
                                 list(dict.fromkeys(m.primitive for m in models if m.unbound)), settings.segment,
                                 settings.neutral_style, example_conversion)
    elif example_style:
        raise MissingExampleError(f"example_style={example_style} names the style of example=, which is not given")
    else:
        defaults = MotionFileKeys()
        given = {k: v for k, v in dict(example_conversion or {}).items() if v != getattr(defaults, k, None)}
        if given:
            key, value = next(iter(given.items()))
            raise MissingExampleError(f"{key}={value} reads the file of example=, which is not given (the data's "
                                      f"files: data.{key}=)")
    models = zero_shot_models(models, user)
    graphs = morphable_rows(morphable, takeset.name, takeset.fps, settings.neutral_style)
    rows = {p: dict(r) for p, r in (extra_rows or {}).items()}
    for p, r in graphs.rows.items():
        rows.setdefault(p, {}).update(r)
    results = evaluate_models(models, takeset, autoencoder, settings, split=data_cfg.get("split"),
                              autoencoder_info=info, extra_rows=rows)
    for entry in results.get("models", []):
        entry["checkpoint"] = recorded_path(entry.get("checkpoint"), base)
    results["meta"] = {
        "data": data_cfg, "data_name": takeset.name, "seed": int(seed),
        "samples": asdict(settings.samples),
        "checkpoints": [{"path": recorded_path(m.checkpoint, base), "primitive": m.primitive, "name": m.name,
                         "style": m.style, "kind": m.kind} for m in models]
        + [{**r, "path": recorded_path(r["path"], base)} for r in graphs.records],
        "autoencoder": {"path": info["path"], "fingerprint": info["fingerprint"]},
        "paths_relative_to": Path(os.path.relpath(base, out.resolve())).as_posix(),
        "settings": asdict(settings), **provenance(command or None),
        "seconds": time.perf_counter() - started,
    }
    viewer = {f"{m.primitive} {m.name}": m.source.sample(SAMPLES_PER_MODEL, seed=settings.seed) for m in models}
    viewer |= {f"{p} {name}": source.sample(SAMPLES_PER_MODEL, seed=settings.seed)
               for p, r in graphs.rows.items() for name, source in r.items()}
    write_report(results, out, force, samples=viewer)
    return results


def summary_lines(results: dict[str, Any]) -> list[str]:
    """A few lines for the terminal: Table 5.1 diagonals, classifier accuracy, neutral variance ratios."""
    lines = []
    for p, t in results["table_5_1"].items():
        d = t["diagonal"]
        lines.append(f"Table 5.1 {p}: {len(d['rows'])}/{len(t['models'])} rows and {len(d['columns'])}/"
                     f"{len(t['models'])} columns with their minimum on the diagonal")
    rec = results["style_recognition"]
    lines.append(f"style classifier on real held-out clips: {rec['classifier_heldout_accuracy']:.1%} (chance "
                 f"{rec['chance']:.1%}); samples assigned their style: "
                 + ", ".join(f"{m} {s:.0%}" for m, s in rec["per_model"].items()))
    for p, rows in results.get("variation_vs_style", {}).items():
        styled = {m: r for m, r in rows.items() if m != "neutral"}
        if styled:
            across = [r["pose_across_sd"] for r in styled.values()]
            div = [r["diversity"] for r in styled.values()]
            lines.append(f"{p} style models / real clips of their style: pose_across_SD {min(across):.0%}–"
                         f"{max(across):.0%}, diversity {min(div):.0%}–{max(div):.0%}")
    for p, ratio in results["variance_ratio"].items():
        if "neutral" in ratio:
            r = ratio["neutral"]
            lines.append(f"{p} neutral / training data: pose_SD {r['pose_sd']:.1%}, V_SD {r['v_sd']:.1%}, "
                         f"step_SD {r['step_sd']:.1%}")
    return lines
