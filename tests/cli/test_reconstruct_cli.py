"""``stylemotion-reconstruct``: the synthetic default end to end, its files, and bad inputs in one line."""

from __future__ import annotations

import json
import logging

import numpy as np
import pytest
from cli_runner import run_command

from stylemotion.config import ConfigError
from stylemotion.datasets.registry import load_dataset
from stylemotion.io.outputs import OutputExistsError
from stylemotion.reconstruct.command import reconstruct_command
from stylemotion.reconstruct.markers import MarkerInputError, write_marker_csv
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX

DATA = {"name": "synthetic", "takes_per_pair": 1}
TAKE = "synthetic_walk_normal_000"


def test_a_take_of_the_synthetic_default_left_out_of_the_database(tmp_path):
    summary = reconstruct_command(DATA, TAKE, tmp_path / "out")
    with np.load(tmp_path / "out" / "motion.npz", allow_pickle=False) as npz:
        assert npz["positions"].shape == (240, 21, 3) and float(npz["fps"]) == 30.0
        assert list(npz["joint_names"]) == list(CANONICAL_JOINTS)
    assert (tmp_path / "out" / "motion.bvh").read_text().startswith("HIERARCHY")
    assert (tmp_path / "out" / "motion.gif").read_bytes()[:6] == b"GIF89a"
    written = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert written["markers"]["excluded_take"] == TAKE and written["database"]["takes"] == 27
    assert written["error"]["mean_cm"] < written["error_nearest_neighbour"]["mean_cm"]
    assert summary["error"]["mean_cm"] < 2.0 and written["frames_per_s"] > 0
    with pytest.raises(OutputExistsError):
        reconstruct_command(DATA, TAKE, tmp_path / "out")


def test_csv_with_a_gap_is_filled_and_said(tmp_path, caplog):
    take = load_dataset("synthetic", takes_per_pair=1).takes[0]
    joints = ["Hand_L", "Hand_R", "Hips"]
    markers = take.positions[:40, [JOINT_INDEX[j] for j in joints]].astype(np.float64)
    markers[10:13, 0] = np.nan
    write_marker_csv(tmp_path / "m.csv", joints, markers, 30)
    with caplog.at_level(logging.INFO, logger="stylemotion"):
        summary = reconstruct_command(DATA, str(tmp_path / "m.csv"), tmp_path / "out")
    said = caplog.messages
    assert summary["markers"]["joints"] == joints and "error" not in summary
    assert summary["markers"]["filled_frames"] == {"Hand_L": [10, 11, 12]}
    assert any("Hand_L missing at frames 10-12" in line for line in said)
    with np.load(tmp_path / "out" / "motion.npz") as npz:
        np.testing.assert_allclose(npz["positions"][:, JOINT_INDEX["Hips"]], take.positions[:40, JOINT_INDEX["Hips"]],
                                   atol=0.05)


def test_bad_values_are_named_and_nothing_is_written(tmp_path):
    with pytest.raises(ConfigError, match="features=EP19"):
        reconstruct_command(DATA, TAKE, tmp_path / "a", features="EP19")
    with pytest.raises(MarkerInputError, match="'Knee_L'"):
        reconstruct_command(DATA, TAKE, tmp_path / "a", joints=["Hips", "Knee_L"])
    with pytest.raises(MarkerInputError, match="no such file"):
        reconstruct_command(DATA, str(tmp_path / "none.csv"), tmp_path / "a")
    with pytest.raises(ConfigError, match="noise_mm=-1"):
        reconstruct_command(DATA, TAKE, tmp_path / "a", noise_mm=-1)
    assert not (tmp_path / "a").exists()


def test_the_console_command_runs_and_refuses_in_one_line(tmp_path, capsys, monkeypatch):
    run = [f"markers={TAKE}", "data.takes_per_pair=1", "gif=false"]
    done = run_command("reconstruct", *run, f"out={tmp_path / 'o'}", "k=16", capsys=capsys, monkeypatch=monkeypatch,
                       cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["settings"]["k"] == 16
    done = run_command("reconstruct", *run, f"out={tmp_path / 'p'}", "joints=[Hips,Tail]", capsys=capsys,
                       monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "'Tail'" in done.stderr and "Traceback" not in done.stderr


def test_a_c3d_of_skin_markers_at_60_fps(tmp_path, capsys, monkeypatch):
    from c3d_writer import write_c3d

    from stylemotion.reconstruct.marker_set import SKIN_MARKERS, virtual_markers

    take = load_dataset("synthetic", takes_per_pair=1).takes[0]
    truth = np.asarray(take.positions[:41], np.float64)
    at_60 = np.repeat(truth, 2, axis=0)[:-1]  # 60 fps: each 30 fps pose twice (linear in between: the mean)
    at_60[1::2] = 0.5 * (truth[:-1] + truth[1:])
    markers = virtual_markers(at_60, SKIN_MARKERS)
    z_up_mm = np.stack([markers[..., 0], -markers[..., 2], markers[..., 1]], axis=-1) * 1000.0
    write_c3d(tmp_path / "walk.c3d", list(SKIN_MARKERS.names), z_up_mm, 60.0)
    summary = reconstruct_command(DATA, str(tmp_path / "walk.c3d"), tmp_path / "out", marker_set="skin",
                                  subject="markers", gif=False)
    with np.load(tmp_path / "out" / "motion.npz") as npz:
        positions = npz["positions"]
    assert positions.shape == (41, 21, 3)
    assert np.linalg.norm(positions - truth, axis=-1).mean() < 0.02  # the take is in the database: near exact
    assert summary["markers"]["marker_set"] == "skin" and summary["markers"]["subject"]["value"] == "markers"
    assert summary["bone_length_sd_cm"]["max_range_cm"] < 1e-3
    with pytest.raises(MarkerInputError, match="marker_set=skin"):
        reconstruct_command(DATA, str(tmp_path / "walk.c3d"), tmp_path / "b")
    with pytest.raises(ConfigError, match="joints="):
        reconstruct_command(DATA, str(tmp_path / "walk.c3d"), tmp_path / "b", marker_set="skin", joints=["Hips"])
    with pytest.raises(ConfigError, match="subject=walk.txt"):
        reconstruct_command(DATA, str(tmp_path / "walk.c3d"), tmp_path / "b", marker_set="skin", subject="walk.txt")
    run = [f"markers={tmp_path / 'walk.c3d'}", "marker_set=skin", "data.takes_per_pair=1", "gif=false",
           f"out={tmp_path / 'c'}", "markers_up_axis=x"]
    done = run_command("reconstruct", *run, capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "markers_up_axis=x" in done.stderr and "Traceback" not in done.stderr
    assert not (tmp_path / "b").exists()


def test_subject_from_a_bvh_gives_its_whole_skeleton(tmp_path):
    from stylemotion.io.export import write_motion_bvh
    from stylemotion.reconstruct.subject import subject_from_motion

    take = load_dataset("synthetic", takes_per_pair=1).takes[1]
    other = np.asarray(take.positions, np.float64) * 1.1  # a taller subject recorded elsewhere
    write_motion_bvh(other, tmp_path / "subject.bvh", fps=30.0)
    summary = reconstruct_command(DATA, TAKE, tmp_path / "out", marker_set="skin",
                                  subject=str(tmp_path / "subject.bvh"), gif=False)
    recorded = summary["settings"]["subject"]
    expected = subject_from_motion(other)
    np.testing.assert_allclose(recorded["bones_m"], expected.lengths, atol=2e-3)
    for part in ("rigid", "hinged"):  # not the lengths alone: the directions the skeleton fixes come along
        assert set(recorded[part]) == set(getattr(expected, part))
        for bone, direction in recorded[part].items():
            np.testing.assert_allclose(direction, getattr(expected, part)[bone], atol=0.02)
    assert summary["markers"]["subject"]["value"] == str(tmp_path / "subject.bvh")
