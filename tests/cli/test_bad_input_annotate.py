"""``stylemotion-annotate`` with a damaged templates folder (issue 26): a corrupt, cut-off or pickled
``templates.npz``/``tensors.npz`` or a cut-off ``model.json`` ends in one line naming the file, exit status 2, no
traceback, no hint to load it with ``allow_pickle``, nothing written."""

from __future__ import annotations

import io
import json
import pickle

import numpy as np
import pytest
from cli_runner import run_command

from stylemotion.annotate.features import FEATURE_NAMES
from stylemotion.annotate.model import MODEL_FORMAT


def _npz(**arrays) -> bytes:
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


GOOD = _npz(walk=np.zeros((30, len(FEATURE_NAMES))))
DAMAGED = {
    "cut off": GOOD[: len(GOOD) // 2],
    "empty": b"",
    "not a zip": b"BVH? no: plain text\n",
    "flipped bytes": GOOD[:60] + b"\xff" * 16 + GOOD[76:],
    "pickled": _npz(walk=np.array([{"x": 1}], dtype=object)),
    "a pickle": pickle.dumps({"walk": [1.0]}),
}


def _folder(tmp_path, damaged: str, content: bytes):
    folder = tmp_path / "templates"
    folder.mkdir()
    meta = {"format": MODEL_FORMAT, "features": list(FEATURE_NAMES), "fps": 30.0, "delta": 0.5,
            "classes": [{"label": "walk", "frames": 30, "examples": 2}], "tensors": {}}
    (folder / "model.json").write_text(json.dumps(meta))
    (folder / "templates.npz").write_bytes(GOOD)
    (folder / "tensors.npz").write_bytes(_npz())
    (folder / damaged).write_bytes(content)
    return folder


@pytest.mark.parametrize("damaged", ["templates.npz", "tensors.npz"])
@pytest.mark.parametrize("kind", list(DAMAGED))
def test_a_damaged_npz_is_named_in_one_line(damaged, kind, tmp_path, capsys, monkeypatch):
    folder = _folder(tmp_path, damaged, DAMAGED[kind])
    done = run_command("annotate", "document=walk.bvh", f"templates={folder}", "out=out", "hydra.run.dir=hydra",
                       capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith(f"stylemotion-annotate: {folder / damaged}: "), line
    assert ("pickled Python objects, which are never loaded" if "pickle" in kind else
            "not a NumPy .npz archive" if kind == "not a zip" else "not a readable") in line, line
    assert "allow_pickle" not in line, line
    assert not (tmp_path / "out").exists()


def test_a_cut_off_model_json_is_named_in_one_line(tmp_path, capsys, monkeypatch):
    folder = _folder(tmp_path, "model.json", b'{"format": 1, "feat')
    done = run_command("annotate", "document=walk.bvh", f"templates={folder}", "out=out", "hydra.run.dir=hydra",
                       capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith(f"stylemotion-annotate: {folder / 'model.json'}:1: not valid JSON"), line
    assert "learn the model again" in line, line
