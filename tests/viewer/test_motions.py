"""Reading motions for the viewer: files, run folders and bad input."""

from __future__ import annotations

import json

import numpy as np
import pytest
from viewer_fixtures import synthetic_samples, write_take_npz

from stylemotion.io.errors import MotionDataError
from stylemotion.primitives.contacts import foot_contacts
from stylemotion.reconstruct.output import write_motion_folder
from stylemotion.viewer.motions import read_inputs


def test_npz_walk_has_contacts_path_and_targets(motion_files):
    walk = read_inputs(motion_files[:1])[0]
    data = np.load(motion_files[0])
    assert walk.positions.shape == data["positions"].shape and walk.fps == 30.0
    np.testing.assert_array_equal(walk.contacts, foot_contacts(data["positions"], 30.0))
    assert walk.contacts.any(0).all()  # both feet touch the ground in a walk
    np.testing.assert_allclose(walk.path, data["path"], atol=1e-6)
    # targets: the root at each junction, then the path's end
    np.testing.assert_allclose(walk.targets[:3], data["positions"][[0, 30, 60], 0][:, [0, 2]], atol=1e-6)
    np.testing.assert_allclose(walk.targets[-1], data["path"][-1], atol=1e-6)


def test_bvh_file_goes_through_the_project_loader(tmp_path):
    from stylemotion.io.export import write_motion_bvh

    pos = np.load(write_take_npz(tmp_path / "a.npz", "normal"))["positions"]
    write_motion_bvh(pos, tmp_path / "a.bvh", 30.0)
    m = read_inputs([tmp_path / "a.bvh"])[0]
    assert m.positions.shape == pos.shape
    assert np.linalg.norm(m.positions - pos, axis=-1).max() < 0.05


def test_reconstruction_folder_and_generated_walk_folder(tmp_path):
    pos = np.load(write_take_npz(tmp_path / "a.npz", "elderly"))["positions"]
    write_motion_folder(tmp_path / "rec", False, pos, 30.0, {"meta": {"style": "elderly"}}, 0.0)
    (m,) = read_inputs([tmp_path / "rec"])
    assert m.group == "elderly" and m.name == "rec (elderly)" and m.path is None


def test_samples_folder_written_by_the_sample_callback(tmp_path):
    from stylemotion.viz.animation import save_samples_npz

    samples = synthetic_samples(("normal", "active"), 3.0, lengths=[90, 50])
    save_samples_npz(samples, tmp_path / "run" / "cvae" / "walk_left_active" / "samples" / "samples.npz")
    motions = read_inputs([tmp_path / "run"])
    assert [m.frames for m in motions] == [90, 50]
    assert {m.group for m in motions} == {"walk_left_active"}
    np.testing.assert_array_equal(motions[1].positions, samples.positions[1, :50].numpy())


@pytest.mark.parametrize("content, match", [
    ({"positions": np.zeros((10, 20, 3)), "fps": 30.0}, r"must have shape \(frames, 21, 3\).*got \(10, 20, 3\)"),
    ({"positions": np.zeros((10, 21, 3))}, "no key 'fps'"),
    ({"positions": np.zeros((10, 21, 3)), "fps": -1.0}, "key 'fps'"),
    ({"rotations": np.zeros((10, 21, 3)), "fps": 30.0}, "no key 'positions'"),
    ({"positions": np.zeros((2, 10, 21, 3)), "fps": 30.0}, "no key 'num_frames'"),
    ({"positions": np.zeros((10, 21, 3)), "fps": 30.0, "path": np.zeros((5, 3))}, "key 'path'"),
    ({"positions": np.full((10, 21, 3), np.nan), "fps": 30.0}, "NaN or infinite values, first at frame 0"),
])
def test_bad_npz_names_file_and_key(tmp_path, content, match):
    bad = tmp_path / "bad.npz"
    np.savez(bad, **content)
    with pytest.raises(MotionDataError, match=match) as info:
        read_inputs([bad])
    assert str(bad) in str(info.value)


def test_other_files_and_empty_run_folders(tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(MotionDataError, match="neither a BVH file"):
        read_inputs([tmp_path / "notes.txt"])
    (tmp_path / "fake.npz").write_text("not a zip")
    with pytest.raises(MotionDataError, match="not a NumPy .npz"):
        read_inputs([tmp_path / "fake.npz"])
    (tmp_path / "empty_run").mkdir()
    (tmp_path / "empty_run" / "summary.json").write_text(json.dumps({}))
    with pytest.raises(MotionDataError, match="a run folder without samples"):
        read_inputs([tmp_path / "empty_run"])
    with pytest.raises(MotionDataError, match="no such file"):
        read_inputs([tmp_path / "missing.bvh"])


def test_malformed_bvh_names_file_and_line(tmp_path):
    bad = tmp_path / "bad.bvh"
    bad.write_text("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n}\n")
    with pytest.raises(MotionDataError) as info:
        read_inputs([bad])
    assert str(info.value).startswith(f"{bad}:")
