import numpy as np
import pytest
from scipy.optimize import lsq_linear

from stylemotion.annotate.tensors import (
    WEIGHT_BOUNDS,
    TensorInputError,
    _bounded_least_squares,
    build_tensor,
)


@pytest.fixture(scope="module")
def walk_tensor(synthetic_split):
    examples = {}
    for take in synthetic_split["train"]:
        if take.content == "walk" and take.style in ("normal", "elderly", "feminine"):
            examples.setdefault(take.style, []).append(take.positions)
    return build_tensor("walk", examples, 30.0, repetitions=2)


def test_unit_weights_return_the_examples(walk_tensor):
    tensor, theta = walk_tensor
    assert theta.shape == (63, tensor.frames, 3, 2)
    for s in range(3):
        for r in range(2):
            motion = tensor.synthesize(np.eye(3)[s], np.eye(2)[r])
            assert np.abs(motion - theta[:, :, s, r].T).max() < 1e-10


def test_truncation_keeps_shapes_and_costs_accuracy(walk_tensor):
    tensor, theta = walk_tensor
    small = tensor.truncated((10, 20, 3, 1))
    assert small.ranks == (10, 20, 3, 1) and small.nbytes < tensor.nbytes
    error = np.abs(small.synthesize(np.eye(3)[0], np.eye(2)[0]) - theta[:, :, 0, 0].T).mean()
    assert 0 < error < 0.05                                  # metres
    with pytest.raises(ValueError, match="ranks"):
        tensor.truncated((100, 1, 1, 1))


def test_parametrization_names_the_style_of_a_held_out_take(walk_tensor, synthetic_split):
    tensor, _ = walk_tensor
    fits = {t.style: tensor.parametrize(t.positions) for t in synthetic_split["test"]
            if t.content == "walk" and t.style in tensor.styles}
    assert set(fits) == set(tensor.styles)
    assert all(fit.style == style for style, fit in fits.items())
    assert all(((-0.2 - 1e-9 <= fit.style_weights) & (fit.style_weights <= 1.2 + 1e-9)).all() for fit in fits.values())


def test_bad_input(synthetic_split):
    walk = [t.positions for t in synthetic_split["train"] if t.content == "walk"]
    with pytest.raises(TensorInputError, match="at least 2 styles"):
        build_tensor("walk", {"normal": walk[:3]}, 30.0)
    with pytest.raises(TensorInputError, match="fewer than 2"):
        build_tensor("walk", {"normal": walk[:3], "elderly": walk[3:4]}, 30.0, repetitions=2)


def test_bounded_least_squares_equals_the_full_problem():
    rng = np.random.default_rng(4)
    a, b = rng.normal(size=(500, 6)), rng.normal(size=500) * 3
    want = lsq_linear(a, b, bounds=WEIGHT_BOUNDS, method="bvls").x
    assert np.allclose(_bounded_least_squares(a, b), want, atol=1e-9)
