"""Skin-marker sets: segment frames, virtual markers (offsets as specified, moving rigidly with the body), the CSV
of a user's set and its one-line errors."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from stylemotion.datasets.registry import load_dataset
from stylemotion.reconstruct.marker_set import (
    SKIN_MARKERS,
    joint_marker_set,
    marker_set_named,
    read_marker_set,
    segment_frames,
    virtual_markers,
)
from stylemotion.reconstruct.markers import MarkerInputError
from stylemotion.skeleton import JOINT_INDEX


@pytest.fixture(scope="module")
def motion():
    return np.asarray(load_dataset("synthetic", takes_per_pair=1).takes[0].positions[:50], np.float64)


def test_segment_frames_are_rotations_along_the_bone(motion):
    frames = segment_frames(motion, ["Hand_L", "Hips", "Foot_R"])
    eye = np.einsum("fsji,fsjk->fsik", frames, frames)
    np.testing.assert_allclose(eye, np.broadcast_to(np.eye(3), eye.shape), atol=1e-9)
    np.testing.assert_allclose(np.linalg.det(frames), 1.0, atol=1e-9)
    forearm = motion[:, JOINT_INDEX["Hand_L"]] - motion[:, JOINT_INDEX["LowerArm_L"]]
    np.testing.assert_allclose(frames[:, 0, :, 1], forearm / np.linalg.norm(forearm, axis=-1, keepdims=True),
                               atol=1e-9)
    left = motion[:, JOINT_INDEX["UpperLeg_L"]] - motion[:, JOINT_INDEX["UpperLeg_R"]]
    assert np.all(np.sum(frames[:, 1, :, 0] * left, axis=-1) > 0)  # the hips' x points to the body's left


def test_virtual_markers_sit_at_their_offset_and_move_rigidly(motion):
    markers = virtual_markers(motion, SKIN_MARKERS)
    for m, marker in enumerate(SKIN_MARKERS.markers):
        distance = np.linalg.norm(markers[:, m] - motion[:, JOINT_INDEX[marker.segment]], axis=-1)
        np.testing.assert_allclose(distance, np.linalg.norm(marker.offset), atol=1e-9)
    sacrum = markers[:, SKIN_MARKERS.names.index("SACR")] - motion[:, JOINT_INDEX["Hips"]]
    wrist = markers[:, SKIN_MARKERS.names.index("LWRI")] - motion[:, JOINT_INDEX["Hand_L"]]
    left = motion[:, JOINT_INDEX["UpperArm_L"]] - motion[:, JOINT_INDEX["UpperArm_R"]]
    assert np.all(np.sum(wrist * left, axis=-1) > 0)  # the left wrist marker sits on the left of the wrist
    facing = np.cross(left, [0.0, 1.0, 0.0])
    assert np.all(np.sum(sacrum * facing, axis=-1) < 0)  # the sacrum marker sits behind the hips
    turn = Rotation.from_euler("y", 70, degrees=True).as_matrix()
    moved = motion @ turn.T + np.array([2.0, 0.1, -1.0])
    np.testing.assert_allclose(virtual_markers(moved, SKIN_MARKERS), markers @ turn.T + np.array([2.0, 0.1, -1.0]),
                               atol=1e-9)


def test_joint_markers_are_the_joints(motion):
    joints = joint_marker_set(["Hips", "Hand_R"])
    np.testing.assert_array_equal(virtual_markers(motion, joints), motion[:, [JOINT_INDEX["Hips"],
                                                                              JOINT_INDEX["Hand_R"]]])
    assert joints.is_joint_centres and not SKIN_MARKERS.is_joint_centres
    assert marker_set_named("skin") is SKIN_MARKERS and marker_set_named(None).names[0] == "Hand_L"


def test_a_set_from_csv_and_its_errors(tmp_path):
    path = tmp_path / "set.csv"
    path.write_text("name,segment,x,y,z\nLW,Hand_L,0.02,0,0\nC7,Neck,0,0,-0.05\n")
    marker_set = read_marker_set(path)
    assert marker_set.names == ("LW", "C7") and marker_set.markers[1].offset == (0.0, 0.0, -0.05)
    cases = {"name,segment,x,y,z\nLW,Wrist,0,0,0\n": "segment 'Wrist'",
             "name,segment,x,y,z\nLW,Hand_L,0,abc,0\n": "line 2, column y: 'abc'",
             "name,segment,x,y,z\nLW,Hand_L,0,0,0\nLW,Hand_R,0,0,0\n": "named more than once",
             "name,segment,x,y,z\nA,Hand_L,0,0,0\nB,Hand_L,0,0,0.1\n": "more than one marker",
             "name,segment,x,y,z\nA,Hand_L,0,0,5\n": "within 1 m",
             "marker,joint\n": "line 1 must be the header"}
    for text, message in cases.items():
        path.write_text(text)
        with pytest.raises(MarkerInputError, match=message):
            read_marker_set(path)
    with pytest.raises(MarkerInputError, match="no such file"):
        marker_set_named(str(tmp_path / "none.csv"))
