"""One registry of datasets, addressed by name from the Hydra config group ``data/``."""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from typing import Any

from stylemotion.datasets.bandai import load_bandai
from stylemotion.datasets.base import Take, TakeSet
from stylemotion.datasets.bvh_folder import load_bvh_folder
from stylemotion.datasets.loading import DEFAULT_MAX_FRAMES, ConversionSettings, check_positive
from stylemotion.datasets.retarget import check_retarget, retarget_takeset
from stylemotion.io.errors import UserInputError


class DatasetOptionError(UserInputError, KeyError):
    """An unknown data set or option of a ``data`` config; the message names it and the valid ones."""

    def __str__(self) -> str:  # a KeyError's str() is its repr: show the message as it is
        return str(self.args[0]) if self.args else ""


DatasetLoader = Callable[..., TakeSet]
DATASETS: dict[str, DatasetLoader] = {}

#: Keys of a data config that are conversion settings rather than loader arguments.
_CONVERSION_KEYS = ("fps", "joint_map", "unit_scale", "up_axis", "max_file_mb", "max_frames", "max_joint_frames")
#: Keys of a data config used by the data modules, not by the loaders.
_MODULE_KEYS = ("name", "split")
#: Keys of a data config applied here to every dataset kind, after its loader.
_TAKESET_KEYS = ("retarget",)
#: Keys added after run records began hashing data configs, whose null is the behaviour from
#: before they existed: a null one is left out of :func:`data_config_key`.
_NULL_IS_ABSENT = ("retarget",)


def register_dataset(name: str) -> Callable[[DatasetLoader], DatasetLoader]:
    """Decorator adding a loader ``f(**options) -> TakeSet`` under ``name``."""
    def add(loader: DatasetLoader) -> DatasetLoader:
        if name in DATASETS:
            raise ValueError(f"dataset {name!r} is registered twice")
        DATASETS[name] = loader
        return loader
    return add


register_dataset("bandai")(load_bandai)
register_dataset("bvh_folder")(load_bvh_folder)


#: Most frames the synthetic generator makes in one data set (≈ 2.5 GB of float32 positions).
MAX_SYNTHETIC_FRAMES = 10_000_000


@register_dataset("synthetic")
def load_synthetic(
    takes_per_pair: int = 4, seed: int = 0, fps: float = 30.0, duration_s: float = 8.0,
    styles: list[str] | None = None, contents: list[str] | None = None,
) -> TakeSet:
    """The procedural stylized-locomotion dataset (see :mod:`stylemotion.datasets.synthetic`)."""
    from stylemotion.datasets.synthetic import generate_takes

    check_positive(takes_per_pair, "data.takes_per_pair", integer=True, allow_none=False)
    check_positive(fps, "data.fps", integer=False, allow_none=False)
    check_positive(duration_s, "data.duration_s", integer=False, allow_none=False)
    from stylemotion.datasets.synthetic import CONTENTS, STYLES

    pairs = len(contents if contents is not None else CONTENTS) * len(styles if styles is not None else STYLES)
    frames = float(takes_per_pair) * pairs * float(duration_s) * float(fps)
    if float(duration_s) * float(fps) > DEFAULT_MAX_FRAMES or frames > MAX_SYNTHETIC_FRAMES:
        raise DatasetOptionError(
            f"data.takes_per_pair={takes_per_pair}, data.duration_s={duration_s}, data.fps={fps}: "
            f"{frames:,.0f} frames in all ({float(duration_s) * float(fps):,.0f} per take) is more than the synthetic "
            f"generator makes ({MAX_SYNTHETIC_FRAMES:,} in all, {DEFAULT_MAX_FRAMES:,} per take); ask for fewer or "
            f"shorter takes")
    generated = generate_takes(takes_per_pair=takes_per_pair, seed=seed, fps=fps, duration_s=duration_s,
                               styles=styles, contents=contents)
    takes = [Take(g.name, g.positions, g.fps, dict(g.labels), source=f"synthetic(seed={seed})")
             for g in sorted(generated, key=lambda g: g.name)]
    return TakeSet("synthetic", takes, fps)


def load_dataset(name: str, **options: Any) -> TakeSet:
    """Build dataset ``name`` with loader ``options``; unknown names or keys get a clear error.

    Conversion keys (``fps``, ``joint_map``, ``unit_scale``, ``up_axis`` and the limits
    ``max_file_mb``, ``max_frames``, ``max_joint_frames``) are gathered into a
    :class:`ConversionSettings` for the loaders that convert files; a bad value is a ValueError
    naming its ``data.`` key. ``retarget`` (a style name or None) is applied here, to every
    dataset kind, after the loader (:func:`stylemotion.datasets.retarget.retarget_takeset`), so
    the converted takes and their cache do not depend on it.
    """
    if name not in DATASETS:
        raise DatasetOptionError(f"unknown dataset {name!r}; registered: {sorted(DATASETS)}")
    loader = DATASETS[name]
    params = inspect.signature(loader).parameters
    for key, what in (("styles", "style"), ("contents", "content")):
        if isinstance(options.get(key), (list, tuple)) and not options[key]:  # null means all; [] means none
            raise DatasetOptionError(f"data.{key}=[] selects no {what}: give at least one, or null for all")
    retarget = check_retarget(options.pop("retarget", None))
    if "settings" in params:
        conv = {k: options.pop(k) for k in _CONVERSION_KEYS if k in options}
        options["settings"] = ConversionSettings(**conv)
    unknown = sorted(set(options) - set(params))
    if unknown:
        valid = sorted(set(params) - {"settings"} | set(_TAKESET_KEYS)
                       | (set(_CONVERSION_KEYS) if "settings" in params else set()))
        raise DatasetOptionError(f"dataset {name!r} has no option(s) {unknown}; valid options: {valid}")
    return retarget_takeset(loader(**options), retarget)


def build_dataset(cfg: Mapping[str, Any]) -> TakeSet:
    """Build the dataset described by a ``data`` config node (``name`` plus options)."""
    options = {k: _plain(v) for k, v in dict(cfg).items() if k not in _MODULE_KEYS}
    if "name" not in cfg:
        raise DatasetOptionError(f"data config needs a 'name' (one of {sorted(DATASETS)})")
    return load_dataset(str(cfg["name"]), **options)


def data_config_key(cfg: Mapping[str, Any]) -> dict[str, Any]:
    """``cfg`` (a ``data`` config node) as run records hash it: null keys of :data:`_NULL_IS_ABSENT`
    left out, so a config that names them as null hashes like one written before they existed."""
    return {k: _plain(v) for k, v in dict(cfg).items() if not (k in _NULL_IS_ABSENT and v is None)}


def _plain(value: Any) -> Any:
    """OmegaConf containers to plain Python values."""
    try:
        from omegaconf import DictConfig, ListConfig, OmegaConf
    except ImportError:  # pragma: no cover - hydra-core is a dependency
        return value
    if isinstance(value, (DictConfig, ListConfig)):
        return OmegaConf.to_container(value, resolve=True)
    return value
