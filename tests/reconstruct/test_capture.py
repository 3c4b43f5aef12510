"""Marker tracks from captures: C3D files written with ezc3d's writer (units, axes, labels, gaps, bad files),
CSV at another rate, resampling and virtual markers on a motion."""

from __future__ import annotations

import numpy as np
import pytest
from c3d_writer import write_c3d

from stylemotion.reconstruct.capture import read_c3d, read_capture, resample_tracks, tracks_on_motion
from stylemotion.reconstruct.marker_set import SKIN_MARKERS, joint_marker_set, virtual_markers
from stylemotion.reconstruct.markers import MarkerGapWarning, MarkerInputError, MarkerTracks, write_marker_csv


def y_up_to_z_up_mm(positions_m):
    """Metres Y up → millimetres Z up, as capture systems write them: (x, y, z) → (x, −z, y)."""
    p = np.asarray(positions_m, np.float64)
    return np.stack([p[..., 0], -p[..., 2], p[..., 1]], axis=-1) * 1000.0


def test_c3d_in_mm_z_up_reads_as_metres_y_up_with_labels_mapped(tmp_path):
    rng = np.random.default_rng(0)
    truth = rng.uniform(-1, 1, (40, 6, 3))
    labels = ["Subj:" + n for n in SKIN_MARKERS.names[:-1]] + ["PELVIS_BACK", "EXTRA"]
    xyz = np.concatenate([y_up_to_z_up_mm(truth), np.zeros((40, 1, 3))], axis=1)
    path = write_c3d(tmp_path / "a.c3d", labels, xyz, 120)
    tracks = read_c3d(path, SKIN_MARKERS, names={"SACR": "PELVIS_BACK"})
    assert tracks.joints == SKIN_MARKERS.names and tracks.fps == 120 and tracks.full is None
    np.testing.assert_allclose(tracks.positions, truth, atol=1e-5)
    with pytest.raises(MarkerInputError, match=r"a\.c3d: marker SACR: no point labelled 'SACR'"):
        read_c3d(path, SKIN_MARKERS)


def test_c3d_gaps_are_filled_or_named(tmp_path):
    truth = np.linspace(0, 1, 30)[:, None, None] * np.ones((30, 6, 3))
    residual = np.zeros((30, 6))
    residual[10:13, 2] = -1.0  # LANK not seen in frames 10-12
    path = write_c3d(tmp_path / "g.c3d", SKIN_MARKERS.names, y_up_to_z_up_mm(truth), 30, residual)
    with pytest.warns(MarkerGapWarning, match="LANK missing at frames 10-12"):
        tracks = read_c3d(path, SKIN_MARKERS)
    np.testing.assert_allclose(tracks.positions, truth, atol=1e-5)  # linear motion: interpolation is exact
    residual[25:, 4] = -1.0
    path = write_c3d(tmp_path / "e.c3d", SKIN_MARKERS.names, y_up_to_z_up_mm(truth), 30, residual)
    with pytest.raises(MarkerInputError, match=r"e\.c3d: marker HEAD is missing at frame 25"), \
            pytest.warns(MarkerGapWarning):
        read_c3d(path, SKIN_MARKERS)


def test_bad_c3d_files_end_in_one_line(tmp_path):
    junk = tmp_path / "junk.c3d"
    junk.write_bytes(b"not a c3d file at all" * 10)
    with pytest.raises(MarkerInputError, match=r"junk\.c3d: not a readable C3D file"):
        read_c3d(junk, SKIN_MARKERS)
    with pytest.raises(MarkerInputError, match="no such file"):
        read_c3d(tmp_path / "none.c3d", SKIN_MARKERS)
    with pytest.raises(MarkerInputError, match="up_axis"):
        read_c3d(junk, SKIN_MARKERS, up_axis="x")


def test_resampling_a_linear_track_is_exact():
    frames = np.arange(61) / 60.0
    positions = (frames[:, None, None] * np.array([1.0, 2.0, -0.5]))[:, None, :].repeat(2, axis=1)[:, :, 0, :]
    tracks = MarkerTracks(("Hips", "Head"), positions, 60.0, "t")
    half = resample_tracks(tracks, 30.0)
    assert half.num_frames == 31 and half.fps == 30.0
    np.testing.assert_allclose(half.positions, positions[::2], atol=1e-12)
    odd = resample_tracks(tracks, 25.0)
    times = np.arange(odd.num_frames) / 25.0
    np.testing.assert_allclose(odd.positions[:, 0], times[:, None] * np.array([1.0, 2.0, -0.5]), atol=1e-12)


def test_csv_at_another_rate_and_virtual_markers_on_a_motion(tmp_path):
    rng = np.random.default_rng(1)
    walk = np.cumsum(rng.normal(0, 0.01, (121, 6, 3)), axis=0)
    path = write_marker_csv(tmp_path / "m.csv", ["Hips", "Head", "Hand_L", "Hand_R", "Foot_L", "Foot_R"], walk, 120)
    tracks = read_capture(str(path), joint_marker_set(["Hand_L", "Hips"]), 30.0)
    assert tracks.fps == 30.0 and tracks.num_frames == 31 and tracks.joints == ("Hand_L", "Hips")
    np.testing.assert_allclose(tracks.positions, walk[::4][:, [2, 0]], atol=1e-6)
    from stylemotion.datasets.registry import load_dataset

    motion = load_dataset("synthetic", takes_per_pair=1).takes[0].positions[:20]
    on = tracks_on_motion(motion, SKIN_MARKERS, 30.0)
    np.testing.assert_allclose(on.positions, virtual_markers(motion, SKIN_MARKERS))
    assert on.full is not None and on.full.shape == (20, 21, 3)
    with pytest.raises(MarkerInputError, match="must end in one of"):
        read_capture(str(tmp_path / "m.trc"), SKIN_MARKERS, 30.0)
