"""Marker sets and tracks: names, NPZ/CSV/BVH reading, gap filling and its errors."""

from __future__ import annotations

import numpy as np
import pytest

from stylemotion.reconstruct.markers import (
    DEFAULT_MARKERS,
    MarkerGapWarning,
    MarkerInputError,
    check_marker_names,
    fill_gaps,
    read_markers,
    tracks_from_positions,
    write_marker_csv,
)
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX


def _motion(frames: int = 12) -> np.ndarray:
    rng = np.random.default_rng(0)
    return rng.normal(0, 0.3, (frames, len(CANONICAL_JOINTS), 3))


def test_unknown_and_repeated_names_are_named():
    with pytest.raises(MarkerInputError, match="'Wrist_L'"):
        check_marker_names(["Hand_L", "Wrist_L"])
    with pytest.raises(MarkerInputError, match="Hips"):
        check_marker_names(["Hips", "Hips"])
    with pytest.raises(MarkerInputError, match="empty"):
        check_marker_names([])
    assert check_marker_names(DEFAULT_MARKERS) == DEFAULT_MARKERS


def test_interior_gaps_are_interpolated_with_a_warning_naming_them():
    track = np.zeros((6, 1, 3))
    track[:, 0, 0] = np.arange(6.0)
    track[2:4, 0, :] = np.nan
    with pytest.warns(MarkerGapWarning, match=r"Head missing at frames 2-3"):
        filled, which = fill_gaps(track, ["Head"])
    assert which == {"Head": [2, 3]}
    np.testing.assert_allclose(filled[:, 0, 0], np.arange(6.0))


@pytest.mark.parametrize("frame", [0, 5])
def test_edge_gaps_raise_naming_joint_and_frame(frame):
    track = np.ones((6, 2, 3))
    track[frame, 1, 2] = np.nan
    with pytest.raises(MarkerInputError, match=f"Foot_R is missing at frame {frame}"):
        fill_gaps(track, ["Head", "Foot_R"])


def test_npz_as_convert_writes_it(tmp_path):
    positions = _motion()
    path = tmp_path / "m.npz"
    np.savez(path, positions=positions, joint_names=np.array(CANONICAL_JOINTS), fps=np.float64(30))
    tracks = read_markers(path)
    assert tracks.joints == DEFAULT_MARKERS and tracks.fps == 30
    np.testing.assert_allclose(tracks.positions[:, 4], positions[:, JOINT_INDEX["Head"]])
    np.testing.assert_allclose(tracks.full, positions)
    with pytest.raises(MarkerInputError, match="'Nose'"):
        read_markers(path, joints=["Hips", "Nose"])


def test_csv_round_trip_gaps_and_bad_cells(tmp_path):
    positions = _motion()[:, [JOINT_INDEX[j] for j in ("Hips", "Head")]]
    holey = positions.copy()
    holey[4, 1] = np.nan
    path = write_marker_csv(tmp_path / "m.csv", ["Hips", "Head"], holey, 25)
    with pytest.warns(MarkerGapWarning, match="Head missing at frames 4"):
        tracks = read_markers(path)
    assert tracks.joints == ("Hips", "Head") and tracks.fps == 25 and tracks.full is None
    np.testing.assert_allclose(tracks.positions[3:6:2], positions[3:6:2], atol=1e-6)
    np.testing.assert_allclose(tracks.positions[4, 1], (positions[3, 1] + positions[5, 1]) / 2, atol=1e-6)
    with pytest.raises(MarkerInputError, match="Hand_L"):
        read_markers(path, joints=["Hand_L"])
    lines = path.read_text().splitlines()
    lines[3] = lines[3].replace(lines[3].split(",")[2], "abc", 1)
    path.write_text("\n".join(lines))
    with pytest.raises(MarkerInputError, match="line 3.*'abc'"):
        read_markers(path)
    path.write_text("frame,Elbow_x,Elbow_y,Elbow_z\n0,1,2,3\n")
    with pytest.raises(MarkerInputError, match="'Elbow'"):
        read_markers(path)


def test_missing_csv_rows_are_gaps(tmp_path):
    path = tmp_path / "m.csv"
    path.write_text("frame,Hips_x,Hips_y,Hips_z\n0,0,1,0\n2,2,1,0\n")
    with pytest.warns(MarkerGapWarning, match="frames 1"):
        tracks = read_markers(path, fps=30)
    np.testing.assert_allclose(tracks.positions[:, 0, 0], [0, 1, 2])


def test_bvh_through_the_project_conversion(tmp_path):
    from stylemotion.datasets.registry import load_dataset
    from stylemotion.io.export import write_motion_bvh

    take = load_dataset("synthetic", takes_per_pair=1).takes[0]
    path = tmp_path / "take.bvh"
    write_motion_bvh(take.positions[:20], path, 30.0)
    tracks = read_markers(f"{path}:0-10", fps=30.0)
    assert tracks.positions.shape == (10, 6, 3) and tracks.full.shape == (10, 21, 3)
    np.testing.assert_allclose(tracks.positions[:, 5], take.positions[:10, JOINT_INDEX["Hips"]], atol=0.01)
    with pytest.raises(MarkerInputError, match="must end in"):
        read_markers(tmp_path / "x.txt")


def test_tracks_from_positions_checks_shape():
    with pytest.raises(MarkerInputError, match=r"\(frames, 21, 3\)"):
        tracks_from_positions(np.zeros((3, 5, 3)), DEFAULT_MARKERS, 30)
