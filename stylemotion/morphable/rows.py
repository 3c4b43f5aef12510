"""The Morphable Graph's neutral models as extra rows of an evaluation (``stylemotion-reproduce morphable=true``).

:func:`neutral_models` fits (or reuses) one :class:`~stylemotion.morphable.model.MorphableModel` per primitive on
the neutral style's training clips of the run's data (the same take-based split and segmentation the VAEs train
on; the default :class:`~stylemotion.morphable.model.FitSettings`, with fewer latent dimensions than clips on
small data), into ``<folder>/<primitive>/model.npz``. A model file is reused only if it records the same data,
style, segmentation and seed; otherwise the run stops with an error naming the file. The models need no
space-partitioning tree here (they are only sampled).
"""

from __future__ import annotations

import hashlib
import json
import logging
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from stylemotion.config import ConfigError
from stylemotion.datamodules.clips import ClipDataModule
from stylemotion.datasets import data_config_key
from stylemotion.morphable.model import FitSettings, MorphableModel, fit_primitive
from stylemotion.primitives.segmentation import parse_primitive

log = logging.getLogger(__name__)

#: Row name of the Morphable Graph's neutral model in Tables 5.1–5.3.
ROW = "morphable"


def _key(data_cfg: Mapping[str, Any], primitive: str, style: str, segment: Mapping[str, Any], seed: int) -> str:
    payload = {"data": data_config_key(dict(data_cfg)), "split": data_cfg.get("split"), "primitive": primitive,
               "style": style, "segment": dict(segment), "seed": int(seed)}
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=str).encode()).hexdigest()[:16]


def neutral_models(data_cfg: Mapping[str, Any], primitives: Sequence[str], style: str, folder: Path,
                   segment: Mapping[str, Any] | None = None, seed: int = 0) -> dict[str, MorphableModel]:
    """``{primitive: model}`` fitted on ``style``'s training clips of ``data_cfg`` (or reused; module doc).

    Raises:
        ConfigError: a model file of other data or settings is in the way, or a primitive cannot be fitted.
    """
    models = {}
    for primitive in primitives:
        action, name = parse_primitive(primitive)
        path = Path(folder) / primitive / "model.npz"
        key = _key(data_cfg, primitive, style, segment or {}, seed)
        if path.is_file():
            model = MorphableModel.load(path)
            if model.meta.get("rows_key") != key:
                raise ConfigError(f"{path} holds a Morphable Graph model of other data or settings; delete it to fit "
                                  "again, or choose another out=…")
            log.info(f"    morphable {primitive}: reused {path}")
        else:
            dm = ClipDataModule(data=dict(data_cfg), action=action, primitives=[name], styles=[style],
                                segment=segment)
            dm.setup()
            clips = dm.clips["train"]
            settings = FitSettings(seed=seed)
            if 2 < len(clips) <= settings.latent_dim:  # small data (the synthetic default): fewer dimensions
                settings = FitSettings(seed=seed, latent_dim=len(clips) - 1)
                log.info(f"    morphable {primitive}: {len(clips)} training clips, so latent_dim={settings.latent_dim} "
                         f"(default {FitSettings.latent_dim})")
            try:
                model = fit_primitive(clips, settings,
                                      meta={"data": str(data_cfg.get("name")), "action": action, "primitive": name,
                                            "style": style, "rows_key": key})
            except ValueError as err:
                raise ConfigError(f"morphable=true, {primitive}: {err}") from err
            model.save(path)
            log.info(f"    morphable {primitive}: fitted on {len(clips)} {style} clips → {path}")
        models[primitive] = model
    return models
