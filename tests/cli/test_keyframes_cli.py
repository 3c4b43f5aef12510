"""``stylemotion-keyframes``: keys from a JSON file on the synthetic default, its files, bad key files named, the
console command in one line."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from cli_runner import run_command

from stylemotion.datasets.registry import load_dataset
from stylemotion.io.outputs import OutputExistsError
from stylemotion.reconstruct.keyframes import KeyframeError
from stylemotion.reconstruct.keyframes_command import keyframes_command, read_keys
from stylemotion.skeleton import CANONICAL_JOINTS

DATA = {"name": "synthetic", "takes_per_pair": 1}
TAKE = "synthetic_walk_normal_000"


def _write(path: Path, spec) -> Path:
    path.write_text(json.dumps(spec) if not isinstance(spec, str) else spec)
    return path


def test_keys_from_a_take_and_a_file_give_a_motion_and_its_files(tmp_path):
    takes = load_dataset("synthetic", takes_per_pair=1).takes
    take = {t.name: t for t in takes}[TAKE]
    np.savez(tmp_path / "pose.npz", positions=take.positions[80:110], joint_names=np.array(CANONICAL_JOINTS),
             fps=30.0)
    keys = _write(tmp_path / "keys.json", {"keys": [
        {"time": 0.0, "take": TAKE, "frame": 20},
        {"time": 2.0, "motion": "pose.npz", "frame": 0, "turn_deg": 15, "shift_m": [0.1, 0.0, 0.0]}]})
    summary = keyframes_command(DATA, keys, tmp_path / "out")
    with np.load(tmp_path / "out" / "motion.npz", allow_pickle=False) as npz:
        assert npz["positions"].shape == (61, 21, 3) and float(npz["fps"]) == 30.0
        last = npz["positions"][-1]
    for name in ("motion.bvh", "motion.gif", "summary.json"):
        assert (tmp_path / "out" / name).stat().st_size > 0
    written = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert written["excluded_takes"] == [TAKE] and written["database"]["takes"] == len(takes) - 1
    assert [k["frame_in_motion"] for k in written["keys"]] == [0, 60]
    assert set(written["pairs"][0]) >= {"iterations", "connections", "duration_error_s", "intermediate_key_error_cm"}
    # cleaning adds at most 2 points of foot skating: the turning-aware search (turn_radius_m = 1) joins segments that
    # skate less (7.4 %) than eq. 4.12's did (10.9 %) and the cleaned result skates 8.9 % after either
    assert summary["foot_skating_ratio"]["result"] <= summary["foot_skating_ratio"]["intermediate"] + 0.02
    hips = np.asarray(take.positions[80, 0], dtype=np.float64)  # the turned, shifted key: Hips moved by shift only
    np.testing.assert_allclose(last[0], hips + [0.1, 0.0, 0.0], atol=1e-5)
    with pytest.raises(OutputExistsError):
        keyframes_command(DATA, keys, tmp_path / "out")


def test_every_s_keys_and_bad_key_files_are_named(tmp_path):
    takeset = load_dataset("synthetic", takes_per_pair=1)
    keys, described, used = read_keys(_write(tmp_path / "a.json", {"motion": TAKE, "every_s": 2.0, "start_s": 1.0}),
                                      takeset)
    assert [k.time_s for k in keys] == [0.0, 2.0, 4.0, 6.0] and used == {TAKE}
    assert [d["frame"] for d in described] == [30, 90, 150, 210]
    cases = [
        ('{"keys": [\n{"time": 0, }]}', r"line 2: not valid JSON"),
        ({"keys": [{"time": 0, "take": TAKE, "frame": 0, "pose": 1}]}, r"keys\[0\]: unknown field\(s\) \['pose'\]"),
        ({"keys": [{"time": 0, "take": TAKE, "frame": 9999}]}, r"keys\[0\]: frame=9999 must be a frame"),
        ({"keys": [{"time": 0, "take": "nope", "frame": 0}]}, r"keys\[0\]: take='nope' is not a take"),
        ({"keys": [{"time": 1, "take": TAKE, "frame": 0}, {"time": 0, "take": TAKE, "frame": 5}]},
         r"keyframe 1: time 0 s is not after keyframe 0's 1 s"),
        ({"keys": [{"time": 0, "positions": [[0, 0, 0]] * 3}]}, r"keys\[0\]: positions must be 21"),
        ({"keys": [{"time": 0, "take": TAKE, "frame": 0, "shift_m": [1, 2]}]}, r"keys\[0\]: shift_m"),
    ]
    for i, (spec, message) in enumerate(cases):
        with pytest.raises(KeyframeError, match=message):
            read_keys(_write(tmp_path / f"bad{i}.json", spec), takeset)
    with pytest.raises(KeyframeError, match="no such file"):
        keyframes_command(DATA, tmp_path / "missing.json", tmp_path / "o")
    assert not (tmp_path / "o").exists()


def test_the_console_command_runs_and_refuses_in_one_line(tmp_path, capsys, monkeypatch):
    keys = _write(tmp_path / "keys.json", {"motion": TAKE, "every_s": 1.0, "start_s": 1.0, "end_s": 3.0})
    run = ["data.takes_per_pair=1", "gif=false"]
    done = run_command("keyframes", *run, f"keys={keys}", f"out={tmp_path / 'o'}", capsys=capsys,
                       monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["frames"] == 61
    assert not (tmp_path / "o" / "motion.gif").exists()
    bad = _write(tmp_path / "bad.json", {"keys": [{"time": 0, "take": "nope", "frame": 0}]})
    done = run_command("keyframes", *run, f"keys={bad}", f"out={tmp_path / 'p'}", capsys=capsys,
                       monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "take='nope'" in done.stderr and "Traceback" not in done.stderr
    assert not (tmp_path / "p").exists()
