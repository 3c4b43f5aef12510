"""Real data: a document of Bandai test takes is annotated with their contents (normal style, four contents)."""

import pytest
from conftest import BANDAI_ZIP, shared_data_dir

from stylemotion.annotate.annotation import frame_scores, segment_scores
from stylemotion.annotate.command import annotate_positions
from stylemotion.annotate.documents import join_takes
from stylemotion.annotate.model import learn_model
from stylemotion.datasets import load_dataset

CONTENTS = ["walk", "walk-turn-left", "wave-left-hand", "raise-up-right-hand"]


@pytest.mark.realdata
def test_bandai_document_of_test_takes():
    root = shared_data_dir(BANDAI_ZIP) / BANDAI_ZIP
    takeset = load_dataset("bandai", root=root, contents=CONTENTS, styles=["normal"])
    split = takeset.split(0, 0.1, 0.1)
    model = learn_model(split["train"], takeset.fps, per_class=9, seed=0, tensors=False)
    doc = join_takes([(t.name, t.content, t.style, t.positions) for t in split["test"]], takeset.fps)
    assert len(doc.parts) == 16
    labels, _ = annotate_positions(doc.positions, model)
    frame, segment = frame_scores(doc.labels, labels), segment_scores(doc.labels, labels)
    # measured: P1 0.91, R1 0.89, F1 0.90; P2 0.94, R2 1.0, F2 0.97 (2158 frames, 16 takes)
    assert frame["F1"] > 0.87 and segment["R2"] == 1.0 and segment["F2"] > 0.95
