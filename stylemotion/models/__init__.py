"""Networks (plain ``nn.Module``s) and the Lightning modules that train them."""

from stylemotion.models.autoencoder import (
    ConvAutoencoder,
    IncompatibleModelError,
    MotionAutoencoder,
    NonFiniteLossError,
    local_mpjpe,
    mpjpe,
)
from stylemotion.models.cvae import StyleCVAE
from stylemotion.models.style import gram, mean_gram
from stylemotion.models.vae import MLPVAE, PrimitiveVAE

__all__ = ["MLPVAE", "ConvAutoencoder", "IncompatibleModelError", "MotionAutoencoder", "NonFiniteLossError",
           "PrimitiveVAE", "StyleCVAE", "gram", "local_mpjpe", "mean_gram", "mpjpe"]
