"""Networks (plain ``nn.Module``s) and the Lightning modules that train them."""

from stylemotion.models.autoencoder import (
    ConvAutoencoder,
    IncompatibleModelError,
    MotionAutoencoder,
    NonFiniteLossError,
    local_mpjpe,
    mpjpe,
)

__all__ = ["ConvAutoencoder", "IncompatibleModelError", "MotionAutoencoder", "NonFiniteLossError", "local_mpjpe",
           "mpjpe"]
