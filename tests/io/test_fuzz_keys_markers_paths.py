"""Fuzzed keyframe (keys.json), marker (CSV, NPZ) and path (CSV, JSON) files (issue 26): every read of a mutated
valid file either succeeds with finite values or raises a UserInputError subclass — never another exception, never
a hang. A few hundred mutations in a few seconds (fixed seeds)."""

from __future__ import annotations

import io
import json
import random
from types import SimpleNamespace

import numpy as np
import pytest

from stylemotion.io.errors import UserInputError
from stylemotion.reconstruct.keyframes_command import read_keys
from stylemotion.reconstruct.markers import read_markers, write_marker_csv
from stylemotion.skeleton import CANONICAL_JOINTS, NUM_JOINTS
from stylemotion.synthesis.path import GroundPath

ODD = [b"nan", b"NaN", b"inf", b"-inf", b"1e309", b"-1e400", b"1e308", b"0", b"-0", b"\"x\"", b"null", b"true",
       b"[]", b"{}", b"[[1,2]]", b"99999999999999999999999", b"\xff\xfe", b"", b",", b"\n", b"\x00"]


def _mutate(data: bytes, rng: random.Random) -> bytes:
    kind = rng.randrange(5)
    if kind == 0:  # truncation
        return data[:rng.randrange(len(data) + 1)]
    if kind == 1:  # byte flips
        out = bytearray(data)
        for _ in range(rng.randint(1, 4)):
            out[rng.randrange(len(out))] = rng.randrange(256)
        return bytes(out)
    # a number (or token) replaced by a huge number, NaN, a wrong type...
    starts = [i for i in range(len(data)) if data[i:i + 1].isdigit() and (i == 0 or not data[i - 1:i].isdigit())]
    if not starts:
        return data + rng.choice(ODD)
    i = rng.choice(starts)
    j = i
    while j < len(data) and (data[j:j + 1].isdigit() or data[j:j + 1] in b".e-"):
        j += 1
    return data[:i] + rng.choice(ODD) + data[j:]


def _fuzz(tmp_path, name: str, valid: bytes, read, count: int, seed: int) -> None:
    rng = random.Random(seed)
    path = tmp_path / name
    for n in range(count):
        data = _mutate(valid, rng)
        path.write_bytes(data)
        try:
            values = read(path)
        except UserInputError:
            continue
        except Exception as exc:  # noqa: BLE001 - the point of the test
            pytest.fail(f"mutation {n} of {name} ({data[:200]!r}…) raised {type(exc).__name__}: {exc}")
        for value in values:
            assert np.isfinite(value).all(), f"mutation {n} of {name} read non-finite values: {data[:200]!r}"


def _pose(scale: float) -> list[list[float]]:
    return (np.linspace(0.0, 1.0, NUM_JOINTS * 3).reshape(NUM_JOINTS, 3) * scale).round(3).tolist()


def test_fuzzed_keys_files(tmp_path):
    takeset = SimpleNamespace(takes=[], fps=30.0, name="none")
    valid = json.dumps({"keys": [{"time": 0, "positions": _pose(1.0)},
                                 {"time": 1.5, "positions": _pose(1.1), "turn_deg": 30, "shift_m": [0.5, 0, 0]}]})

    def read(path):
        keys, _, _ = read_keys(path, takeset)
        return [np.array([k.time_s for k in keys])] + [k.pose for k in keys]

    _fuzz(tmp_path, "keys.json", valid.encode(), read, 300, 0)


def test_fuzzed_marker_files(tmp_path):
    joints = ["Hips", "Head", "Foot_L", "Foot_R"]
    frames = np.linspace(0, 1, 12 * len(joints) * 3).reshape(12, len(joints), 3).round(3)
    write_marker_csv(tmp_path / "valid.csv", joints, frames, 30.0)

    def read(path):
        tracks = read_markers(path)
        return [tracks.positions, np.array([tracks.fps])]

    _fuzz(tmp_path, "markers.csv", (tmp_path / "valid.csv").read_bytes(), read, 250, 1)
    buffer = io.BytesIO()
    np.savez(buffer, positions=np.zeros((12, len(CANONICAL_JOINTS), 3)) + 0.5, fps=np.float64(30))
    _fuzz(tmp_path, "markers.npz", buffer.getvalue(), read, 150, 2)


def test_fuzzed_path_files(tmp_path):
    def read(path):
        return [np.asarray(GroundPath.from_file(path).points)]

    _fuzz(tmp_path, "path.json", json.dumps({"points": [[0, 0], [1.5, 0.5], [3, 0], [4.5, -1]]}).encode(), read,
          200, 3)
    _fuzz(tmp_path, "path.csv", b"x,z\n0,0\n1.5,0.5\n3,0\n4.5,-1\n", read, 200, 4)
