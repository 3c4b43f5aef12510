"""Regression on a fixed slice of Bandai (realdata): a small raise-up-left-hand ``raise`` model fitted on the train
takes of style normal (split seed 0), checked on the **test** takes against tolerances set from the **val** takes.

The references are the val figures of suite ``morphable`` (``benchmarks/results/morphable.json``,
``results.regression``: ``val_joint_rmse_m`` and ``val_keyframe_max_m``), each with 50 % headroom; nothing measured
on the test takes set them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from stylemotion.datasets import load_dataset
from stylemotion.morphable import FitSettings, fit_primitive
from stylemotion.morphable.heldout import keyframe_errors
from stylemotion.morphable.model import reconstruction_error
from stylemotion.primitives.arm import arm_clips
from stylemotion.skeleton import CANONICAL_JOINTS

#: val joint RMSE of the small model (results.regression.val_joint_rmse_m), metres.
VAL_JOINT_RMSE_M = 0.00837
#: largest val Hand_L error after MAP at the default σ_c (results.regression.val_keyframe_max_m), metres.
VAL_KEYFRAME_MAX_M = 0.01114
HEADROOM = 1.5


@pytest.mark.realdata
def test_bandai_raise_model_on_test_takes_within_the_val_tolerances(bandai_zip_path: Path) -> None:
    takes = load_dataset("bandai", root=bandai_zip_path, contents=["raise-up-left-hand"], styles=["normal"])
    split = takes.split(seed=0, val_fraction=0.1, test_fraction=0.1)
    train, _ = arm_clips(split["train"], "raise-up-left-hand", "raise")
    test, _ = arm_clips(split["test"], "raise-up-left-hand", "raise")
    assert len(train) >= 50 and len(test) >= 5, (len(train), len(test))
    model = fit_primitive(train, FitSettings(latent_dim=8, reduction="fpca"))
    model.build_tree(2000, seed=0)
    assert reconstruction_error(model, test) <= HEADROOM * VAL_JOINT_RMSE_M
    j = CANONICAL_JOINTS.index("Hand_L")
    found = keyframe_errors(model, np.stack([c.positions[-1, j] for c in test]), "Hand_L", 0.005)
    assert found["failures"] == 0 and max(found["errors_m"]) <= HEADROOM * VAL_KEYFRAME_MAX_M, found["errors_m"]
