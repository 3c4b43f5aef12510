"""Evaluate trained primitive models and write a report folder (what ``stylemotion-eval`` runs).

    stylemotion-eval 'checkpoints=[runs/reproduce/synthetic/vae,runs/reproduce/synthetic/cvae]'
    stylemotion-eval data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right]' \\
        'checkpoints=[runs/train/primitive_vae/multirun/*/*/checkpoints/best.ckpt]' out=reports/eval/bandai
    stylemotion-eval ... evaluation.samples.variance=2000 force=true

``checkpoints`` lists PrimitiveVAE/StyleCVAE checkpoint files, glob patterns or folders (searched for
``**/checkpoints/best.ckpt``); all models must share one autoencoder (``autoencoder_ckpt``, default
the one they record). ``data`` must be the data they were trained on. The report folder ``out``
(see :mod:`stylemotion.evaluation.report`) is refused if it exists, unless ``force=true``.
"""

from __future__ import annotations

import glob
import logging
import os
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import torch
from omegaconf import DictConfig, OmegaConf

from stylemotion.datamodules.features import autoencoder_info, load_autoencoder
from stylemotion.datasets import build_dataset
from stylemotion.evaluation.pipeline import EvalSettings, evaluate_models
from stylemotion.evaluation.report import write_report
from stylemotion.evaluation.sources import check_one_autoencoder, load_model
from stylemotion.io.outputs import check_new_output
from stylemotion.provenance import provenance

log = logging.getLogger(__name__)


def settings_from_config(node: Mapping[str, Any], seed: int) -> EvalSettings:
    """:class:`EvalSettings` from an ``evaluation`` config node (``configs/evaluation/default.yaml``)."""
    node = OmegaConf.to_container(node, resolve=True) if isinstance(node, DictConfig) else dict(node)
    known = {"samples", "neutral_style", "classifier", "skate_speed_mps", "diversity_items", "gram_chunk",
             "autoencoder_test", "segment"}
    unknown = sorted(set(node) - known)
    if unknown:
        raise ValueError(f"unknown evaluation option(s) {unknown}; valid: {sorted(known)}")
    samples, clf, ae = node.get("samples", {}), node.get("classifier", {}), node.get("autoencoder_test", {})
    return EvalSettings(seed=int(seed), table_samples=int(samples.get("table_5_1", 1000)),
                        variance_samples=int(samples.get("variance", 10000)),
                        metric_samples=int(samples.get("metrics", 1000)),
                        neutral_style=str(node.get("neutral_style", "normal")),
                        classifier_components=int(clf.get("components", 32)), classifier_c=float(clf.get("C", 1.0)),
                        skate_speed=float(node.get("skate_speed_mps", 0.2)),
                        diversity_items=int(node.get("diversity_items", 2000)), chunk=int(node.get("gram_chunk", 256)),
                        ae_window_frames=int(ae.get("window_frames", 60)), ae_stride=int(ae.get("stride", 30)),
                        segment=dict(node.get("segment") or {}))


def is_model_checkpoint(path: str | os.PathLike) -> bool:
    """Whether a checkpoint holds a trained PrimitiveVAE/StyleCVAE (its hyperparameters carry a data ``spec``)."""
    hparams = torch.load(path, map_location="cpu", weights_only=True).get("hyper_parameters", {})
    return isinstance(hparams.get("spec"), dict)


def find_checkpoints(patterns: Sequence[str]) -> list[Path]:
    """Checkpoint files from files, glob patterns and folders.

    A folder is searched for ``**/checkpoints/best.ckpt`` of primitive models (an autoencoder's
    checkpoint in it is skipped); files and glob matches are taken as given.
    """
    if isinstance(patterns, str):
        patterns = [patterns]
    found: list[Path] = []
    for pattern in patterns:
        path = Path(pattern).expanduser()
        if path.is_dir():
            hits = [h for h in sorted(path.glob("**/checkpoints/best.ckpt")) if is_model_checkpoint(h)]
        elif path.is_file():
            hits = [path]
        else:
            hits = sorted(Path(p) for p in glob.glob(str(path), recursive=True))
        if not hits:
            raise FileNotFoundError(f"no checkpoint matches {pattern!r} (a file, a glob pattern, or a folder holding "
                                    "**/checkpoints/best.ckpt of a PrimitiveVAE/StyleCVAE)")
        found += [h for h in hits if h not in found]
    return found


def run_evaluation(data_cfg: Mapping[str, Any], checkpoints: Sequence[str], evaluation: Mapping[str, Any],
                   out: str | os.PathLike, seed: int = 0, autoencoder_ckpt: str | None = None, force: bool = False,
                   command: str = "", progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Load the models and their autoencoder, evaluate them on ``data_cfg``'s data, write the report.

    Returns:
        The results as written to ``report.json`` (with ``meta``).

    Raises:
        OutputExistsError: ``out`` exists and ``force`` is off (checked before any work).
        MixedAutoencodersError, MissingExampleError, FileNotFoundError, ValueError: bad input.
    """
    started = time.perf_counter()
    out = check_new_output(out, force)
    settings = settings_from_config(evaluation, seed)
    data_cfg = OmegaConf.to_container(data_cfg, resolve=True) if isinstance(data_cfg, DictConfig) else dict(data_cfg)
    paths = find_checkpoints(checkpoints)
    models = [load_model(p, settings.neutral_style) for p in paths]
    if autoencoder_ckpt:
        autoencoder = load_autoencoder(autoencoder_ckpt)
        info = autoencoder_info(autoencoder, autoencoder_ckpt)
        check_one_autoencoder(models, info["fingerprint"])
    else:
        check_one_autoencoder(models)
        recorded = models[0].autoencoder
        autoencoder = load_autoencoder(recorded["path"], expected=recorded)
        info = autoencoder_info(autoencoder, recorded["path"])
    for m in models:
        m.source.attach_autoencoder(autoencoder)
    takeset = build_dataset(data_cfg)
    results = evaluate_models(models, takeset, autoencoder, settings, split=data_cfg.get("split"),
                              autoencoder_info=info, progress=progress)
    results["meta"] = {
        "data": data_cfg, "data_name": takeset.name, "seed": int(seed),
        "samples": {"table_5_1": settings.table_samples, "variance": settings.variance_samples,
                    "metrics": settings.metric_samples},
        "checkpoints": [{"path": str(m.checkpoint), "primitive": m.primitive, "name": m.name, "style": m.style}
                        for m in models],
        "autoencoder": {"path": info["path"], "fingerprint": info["fingerprint"]},
        "settings": {k: v for k, v in vars(settings).items()}, **provenance(command or None),
        "seconds": time.perf_counter() - started,
    }
    write_report(results, out, force)
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
    for p, ratio in results["variance_ratio"].items():
        if "neutral" in ratio:
            r = ratio["neutral"]
            lines.append(f"{p} neutral / training data: pose_SD {r['pose_sd']:.1%}, V_SD {r['v_sd']:.1%}, "
                         f"step_SD {r['step_sd']:.1%}")
    return lines
