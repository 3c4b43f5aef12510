"""Networks (plain ``nn.Module``s), the Lightning modules that train them, and the one path that
loads their checkpoints (:mod:`stylemotion.models.loading`; the checkpoint records, which import no model
class: :mod:`stylemotion.models.checkpoints`). Nothing here imports
:mod:`stylemotion.datamodules`: the data side builds on the models, not the other way round."""

from stylemotion.models.autoencoder import (
    ConvAutoencoder,
    IncompatibleModelError,
    MotionAutoencoder,
    NonFiniteLossError,
    local_mpjpe,
    mpjpe,
)
from stylemotion.models.checkpoints import load_autoencoder
from stylemotion.models.cvae import StyleCVAE
from stylemotion.models.loading import load_generative
from stylemotion.models.style import gram, mean_gram
from stylemotion.models.vae import MLPVAE, PrimitiveVAE
from stylemotion.models.zero_shot import ZeroShotStyleVAE

__all__ = ["MLPVAE", "ConvAutoencoder", "IncompatibleModelError", "MotionAutoencoder", "NonFiniteLossError",
           "PrimitiveVAE", "StyleCVAE", "ZeroShotStyleVAE", "gram", "load_autoencoder", "load_generative",
           "local_mpjpe", "mean_gram", "mpjpe"]
