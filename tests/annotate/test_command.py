import csv
import json

import pytest

from stylemotion.annotate.command import AnnotateInputError, annotate, learn
from stylemotion.annotate.documents import join_takes
from stylemotion.io.export import write_motion_bvh
from stylemotion.io.outputs import OutputExistsError

SYNTHETIC = {"name": "synthetic", "split": {"seed": 0, "val_fraction": 0.1, "test_fraction": 0.1}}


@pytest.fixture(scope="module")
def templates_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("annotate") / "templates"
    learn(SYNTHETIC, out, per_class=9)
    return out


def test_learn_then_annotate_a_bvh(templates_dir, synthetic_split, tmp_path):
    meta = json.loads((templates_dir / "model.json").read_text())
    assert [c["label"] for c in meta["classes"]] == ["run", "walk", "walk-turn-left", "walk-turn-right"]
    assert set(meta["tensors"]) == {"run", "walk", "walk-turn-left", "walk-turn-right"}
    takes = [(t.name, t.content, t.style, t.positions) for t in synthetic_split["test"][::4]]
    doc = join_takes(takes, 30.0)
    write_motion_bvh(doc.positions, tmp_path / "doc.bvh", 30.0)
    report = annotate(str(tmp_path / "doc.bvh"), templates_dir, tmp_path / "out")
    with open(tmp_path / "out" / "labels.csv") as f:
        rows = list(csv.reader(f))
    assert rows[0] == ["frame", "label"] and len(rows) == 1 + len(doc.labels)
    assert [int(r[0]) for r in rows[1:]] == list(range(len(doc.labels)))
    assert {r[1] for r in rows[1:]} <= {"", *meta_classes(meta)}
    right = sum(r[1] == want for r, want in zip(rows[1:], doc.labels) if want)
    assert right / sum(1 for want in doc.labels if want) > 0.6
    assert (tmp_path / "out" / "timeline.png").stat().st_size > 1000
    assert report["segments"] == json.loads((tmp_path / "out" / "segments.json").read_text())["segments"]
    with pytest.raises(OutputExistsError):
        annotate(str(tmp_path / "doc.bvh"), templates_dir, tmp_path / "out")


def meta_classes(meta):
    return [c["label"] for c in meta["classes"]]


def test_document_shorter_than_every_template(templates_dir, synthetic_split, tmp_path):
    take = synthetic_split["test"][0]
    write_motion_bvh(take.positions[:20], tmp_path / "short.bvh", 30.0)
    with pytest.raises(AnnotateInputError, match=r"20 frames at 30 fps is shorter than every template"):
        annotate(str(tmp_path / "short.bvh"), templates_dir, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_unmappable_skeleton(templates_dir, tiny_bvh, write_text, tmp_path):
    path = write_text(tiny_bvh, "four_joints.bvh")
    with pytest.raises(AnnotateInputError, match="four_joints.bvh.*joint_map="):
        annotate(str(path), templates_dir, tmp_path / "out")


def test_missing_templates_and_small_classes(tmp_path):
    with pytest.raises(AnnotateInputError, match="no model.json"):
        annotate("x.bvh", tmp_path / "nothing", tmp_path / "out")
    one_each = {**SYNTHETIC, "contents": ["walk"], "styles": ["normal"]}
    with pytest.raises(AnnotateInputError, match="'walk' has 1 example motion"):
        learn(one_each, tmp_path / "t", per_class=1)


def test_a_keyframe_tolerance_outside_zero_to_one_is_refused(tmp_path):
    from stylemotion.annotate.annotation import AnnotationSettings
    from stylemotion.annotate.command import AnnotateInputError, annotate

    with pytest.raises(AnnotateInputError, match=r"keyframes.tolerance=5 must be a fraction in \[0, 1\]"):
        annotate("walk.bvh", tmp_path / "templates", tmp_path / "out",
                 settings=AnnotationSettings(keyframes=True, keyframe_tolerance=5))
    assert not (tmp_path / "out").exists()


def test_the_templates_folder_holds_each_class_turning_and_the_report_says_whether_the_layer_ran(
        templates_dir, synthetic_split, tmp_path):
    from stylemotion.annotate.annotation import AnnotationSettings
    from stylemotion.annotate.turning import turning_rate

    meta = json.loads((templates_dir / "model.json").read_text())
    turning = meta["turning"]
    assert set(turning) == set(meta_classes(meta))
    walks = [t.positions for t in synthetic_split["train"] if t.content == "walk"]
    assert turning["walk"]["takes"] == len(walks)
    assert turning["walk"]["mean"] == pytest.approx(sum(turning_rate(p, 30.0) for p in walks) / len(walks))
    take = synthetic_split["test"][0]
    write_motion_bvh(take.positions, tmp_path / "doc.bvh", 30.0)
    on = annotate(str(tmp_path / "doc.bvh"), templates_dir, tmp_path / "on", settings=AnnotationSettings(turning_z=1))
    off = annotate(str(tmp_path / "doc.bvh"), templates_dir, tmp_path / "off", settings=AnnotationSettings(turning_z=0))
    assert on["settings"]["turning_layer"] is True and off["settings"]["turning_layer"] is False


@pytest.mark.parametrize("key", ["turning_z", "turning_window_s", "sub_frames"])
def test_negative_layer_settings_are_refused(key, tmp_path):
    from stylemotion.annotate.annotation import AnnotationSettings

    with pytest.raises(AnnotateInputError, match=rf"{key}=-1 must be a number ≥ 0"):
        annotate("walk.bvh", tmp_path / "templates", tmp_path / "out", settings=AnnotationSettings(**{key: -1}))
    assert not (tmp_path / "out").exists()
