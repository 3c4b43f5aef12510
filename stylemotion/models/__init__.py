"""Networks (plain ``nn.Module``s), the Lightning modules that train them, and the one path that
loads their checkpoints (:mod:`stylemotion.models.loading`; the checkpoint records, which import no model
class: :mod:`stylemotion.models.checkpoints`). Nothing here imports
:mod:`stylemotion.datamodules`: the data side builds on the models, not the other way round.

The names below load their module on first use (PEP 562), so that importing a light module of this
package (:mod:`stylemotion.models.sampling`, :mod:`stylemotion.models.style`) loads no Lightning.
"""

from __future__ import annotations

import importlib
from typing import Any

#: Public name → the module of this package that defines it.
_HOMES = {
    "ConvAutoencoder": "autoencoder", "IncompatibleModelError": "autoencoder", "MotionAutoencoder": "autoencoder",
    "NonFiniteLossError": "autoencoder", "local_mpjpe": "autoencoder", "mpjpe": "autoencoder",
    "load_autoencoder": "checkpoints", "StyleCVAE": "cvae", "load_generative": "loading", "gram": "style",
    "mean_gram": "style", "MLPVAE": "vae", "PrimitiveVAE": "vae", "ZeroShotStyleVAE": "zero_shot",
}

__all__ = ["MLPVAE", "ConvAutoencoder", "IncompatibleModelError", "MotionAutoencoder", "NonFiniteLossError",
           "PrimitiveVAE", "StyleCVAE", "ZeroShotStyleVAE", "gram", "load_autoencoder", "load_generative",
           "local_mpjpe", "mean_gram", "mpjpe"]


def __getattr__(name: str) -> Any:
    if name not in _HOMES:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{_HOMES[name]}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
