"""The Gram style distance with one target per sequence (a batched factor), as the zero-shot network's
style term uses it: equal to one call per target, and to the direct formula."""

from __future__ import annotations

import torch

from stylemotion.models.style import feature_style_distance, gram, style_distance


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
