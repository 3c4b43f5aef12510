"""``stylemotion-texture``: completion on the synthetic default, its files, a legs-only NPZ, bad inputs in one line."""

from __future__ import annotations

import json

import numpy as np
import pytest
from cli_runner import run_command

from stylemotion.datasets.registry import load_dataset
from stylemotion.io.outputs import OutputExistsError
from stylemotion.reconstruct.texture import LEG_JOINTS, TextureInputError
from stylemotion.reconstruct.texture_command import texture_command
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX

DATA = {"name": "synthetic", "takes_per_pair": 1}
TAKE = "synthetic_walk_normal_000"


def test_a_take_completed_and_its_files(tmp_path):
    summary = texture_command(DATA, TAKE, tmp_path / "out")
    with np.load(tmp_path / "out" / "motion.npz", allow_pickle=False) as npz:
        assert npz["positions"].shape == (240, 21, 3) and float(npz["fps"]) == 30.0
        assert list(npz["joint_names"]) == list(CANONICAL_JOINTS)
    assert (tmp_path / "out" / "motion.bvh").read_text().startswith("HIERARCHY")
    assert (tmp_path / "out" / "motion.gif").read_bytes()[:6] == b"GIF89a"
    written = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert written["motion"]["excluded_take"] == TAKE and written["database"]["takes"] == 27
    assert written["error"]["mean_cm"] < written["error_nearest_neighbour"]["mean_cm"]
    assert "Hand_L" in written["error"]["per_joint_mean_cm"] and "Foot_L" not in written["error"]["per_joint_mean_cm"]
    assert set(written["foot_skating_ratio"]) == {"input", "before_cleanup", "after_cleanup"}
    assert summary["settings"]["mode"] == "complete"
    with pytest.raises(OutputExistsError):
        texture_command(DATA, TAKE, tmp_path / "out")


def test_a_legs_only_npz_is_completed(tmp_path):
    take = load_dataset("synthetic", takes_per_pair=1).takes[0]
    legs = np.array(take.positions[:30], dtype=np.float64)
    upper = [i for i, j in enumerate(CANONICAL_JOINTS) if j not in LEG_JOINTS]
    legs[:, upper] = np.nan
    np.savez(tmp_path / "legs.npz", positions=legs, joint_names=np.array(CANONICAL_JOINTS), fps=30.0)
    summary = texture_command(DATA, str(tmp_path / "legs.npz"), tmp_path / "out")
    assert "error" not in summary
    with np.load(tmp_path / "out" / "motion.npz") as npz:
        assert np.all(np.isfinite(npz["positions"]))
        hips = JOINT_INDEX["Hips"]
        np.testing.assert_allclose(npz["positions"][:, hips], legs[:, hips], atol=1e-5)


def test_bad_values_are_named_and_nothing_is_written(tmp_path):
    with pytest.raises(TextureInputError, match="mode=blur"):
        texture_command(DATA, TAKE, tmp_path / "a", mode="blur")
    with pytest.raises(TextureInputError, match="'Knee_L'"):
        texture_command(DATA, TAKE, tmp_path / "a", joints=["Hips", "Knee_L"])
    assert not (tmp_path / "a").exists()


def test_the_console_command_runs_and_refuses_in_one_line(tmp_path, capsys, monkeypatch):
    run = [f"motion={TAKE}", "data.takes_per_pair=1", "gif=false"]
    done = run_command("texture", *run, f"out={tmp_path / 'o'}", "mode=texture", "k=16", capsys=capsys,
                       monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["settings"]["mode"] == "texture"
    done = run_command("texture", *run, f"out={tmp_path / 'p'}", "mode=blur", capsys=capsys,
                       monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "mode=blur" in done.stderr and "Traceback" not in done.stderr
