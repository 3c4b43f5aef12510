"""The feature-set option: each set's columns, the set recorded in templates and folders, two sets never mixed."""

import json

import numpy as np
import pytest

from stylemotion.annotate import features, mueller_roeder
from stylemotion.annotate.annotation import AnnotationInputError, class_distances
from stylemotion.annotate.command import AnnotateInputError, annotate, learn
from stylemotion.annotate.documents import join_takes
from stylemotion.annotate.feature_sets import (
    FEATURE_SETS,
    FeatureSetError,
    compute_features,
    feature_names,
    same_feature_set,
)
from stylemotion.annotate.model import ModelFolderError, learn_model, load_model, save_model
from stylemotion.annotate.templates import sub_templates
from stylemotion.io.export import write_motion_bvh

SYNTHETIC = {"name": "synthetic", "split": {"seed": 0, "val_fraction": 0.1, "test_fraction": 0.1}}


def test_each_set_computes_its_own_columns(synthetic_split):
    take = synthetic_split["train"][0]
    assert FEATURE_SETS == ("ours", "mueller_roeder")
    assert np.array_equal(compute_features(take.positions, take.fps), features.relational_features(take.positions,
                                                                                                     take.fps))
    mr = compute_features(take.positions, take.fps, "mueller_roeder")
    assert np.array_equal(mr, mueller_roeder.mueller_roeder_features(take.positions, take.fps))
    assert mr.shape[1] == len(feature_names("mueller_roeder")) == 40
    with pytest.raises(FeatureSetError, match="feature_set='hdm05'.*ours, mueller_roeder"):
        compute_features(take.positions, take.fps, "hdm05")


@pytest.fixture(scope="module")
def mr_model(synthetic_split):
    return learn_model(synthetic_split["train"], 30.0, per_class=4, seed=0, tensors=False,
                       feature_set="mueller_roeder")


def test_templates_and_folder_record_the_set(mr_model, tmp_path):
    assert mr_model.feature_set == "mueller_roeder"
    assert all(t.feature_set == "mueller_roeder" and t.values.shape[1] == 40 for t in mr_model.templates)
    assert {w.feature_set for w in sub_templates(mr_model.templates[0], 20)} == {"mueller_roeder"}
    save_model(mr_model, tmp_path)
    meta = json.loads((tmp_path / "model.json").read_text())
    assert meta["feature_set"] == "mueller_roeder" and meta["features"] == list(mueller_roeder.FEATURE_NAMES)
    again = load_model(tmp_path)
    assert again.feature_set == "mueller_roeder"
    assert all(np.array_equal(a.values, b.values) for a, b in zip(again.templates, mr_model.templates))


def test_a_folder_whose_set_and_columns_disagree_is_refused(mr_model, tmp_path):
    save_model(mr_model, tmp_path)
    meta = json.loads((tmp_path / "model.json").read_text())
    (tmp_path / "model.json").write_text(json.dumps({**meta, "feature_set": "ours"}))
    with pytest.raises(ModelFolderError, match="feature set 'ours'"):
        load_model(tmp_path)
    (tmp_path / "model.json").write_text(json.dumps({**meta, "feature_set": "nope"}))
    with pytest.raises(ModelFolderError, match="feature_set='nope'"):
        load_model(tmp_path)


def test_templates_of_two_sets_are_never_matched_together(mr_model, synthetic_model, synthetic_split):
    take = synthetic_split["test"][0]
    mixed = [synthetic_model.templates[0], mr_model.templates[1]]
    with pytest.raises(AnnotationInputError, match=r"mix feature sets \['mueller_roeder', 'ours'\]"):
        class_distances(compute_features(take.positions, take.fps), mixed)
    with pytest.raises(FeatureSetError, match="mix feature sets"):
        same_feature_set(["ours", "mueller_roeder"])


def test_learn_and_annotate_with_mueller_roeder_and_refuse_another_set(synthetic_split, tmp_path):
    folder = tmp_path / "mr"
    learn(SYNTHETIC, folder, per_class=4, tensors=False, feature_set="mueller_roeder")
    assert json.loads((folder / "model.json").read_text())["feature_set"] == "mueller_roeder"
    takes = [(t.name, t.content, t.style, t.positions) for t in synthetic_split["test"][::4]]
    doc = join_takes(takes, 30.0)
    write_motion_bvh(doc.positions, tmp_path / "doc.bvh", 30.0)
    report = annotate(str(tmp_path / "doc.bvh"), folder, tmp_path / "out")
    assert report["feature_set"] == "mueller_roeder" and report["labelled_fraction"] > 0
    with pytest.raises(AnnotateInputError, match="feature_set=ours: .* learned with feature set 'mueller_roeder'"):
        annotate(str(tmp_path / "doc.bvh"), folder, tmp_path / "out2", feature_set="ours")
    assert not (tmp_path / "out2").exists()
    with pytest.raises(AnnotateInputError, match="feature_set='x'"):
        learn(SYNTHETIC, tmp_path / "bad", feature_set="x")
