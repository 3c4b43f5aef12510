"""stylemotion-view: the folder it writes and its errors (nothing half-written)."""

from __future__ import annotations

import json
import socket

import numpy as np

from stylemotion.cli.view import main
from stylemotion.skeleton import CANONICAL_JOINTS


def _data(folder):
    text = (folder / "data.js").read_text()
    prefix = "window.STYLEMOTION_DATA = "
    assert text.startswith(prefix) and text.rstrip().endswith(";")
    return json.loads(text[len(prefix):].rstrip().rstrip(";"))


def test_writes_a_self_contained_folder(motion_files, tmp_path, capsys):
    out = tmp_path / "view"
    assert main([*map(str, motion_files), "--out", str(out), "--title", "three styles"]) == 0
    names = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file())
    assert names == ["data.js", "index.html", "vendor/LICENSE", "vendor/VERSION.json", "vendor/three.bundle.min.js",
                     "viewer.css", "viewer.js"]
    html = (out / "index.html").read_text()
    assert "three styles" in html and "http" not in html  # nothing fetched from the network
    assert "MIT" in (out / "vendor" / "LICENSE").read_text()
    data = _data(out)
    assert data["joints"] == list(CANONICAL_JOINTS) and len(data["motions"]) == 3
    walk = data["motions"][0]
    positions = np.frombuffer(__import__("base64").b64decode(walk["positions"]), dtype="<f4").reshape(-1, 21, 3)
    np.testing.assert_array_equal(positions, np.load(motion_files[0])["positions"])
    assert walk["path"] and walk["targets"] and len({m["color"] for m in data["motions"]}) == 3
    assert "3 motion(s)" in capsys.readouterr().out


def test_bad_input_writes_nothing(motion_files, tmp_path, capsys):
    bad = tmp_path / "bad.npz"
    np.savez(bad, positions=np.zeros((5, 17, 3)), fps=30.0)
    out = tmp_path / "view"
    assert main([str(motion_files[0]), str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("stylemotion-view: ") and str(bad) in err and "(5, 17, 3)" in err
    assert not out.exists() and [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


def test_existing_out_refused_unless_forced(motion_files, tmp_path, capsys):
    out = tmp_path / "view"
    out.mkdir()
    (out / "keep.txt").write_text("mine")
    assert main([str(motion_files[0]), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "already exists; choose another --out or pass --force" in err and (out / "keep.txt").exists()
    assert main([str(motion_files[0]), "--out", str(out), "--force"]) == 0
    assert (out / "index.html").is_file() and not (out / "keep.txt").exists()


def test_port_in_use(motion_files, tmp_path, capsys):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        out = tmp_path / "view"
        assert main([str(motion_files[0]), "--out", str(out), "--serve", "--port", str(port)]) == 2
    assert f"port {port} on 127.0.0.1 is in use" in capsys.readouterr().err
    assert not out.exists()
