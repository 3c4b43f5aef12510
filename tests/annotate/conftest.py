"""Shared fixtures of the annotation tests: the synthetic dataset's split and a model learned from it."""

from __future__ import annotations

import pytest

from stylemotion.annotate.model import learn_model
from stylemotion.datasets import load_dataset


@pytest.fixture(scope="package")
def synthetic_split():
    return load_dataset("synthetic").split(0, 0.1, 0.1)


@pytest.fixture(scope="package")
def synthetic_model(synthetic_split):
    return learn_model(synthetic_split["train"], 30.0, per_class=9, seed=0)
