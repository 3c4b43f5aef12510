"""The Gram style distance with one target per sequence (a batched factor), as the zero-shot network's
style term uses it: equal to one call per target, and to the direct formula."""

from __future__ import annotations

import torch

from stylemotion.models.style import feature_style_distance, gram, gram_factor, style_distance


def test_a_batched_target_factor_gives_each_sequence_its_own_target() -> None:
    generator = torch.Generator().manual_seed(0)
    features = torch.randn(3, 5, 16, 9, generator=generator)  # (samples, batch, C, T')
    examples = torch.randn(5, 16, 7, generator=generator)  # one example (C, T_x) per batch item
    batched = feature_style_distance(features, target_factor=examples / 7 ** 0.5)
    assert batched.shape == (3, 5)
    for i in range(5):
        one = feature_style_distance(features[:, i], target_gram=gram(examples[i]))
        direct = style_distance(gram(features[:, i]), gram(examples[i]))
        assert torch.allclose(batched[:, i], one, rtol=1e-5) and torch.allclose(batched[:, i], direct, rtol=1e-4)
    # one shared target, as before: the same as broadcasting it
    shared = feature_style_distance(features, target_gram=gram(examples[0]))
    broadcast = (examples[0] / 7 ** 0.5).expand(5, -1, -1)
    assert torch.allclose(shared, feature_style_distance(features, target_factor=broadcast), rtol=1e-5)


def test_the_summed_gram_is_eq_5_9_as_written() -> None:
    """``normalization="sum"``: Σ_t y_t y_tᵀ and its Frobenius distance, against a loop over time steps in numpy."""
    import numpy as np

    generator = torch.Generator().manual_seed(1)
    features = torch.randn(3, 5, 7, generator=generator, dtype=torch.float64)
    example = torch.randn(5, 9, generator=generator, dtype=torch.float64)
    y = features.numpy()
    by_hand = np.zeros((3, 5, 5))
    for i in range(3):
        for t in range(7):
            by_hand[i] += np.outer(y[i, :, t], y[i, :, t])
    target = sum(np.outer(example.numpy()[:, t], example.numpy()[:, t]) for t in range(9))
    np.testing.assert_allclose(gram(features, "sum").numpy(), by_hand, rtol=1e-12)
    np.testing.assert_allclose(gram(features).numpy(), by_hand / 7, rtol=1e-12)  # the default: ÷ T
    expected = np.sqrt(((by_hand - target) ** 2).sum((-1, -2)))
    got = feature_style_distance(features, gram(example, "sum"), normalization="sum")
    np.testing.assert_allclose(got.numpy(), expected, rtol=1e-9)
    # several examples average their summed Grams
    from stylemotion.models.style import mean_gram

    np.testing.assert_allclose(mean_gram([example, 2 * example], "sum").numpy(), 2.5 * target, rtol=1e-12)
    import pytest

    with pytest.raises(ValueError, match="normalization"):
        gram(features, "max")


def test_float32_distances_near_the_target_match_the_float64_direct_formula() -> None:
    """Near its target (where the expanded three-term form cancels, so it is computed in float64), the distance of
    float32 features matches the direct float64 ``‖FFᵀ/T − S‖_F`` to 1e-5 of ``‖S‖``, and far from it relatively."""
    generator = torch.Generator().manual_seed(2)
    example = torch.randn(256, 18, generator=generator, dtype=torch.float64) * 3.0
    target = gram(example)
    near = example[None] + 1e-3 * torch.randn(64, 256, 18, generator=generator, dtype=torch.float64)
    far = torch.randn(64, 256, 18, generator=generator, dtype=torch.float64)
    scale = torch.linalg.matrix_norm(target).item()
    for features in (near, far):
        direct = style_distance(gram(features), target)
        fast = feature_style_distance(features.float(), target_factor=gram_factor(target).float())
        assert fast.dtype == torch.float32
        assert torch.allclose(fast.double(), direct, rtol=1e-4, atol=1e-5 * scale), (fast - direct).abs().max()
    # the float64 path agrees with the direct formula to rounding
    exact = feature_style_distance(near, target_gram=target)
    assert torch.allclose(exact, style_distance(gram(near), target), rtol=1e-9, atol=1e-11 * scale)


def test_the_distance_has_the_direct_formulas_gradient() -> None:
    generator = torch.Generator().manual_seed(3)
    example = torch.randn(16, 6, generator=generator, dtype=torch.float64)
    features = torch.randn(4, 16, 9, generator=generator, dtype=torch.float64, requires_grad=True)
    fast = feature_style_distance(features, target_gram=gram(example)).sum()
    (grad_fast,) = torch.autograd.grad(fast, features)
    direct = style_distance(gram(features), gram(example)).sum()
    (grad_direct,) = torch.autograd.grad(direct, features)
    assert torch.allclose(grad_fast, grad_direct, rtol=1e-8, atol=1e-10)
