"""Where the Hydra configs live, and the checks and resolvers every entry point shares.

The configs ship inside the package (``stylemotion/configs``, package data), so every command works
from a wheel or a non-editable install as well as from a clone. Values a user types on the command
line are checked here before any work (:func:`positive_int`, :func:`set_torch_threads`,
:func:`check_trainer_numbers`); a bad one is a :class:`ConfigError` naming the key and the value.
Resolvers registered on import: ``${cpu_precision:}`` and ``${unique_id:}`` (run ids).

Importing this module loads no model, data set or evaluation code. Settings defaults live once, in the
dataclasses that use them; they are registered as Hydra structured configs explicitly, before a config
is composed (:func:`stylemotion.cli.schemas.register_schemas`), with :func:`structured_schema` from here.
"""

from __future__ import annotations

import math
import secrets
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import datetime
from pathlib import Path
from typing import Any

from stylemotion.io.errors import UserInputError

#: The packaged Hydra configs, as a folder on disk.
CONFIG_DIR = Path(__file__).resolve().parent / "configs"
#: The same configs as a Hydra search path (what the console scripts pass to ``hydra.main``).
CONFIG_PACKAGE = "pkg://stylemotion.configs"


def config_dir() -> str:
    """Absolute path of the packaged configs; a clear error if the installation lacks them."""
    if not (CONFIG_DIR / "train.yaml").is_file():
        raise FileNotFoundError(
            f"Hydra configs not found at {CONFIG_DIR}: this installation of stylemotion is incomplete "
            "(the wheel must include stylemotion/configs/**/*.yaml); reinstall it"
        )
    return str(CONFIG_DIR)


class ConfigError(UserInputError, ValueError):
    """A config value that cannot be used; the message names the key and the value."""


@dataclass(frozen=True)
class MotionFileKeys:
    """The keys of every command that reads a user's motion file, as datasets convert theirs
    (:data:`stylemotion.datasets.user_motion.CONVERSION_KEYS`); the settings of those commands derive from it.

    ``joint_map``: the file's skeleton: None = auto-detect (bandai, cmu21, cmu31), a built-in name or a YAML
    map ``{joints: {Hips: <its name>, ...}}``; ``unit_scale``: metres per file unit or a unit name (cm, mm,
    m, inch), None = detect; ``up_axis``: the file's up axis, ``y`` or ``z``.
    """

    joint_map: Any = None
    unit_scale: Any = None
    up_axis: str = "y"


def _is_int(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def positive_int(value: Any, key: str) -> int:
    """``value`` as an int ≥ 1 (an int, or a string of one); :class:`ConfigError` naming ``key`` otherwise.

    Booleans, fractions, ``abc``, 0 and negative numbers are refused.
    """
    number = value
    if isinstance(value, str):
        try:
            number = int(value.strip())
        except ValueError:
            number = None
    if not _is_int(number) or number < 1:
        raise ConfigError(f"{key} must be a whole number ≥ 1, got {value!r}")
    return int(number)


def set_torch_threads(value: Any, key: str = "threads") -> int | None:
    """``torch.set_num_threads(value)`` after :func:`positive_int`; ``None`` keeps torch's default.

    Returns the number of threads set, or None.
    """
    if value is None:
        return None
    threads = positive_int(value, key)
    import torch

    torch.set_num_threads(threads)
    return threads


#: Numeric keys of a Lightning ``Trainer`` node: key → (kind, smallest value allowed).
#: Kinds: ``int``; ``number`` (int or float); ``batches`` (an int count, or a float fraction in [0, 1]).
TRAINER_NUMBERS: dict[str, tuple[str, float]] = {
    "max_epochs": ("int", -1), "min_epochs": ("int", 0), "max_steps": ("int", -1), "min_steps": ("int", 0),
    "num_nodes": ("int", 1), "check_val_every_n_epoch": ("int", 1), "num_sanity_val_steps": ("int", -1),
    "log_every_n_steps": ("int", 0), "accumulate_grad_batches": ("int", 1), "gradient_clip_val": ("number", 0),
    "limit_train_batches": ("batches", 0), "limit_val_batches": ("batches", 0), "limit_test_batches": ("batches", 0),
    "limit_predict_batches": ("batches", 0), "val_check_interval": ("batches", 0),
}


def check_trainer_numbers(trainer: Mapping[str, Any], prefix: str = "trainer") -> None:
    """Check the numeric keys of a ``Trainer`` config node (:data:`TRAINER_NUMBERS`) before it is built.

    ``null`` means Lightning's default and is accepted. Raises :class:`ConfigError` naming
    ``<prefix>.<key>`` and the value (``trainer.max_steps=abc`` fails here, not inside Lightning).
    """
    for key, (kind, low) in TRAINER_NUMBERS.items():
        value = trainer.get(key)
        if value is None:
            continue
        full = f"{prefix}.{key}"
        if kind == "int":
            if not _is_int(value) or value < low:
                raise ConfigError(f"{full} must be a whole number ≥ {low:g}, got {value!r}")
        elif not _is_number(value) or not math.isfinite(value) or value < low:
            raise ConfigError(f"{full} must be a finite number ≥ {low:g}, got {value!r}")
        elif kind == "batches" and isinstance(value, float) and value > 1.0:
            raise ConfigError(f"{full} must be a whole number of batches or a fraction in [0, 1], got {value!r}")


def unique_id() -> str:
    """A run id: local time to the microsecond and 4 random hex digits, e.g. ``2025-06-01_12-30-45_123456_9f3a``.

    Ids sort by time (fixed-width fields), and two runs started in the same microsecond, or on two
    machines at once, still differ. The ``${unique_id:}`` resolver caches it, so one run (and all
    jobs of one sweep) sees one id.
    """
    return datetime.now().strftime("%Y-%m-%d_%H-%M-%S_%f") + "_" + secrets.token_hex(2)


def cpu_precision(cpuinfo: str | Path = "/proc/cpuinfo") -> str:
    """Lightning precision for CPU training: ``bf16-mixed`` where the CPU has bf16 instructions
    (AVX-512 BF16 or AMX, read from ``/proc/cpuinfo``), else ``32-true``.

    Without them bf16 autocast is emulated and an epoch takes ~40× longer than in float32 (measured
    on an AMD EPYC without AVX-512: 3.7 min against ~5 s per Bandai autoencoder epoch).
    """
    try:
        flags = Path(cpuinfo).read_text().split()
    except OSError:  # not Linux: no way to tell, float32 is always safe
        return "32-true"
    return "bf16-mixed" if {"avx512_bf16", "amx_bf16"} & set(flags) else "32-true"


def structured_schema(cls: type) -> Any:
    """``cls`` (a dataclass) as an OmegaConf structured config that overrides may change.

    Frozen dataclasses give read-only nodes, which Hydra could not override; the flag is cleared on
    every node (the dataclass itself stays frozen when built from the config).
    """
    from omegaconf import DictConfig, OmegaConf

    def unlock(node: DictConfig) -> None:
        node._set_flag("readonly", None)
        for key in node.keys():
            child = node._get_node(key)
            if isinstance(child, DictConfig):
                unlock(child)

    node = OmegaConf.structured(cls)
    unlock(node)
    return node


def build_settings(cls: type, values: Mapping[str, Any] | None, key: str) -> Any:
    """An instance of the dataclass ``cls`` from (partial) config values, defaults from ``cls``.

    ``key``: where the values sit in the command's config (``""``: at its top level).

    Raises:
        ConfigError: an unknown key or a value of the wrong type, named as ``<key>.<field>`` (``<field>`` at the
            top level).
    """
    from omegaconf import OmegaConf
    from omegaconf.errors import OmegaConfBaseException

    try:
        return OmegaConf.to_object(OmegaConf.merge(structured_schema(cls), values or {}))
    except OmegaConfBaseException as exc:
        where = getattr(exc, "full_key", None)
        if where:
            raise ConfigError(f"{key}.{where}: {str(exc).splitlines()[0]}" if key else
                              f"{where}: {str(exc).splitlines()[0]}") from None
        raise ConfigError(f"{key}: {exc}" if key else str(exc).splitlines()[0]) from None


def settings_from_config(cfg: Any, cls: type, command: str) -> tuple[dict[str, Any] | None, Any]:
    """A command's composed config (or a plain mapping of its keys) split into its ``data`` config (a plain dict,
    None when it has none) and its settings: the dataclass ``cls`` (whose defaults are the command's, the YAML
    repeating none) built from every other key by :func:`build_settings`.

    Raises:
        ConfigError: not a mapping; an unknown key, a value of the wrong type or a missing mandatory value, named.
    """
    from omegaconf import DictConfig, OmegaConf

    plain = OmegaConf.to_container(cfg, resolve=True) if isinstance(cfg, DictConfig) else dict(cfg)
    if not isinstance(plain, dict):
        raise ConfigError(f"the {command} config must be a mapping")
    data = plain.pop("data", None)
    return data, build_settings(cls, plain, "")


def _register_resolvers() -> None:
    from omegaconf import OmegaConf

    if not OmegaConf.has_resolver("cpu_precision"):
        OmegaConf.register_new_resolver("cpu_precision", cpu_precision)
    if not OmegaConf.has_resolver("unique_id"):
        OmegaConf.register_new_resolver("unique_id", unique_id, use_cache=True)


_register_resolvers()
