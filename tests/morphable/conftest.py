"""Shared synthetic clips and small fitted models for the Morphable Graph tests."""

from __future__ import annotations

import pytest

from stylemotion.datamodules.clips import ClipDataModule
from stylemotion.datasets.registry import load_synthetic
from stylemotion.morphable import FitSettings, MorphableModel, fit_primitive


@pytest.fixture(scope="session")
def walk_takes():
    return load_synthetic(takes_per_pair=6, seed=0, duration_s=6.0, styles=["normal"],
                          contents=["walk", "walk-turn-left", "walk-turn-right"])


def _clips(takes, primitive: str):
    dm = ClipDataModule(takeset=takes, primitives=[primitive], styles=["normal"],
                        split={"seed": 0, "val_fraction": 0.0, "test_fraction": 0.2})
    dm.setup()
    return dm.clips


@pytest.fixture(scope="session")
def left_clips(walk_takes):
    return _clips(walk_takes, "leftStance")


@pytest.fixture(scope="session")
def right_clips(walk_takes):
    return _clips(walk_takes, "rightStance")


@pytest.fixture(scope="session")
def left_model(left_clips) -> MorphableModel:
    model = fit_primitive(left_clips["train"], FitSettings(latent_dim=6, reduction="fpca", num_coefficients=6))
    model.build_tree(1000, seed=0)
    return model


@pytest.fixture(scope="session")
def right_model(right_clips) -> MorphableModel:
    model = fit_primitive(right_clips["train"], FitSettings(latent_dim=6, reduction="fpca", num_coefficients=6))
    model.build_tree(1000, seed=0)
    return model
