"""The normalizer module: identity until given statistics, z-scores over the last dimension and back, checked
statistics, and statistics that travel in a state dict (a checkpoint)."""

from __future__ import annotations

import numpy as np
import pytest
import torch
from torch import nn

from stylemotion.models.normalization import Normalizer


def test_a_fresh_normalizer_is_the_identity_and_not_initialized() -> None:
    norm = Normalizer(3)
    x = torch.randn(4, 5, 3)
    assert not norm.initialized
    assert torch.equal(norm.normalize(x), x) and torch.equal(norm.denormalize(x), x)


def test_z_scores_over_the_last_dimension_and_back() -> None:
    norm = Normalizer(3)
    mean, std = np.array([1.0, -2.0, 10.0]), np.array([0.5, 2.0, 4.0])
    norm.set_stats(mean, std)
    assert norm.initialized
    x = torch.tensor([[[1.5, 0.0, 2.0], [1.0, -2.0, 10.0]]])  # (1, 2, 3)
    z = norm.normalize(x)
    torch.testing.assert_close(z, torch.tensor([[[1.0, 1.0, -2.0], [0.0, 0.0, 0.0]]]))
    torch.testing.assert_close(norm.denormalize(z), x)
    batch = torch.randn(8, 30, 3, dtype=torch.float32) * 3 + 1
    torch.testing.assert_close(norm.denormalize(norm.normalize(batch)), batch, rtol=1e-5, atol=1e-5)


def test_statistics_of_data_make_it_standard() -> None:
    rng = np.random.default_rng(0)
    data = rng.normal([5.0, -1.0], [3.0, 0.1], size=(2000, 2)).astype(np.float32)
    norm = Normalizer(2)
    norm.set_stats(torch.from_numpy(data.mean(0)), torch.from_numpy(data.std(0)))  # tensors as well as arrays
    z = norm.normalize(torch.from_numpy(data))
    torch.testing.assert_close(z.mean(0), torch.zeros(2), atol=1e-4, rtol=0)
    torch.testing.assert_close(z.std(0, unbiased=False), torch.ones(2), atol=1e-4, rtol=0)


@pytest.mark.parametrize("mean, std, message", [
    (np.zeros(2), np.ones(3), r"must have 3 channels, got mean \(2,\) and std \(3,\)"),
    (np.zeros(3), np.ones(4), "must have 3 channels"),
    (np.zeros(3), np.array([1.0, 0.0, 1.0]), "finite with std > 0"),
    (np.zeros(3), np.array([1.0, -1.0, 1.0]), "finite with std > 0"),
    (np.array([0.0, np.nan, 0.0]), np.ones(3), "finite with std > 0"),
    (np.zeros(3), np.array([1.0, np.inf, 1.0]), "finite with std > 0"),
])
def test_bad_statistics_are_refused_and_change_nothing(mean, std, message) -> None:
    norm = Normalizer(3)
    norm.set_stats(np.ones(3), np.full(3, 2.0))
    with pytest.raises(ValueError, match=message):
        norm.set_stats(mean, std)
    assert torch.equal(norm.mean, torch.ones(3)) and torch.equal(norm.std, torch.full((3,), 2.0))


def test_statistics_travel_in_the_state_dict() -> None:
    class Model(nn.Module):
        def __init__(self) -> None:
            super().__init__()
            self.norm = Normalizer(4)
            self.linear = nn.Linear(4, 4)

    trained = Model()
    trained.norm.set_stats(np.arange(4.0), np.arange(1.0, 5.0))
    state = trained.state_dict()
    assert {"norm.mean", "norm.std", "norm._initialized"} <= set(state)  # persistent buffers, not parameters
    assert not any(name.startswith("norm.") for name, _ in trained.named_parameters())
    loaded = Model()
    assert not loaded.norm.initialized
    loaded.load_state_dict(state)
    assert loaded.norm.initialized
    x = torch.randn(3, 4)
    torch.testing.assert_close(loaded.norm.normalize(x), trained.norm.normalize(x))
