"""``stylemotion-train experiment=morphable_graph``: fit one Morphable Graph primitive into a run folder.

The run folder (``runs/train/morphable_graph/<run id>/``, or each sweep job's) receives
``config_resolved.yaml``, ``run.json`` (version, commit, command), ``model.npz`` (the model and its
space-partitioning tree, :meth:`~stylemotion.morphable.model.MorphableModel.save`), ``metrics.json``
(the fit record, val and test reconstruction error, seconds; SFPCA's kept weights chosen on val, a sweep
minimizes the val error) and ``samples/samples.gif`` +
``samples/last_frames.png`` (16 samples, as the VAE runs show them). A folder that already holds a
``model.npz`` is refused unless ``force=true``. Clips come from the ``clips`` DataModule (the take-based
split of ``data``), the primitive and style from ``primitive`` and ``style``.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path
from typing import Any

import numpy as np
from hydra.utils import instantiate
from omegaconf import DictConfig, OmegaConf

from stylemotion.config import ConfigError, set_torch_threads
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.jsonfile import write_json
from stylemotion.io.outputs import OutputExistsError
from stylemotion.morphable.model import FitSettings, MorphableModel, fit_primitive, reconstruction_error
from stylemotion.morphable.variants import TURN_THRESHOLD_DEG, select_turn, variant_name
from stylemotion.primitives.segmentation import parse_primitive
from stylemotion.training.fit import record_start

log = logging.getLogger(__name__)

MODEL_FILE = "model.npz"


def run(cfg: DictConfig) -> dict[str, Any]:
    """Fit, save and measure one primitive as ``cfg`` says; returns ``{"model", "metrics"}``."""
    output_dir = Path(cfg.output_dir)
    model_path = output_dir / MODEL_FILE
    if model_path.exists() and not cfg.get("force", False):
        raise OutputExistsError(f"{output_dir} already holds a morphable model ({MODEL_FILE}); pass force=true to "
                                "replace it or choose another folder (hydra.run.dir=…)")
    set_torch_threads(cfg.get("threads"))
    began = time.perf_counter()
    action, primitive = _parse(str(cfg.primitive))
    record_start(output_dir, cfg, None)
    atomic_write_bytes(output_dir / "config_resolved.yaml", OmegaConf.to_yaml(cfg, resolve=True).encode())
    styles = None if cfg.get("style") in (None, "all") else [str(cfg.style)]
    datamodule = instantiate(cfg.datamodule, data=OmegaConf.to_container(cfg.data, resolve=True), action=action,
                             primitives=[primitive], styles=styles, _convert_="all")
    datamodule.setup()
    turn = cfg.get("turn")
    if turn is not None:
        try:
            datamodule.clips = {part: select_turn(clips, str(turn), float(cfg.get("turn_threshold_deg",
                                                                                   TURN_THRESHOLD_DEG)))
                                for part, clips in datamodule.clips.items()}
        except ValueError as err:
            raise ConfigError(f"experiment=morphable_graph, turn={turn}: {err}") from err
    model_cfg = OmegaConf.to_container(cfg.model, resolve=True)
    tree_cfg = model_cfg.pop("tree", None) or {}
    model_cfg.pop("family", None)
    try:
        settings = FitSettings(**model_cfg)
        model = fit_primitive(datamodule.clips["train"], settings,
                              meta={"data": str(cfg.data.get("name")), "seed": int(cfg.seed),
                                    "variant": variant_name(None if turn is None else str(turn))},
                              validation=datamodule.clips.get("val") or None)
    except (TypeError, ValueError) as err:  # a bad model.* value, too few clips, a mixture that cannot be fitted
        raise ConfigError(f"experiment=morphable_graph, {action}_{primitive}: {err}") from err
    if tree_cfg.get("samples", 0):
        given = {k: tree_cfg[k] for k in ("split", "space", "leaf_size") if tree_cfg.get(k) is not None}
        try:
            model.build_tree(int(tree_cfg["samples"]), seed=int(cfg.seed), **given)  # defaults: build_tree's
        except ValueError as err:  # an unknown split or space, a bad leaf size
            raise ConfigError(f"experiment=morphable_graph, model.tree: {err}") from err
    model.save(model_path)
    metrics: dict[str, Any] = {"fit": model.meta["fit"], "seconds_fit": time.perf_counter() - began,
                               "clips": {p: len(c) for p, c in datamodule.clips.items()},
                               "timeline_frames": model.length, "num_coefficients": model.basis.num_coefficients}
    for part in ("val", "test"):
        if datamodule.clips.get(part):
            metrics[f"{part}/joint_rmse_m"] = reconstruction_error(model, datamodule.clips[part])
    metrics["model_bytes"] = model_path.stat().st_size
    if cfg.get("samples", True):
        _write_samples(model, output_dir / "samples", int(cfg.seed), str(cfg.data.get("name")))
    metrics["seconds"] = time.perf_counter() - began
    write_json(output_dir / "metrics.json", metrics)
    log.info("%s_%s: %s written; training joint RMSE %.4f m, test %.4f m", action, primitive, model_path,
             model.meta["fit"]["joint_rmse_m"], metrics.get("test/joint_rmse_m", float("nan")))
    return {"model": model, "metrics": metrics}


def _parse(name: str) -> tuple[str, str]:
    """``walk_leftStance`` → ``("walk", "leftStance")``, ``raise-up-left-hand_raise`` → ``("raise-up-left-hand",
    "raise")`` (:func:`~stylemotion.primitives.segmentation.parse_primitive`); ConfigError otherwise."""
    try:
        return parse_primitive(name)
    except ValueError as err:
        raise ConfigError(f"primitive={name}: {err}") from None


def _write_samples(model: MorphableModel, folder: Path, seed: int, data_name: str) -> None:
    from stylemotion.viz.animation import save_gif, save_last_frames

    folder.mkdir(parents=True, exist_ok=True)
    samples = model.sample(16, seed=seed)
    title = f"{data_name} {model.meta.get('action')}_{model.meta.get('primitive')} · Morphable Graph · seed {seed}"
    save_gif(samples, folder / "samples.gif", title=title)
    save_last_frames(samples, folder / "last_frames.png", title=title)


def objective(metrics: dict[str, Any]) -> float | None:
    """What a sweep minimizes: the validation joint RMSE (``val/joint_rmse_m``); None without val clips. Never the
    test figure: a sweep that optimized it would report a test error chosen on test."""
    value = metrics.get("val/joint_rmse_m")
    return None if value is None or not np.isfinite(value) else float(value)
