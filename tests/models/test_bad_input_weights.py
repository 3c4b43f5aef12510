"""A checkpoint whose weights hold NaN/inf (a diverged training) is named as such when loaded (issue 26: it used to
surface much later as "durations must be positive")."""

from __future__ import annotations

import pytest
import torch

from stylemotion.models.autoencoder import IncompatibleModelError, MotionAutoencoder
from stylemotion.models.checkpoints import load_autoencoder


@pytest.mark.parametrize("value", [float("nan"), float("inf")])
def test_a_checkpoint_with_non_finite_weights_is_named(value, tmp_path):
    model = MotionAutoencoder(hidden_units=8, kernel_size=3)
    state = model.state_dict()
    name = next(k for k, v in state.items() if v.is_floating_point() and v.ndim > 1)
    state[name] = state[name].clone()
    state[name].view(-1)[0] = value
    path = tmp_path / "diverged.ckpt"
    torch.save({"hyper_parameters": dict(model.hparams), "state_dict": state}, path)
    with pytest.raises(IncompatibleModelError, match=rf"{path}: the model's weights hold NaN/inf \(.*{name}"):
        load_autoencoder(path)
