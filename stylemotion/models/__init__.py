"""Networks (plain ``nn.Module``s) and the Lightning modules that train them.

``PrimitiveVAE``, ``MLPVAE`` and ``StyleCVAE`` are imported on first access: their modules build on
:mod:`stylemotion.datamodules.features`, which itself imports the autoencoder from this package.
"""

from importlib import import_module
from typing import Any

from stylemotion.models.autoencoder import (
    ConvAutoencoder,
    IncompatibleModelError,
    MotionAutoencoder,
    NonFiniteLossError,
    local_mpjpe,
    mpjpe,
)
from stylemotion.models.style import gram, mean_gram

_LAZY = {"MLPVAE": "stylemotion.models.vae", "PrimitiveVAE": "stylemotion.models.vae",
         "StyleCVAE": "stylemotion.models.cvae"}

__all__ = ["MLPVAE", "ConvAutoencoder", "IncompatibleModelError", "MotionAutoencoder", "NonFiniteLossError",
           "PrimitiveVAE", "StyleCVAE", "gram", "local_mpjpe", "mean_gram", "mpjpe"]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        return getattr(import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
