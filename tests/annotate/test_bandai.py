"""Real data, a fixed slice (normal style, four contents): the test takes of the slice score within the
tolerance its validation takes set.

The reference figures are the slice's VAL takes (per-take recall and precision, mean and sample SD), measured
once with the default settings by ``slice_scores("val")``; the test scores the TEST takes, which chose
nothing, and allows the val mean minus three standard errors of a difference of two means.
"""

import numpy as np
import pytest
from conftest import BANDAI_ZIP, shared_data_dir

from stylemotion.annotate.command import annotate_positions
from stylemotion.annotate.documents import join_takes, part_scores
from stylemotion.annotate.model import learn_model
from stylemotion.datasets import load_dataset

CONTENTS = ["walk", "walk-turn-left", "wave-left-hand", "raise-up-right-hand"]
#: ``slice_scores("val")``: (mean, SD) of per-take recall and precision over the slice's 16 val takes.
VAL_RECALL, VAL_PRECISION, VAL_TAKES = (0.9086, 0.1448), (0.9647, 0.1411), 16


def slice_scores(part: str) -> tuple[np.ndarray, np.ndarray]:
    """Per-take recall and precision of one document of the slice's ``part`` takes (name order), annotated
    with templates of its train takes and the default settings."""
    root = shared_data_dir(BANDAI_ZIP) / BANDAI_ZIP
    takeset = load_dataset("bandai", root=root, contents=CONTENTS, styles=["normal"])
    split = takeset.split(0, 0.1, 0.1)
    model = learn_model(split["train"], takeset.fps, per_class=9, seed=0, tensors=False)
    takes = sorted(split[part], key=lambda t: t.name)
    doc = join_takes([(t.name, t.content, t.style, t.positions) for t in takes], takeset.fps)
    labels, _ = annotate_positions(doc.positions, model)
    parts = part_scores(doc, labels)
    return np.array([p["recall"] for p in parts]), np.array([p["precision"] for p in parts])


def least_mean(val: tuple[float, float], test_takes: int) -> float:
    mean, sd = val
    return mean - 3 * sd * np.sqrt(1 / VAL_TAKES + 1 / test_takes)


@pytest.mark.realdata
def test_bandai_test_takes_within_the_validation_tolerance():
    recall, precision = slice_scores("test")
    assert len(recall) == 16
    assert recall.mean() >= least_mean(VAL_RECALL, len(recall))
    assert precision.mean() >= least_mean(VAL_PRECISION, len(precision))
