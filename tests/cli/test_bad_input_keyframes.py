"""``stylemotion-keyframes`` on bad key files (issue 26): a key at a huge time is refused in one line before the
motion between the keys is allocated."""

from __future__ import annotations

import json
import re

import pytest
from cli_runner import run_command

from stylemotion.datasets.registry import load_dataset
from stylemotion.reconstruct.keyframes import MAX_KEYS_SPAN_S, KeyframeError
from stylemotion.reconstruct.keyframes_command import read_keys

TAKE = "synthetic_walk_normal_000"


@pytest.mark.parametrize("late", [200_000.0, 1e9])
def test_a_key_at_a_huge_time_is_refused_before_anything_is_allocated(tmp_path, late):
    keys = tmp_path / "keys.json"
    keys.write_text(json.dumps({"keys": [{"time": 0.0, "take": TAKE, "frame": 0},
                                         {"time": late, "take": TAKE, "frame": 10}]}))
    with pytest.raises(KeyframeError, match=re.escape(f"keys={keys}: keyframe 1: time {late:g} s ")
                       + rf".* at most {MAX_KEYS_SPAN_S:g} s"):
        read_keys(keys, load_dataset("synthetic", takes_per_pair=1))


def test_the_command_refuses_the_huge_time_in_one_line(tmp_path, capsys, monkeypatch):
    keys = tmp_path / "keys.json"
    keys.write_text(json.dumps({"keys": [{"time": 0.0, "take": TAKE, "frame": 0},
                                         {"time": 200000, "take": TAKE, "frame": 10}]}))
    done = run_command("keyframes", f"keys={keys}", f"out={tmp_path / 'out'}", "data.takes_per_pair=1",
                       capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert lines[-1].startswith("stylemotion-keyframes: ") and "200000 s" in lines[-1] and str(keys) in lines[-1]
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("spec, message", [
    ({"motion": TAKE, "every_s": 0}, "every_s=0.0 must be at least one frame"),
    ({"keys": [{"time": 0, "take": TAKE, "frame": 0},
               {"time": 1, "take": TAKE, "frame": 30, "shift_m": [1e308, 0, 0]}]}, "more than 100000 m from"),
])
def test_keys_whose_values_go_out_of_range_name_the_file(tmp_path, spec, message):
    keys = tmp_path / "keys.json"
    keys.write_text(json.dumps(spec))
    with pytest.raises(KeyframeError, match=f"keys={re.escape(str(keys))}.*{message}"):
        read_keys(keys, load_dataset("synthetic", takes_per_pair=1))
