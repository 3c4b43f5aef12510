"""``stylemotion-search``: a take query finds itself first (cost 0) when its take is not excluded, and never when
it is; ``matches.json`` holds exactly the six keys; the distance-matrix PNG is an image; exported BVH re-imports to
the matched frames, GIFs are written; a BVH query of another skeleton (shared data) and a Bandai subset work;
bad input (short query, unknown feature set, k past the database, an empty dataset, an unmappable skeleton, a
range outside the take, an existing out) is one line naming the value, with nothing written."""

from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np
import pytest
from cli_runner import Done, run_command
from conftest import BANDAI_ZIP, shared_data_dir
from PIL import Image
from test_commands_cli import one_line_error

from stylemotion.datasets.loading import ConversionSettings, load_canonical_positions
from stylemotion.datasets.registry import load_dataset
from stylemotion.io.outputs import OutputExistsError
from stylemotion.io.sources import FileSource
from stylemotion.search import DEFAULT_K, MATCH_KEYS
from stylemotion.search.command import SearchInputError, search
from stylemotion.search.settings import SearchSettings

SYNTHETIC = {"name": "synthetic", "takes_per_pair": 1, "seed": 0, "fps": 30, "duration_s": 8.0}
TAKE = "synthetic_walk_normal_000"


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch) -> None:
    monkeypatch.setenv("STYLEMOTION_CACHE", str(tmp_path_factory.getbasetemp() / "search-cache"))


def command(*args: str, cwd: Path, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch) -> Done:
    """``stylemotion-search args`` in this process (:func:`cli_runner.run_command`)."""
    return run_command("search", *args, f"hydra.run.dir={cwd / 'hydra'}", cwd=cwd, capsys=capsys,
                       monkeypatch=monkeypatch)


def test_a_take_query_finds_its_own_frames_first_and_exports_them(tmp_path: Path, capsys, monkeypatch) -> None:
    out = tmp_path / "found"
    done = command(f"query={TAKE}:30-90", "data.takes_per_pair=1", f"out={out}", "exclude_query_take=false",
                   "export.bvh=true", "export.top=2", "top=4", cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    matches = json.loads((out / "matches.json").read_text())
    assert 1 <= len(matches) <= 4 and all(list(m) == list(MATCH_KEYS) for m in matches)
    assert matches[0] == {"take": TAKE, "content": "walk", "style": "normal", "start": 30, "end": 90, "cost": 0.0}
    assert [m["cost"] for m in matches] == sorted(m["cost"] for m in matches)
    report = json.loads((out / "search.json").read_text())
    assert report["matches"] == matches and report["k"] == DEFAULT_K and report["features"] == "E15"
    assert report["query"] == {"value": f"{TAKE}:30-90", "kind": "take", "take": TAKE, "start": 30, "end": 90,
                               "fps": 30.0}
    assert report["excluded_takes"] == [] and report["provenance"]["command"].startswith("stylemotion-search query=")
    assert len(report["paths"][0]) == 60 and report["paths"][0][0] == [0, 30]
    with Image.open(out / "distance_matrix.png") as image:
        image.verify()
        assert image.format == "PNG" and image.size[0] > 300
    data = load_dataset("synthetic", takes_per_pair=1)
    source = next(t for t in data.takes if t.name == TAKE).positions
    for name, frames in ((f"01_{TAKE}_30-90.bvh", slice(30, 90)), ("query.bvh", slice(30, 90))):
        back = load_canonical_positions(FileSource(str(out / "bvh" / name)), ConversionSettings(fps=30.0))
        assert back.shape == (60, 21, 3)
        assert np.linalg.norm(back - source[frames], axis=-1).mean() < 0.01  # metres
    assert len(list((out / "bvh").glob("*.bvh"))) == 1 + min(2, len(matches))
    assert "cost 0" in done.stdout
    # the command skeleton keeps the run's record beside its results: the resolved config and the log
    assert f"query: {TAKE}:30-90" in (out / "config_resolved.yaml").read_text()
    assert "match(es) written to" in (out / "search.log").read_text()


def test_the_query_take_is_excluded_by_default_and_gifs_are_written(tmp_path: Path) -> None:
    report = search(SYNTHETIC, f"{TAKE}:30-90", tmp_path / "out", top=3, export_gif=True, export_top=1)
    assert report["excluded_takes"] == [TAKE] and report["matches"]
    assert all(m["take"] != TAKE for m in report["matches"])
    assert sorted(p.name for p in (tmp_path / "out" / "gif").iterdir()) == sorted(
        ["query.gif", f"01_{report['matches'][0]['take']}_{report['matches'][0]['start']}-"
                      f"{report['matches'][0]['end']}.gif"])
    with Image.open(tmp_path / "out" / "gif" / "query.gif") as gif:
        assert gif.format == "GIF" and gif.n_frames > 10


@pytest.mark.parametrize("overrides, message", [
    ({"query": f"{TAKE}:30-32", "features": "E15x3"},
     f"query={TAKE}:30-32: 2 frames at 30 fps is shorter than the window of features=E15x3 (10 frames)"),
    ({"features": "E16"}, "features=E16 is no feature set; valid: ['E15'"),
    ({"k": 6721, "exclude_query_take": False}, "k=6721 exceeds the database's 6720 frames"),
    ({"k": 6481}, f"k=6481 exceeds the database's 6480 frames outside the query's take {TAKE}"),
    ({"k": 0}, "k must be a whole number ≥ 1, got 0"),
    ({"data": {**SYNTHETIC, "contents": []}}, "data=synthetic: data.contents=[] selects no content"),
    ({"query": f"{TAKE}:200-300"}, f"query={TAKE}:200-300: the frame range 200-300 ends after the take's last "
                                   f"frame: {TAKE} has 240 frames (0-240) at 30 fps"),
    ({"query": f"{TAKE}:9-3"}, f"query={TAKE}:9-3: the frame range '9-3' must be START-END"),
    ({"query": "nowhere.bvh"}, "query=nowhere.bvh: no such file, and 'nowhere.bvh' is no take of dataset"),
    ({"eps": -1}, "eps=-1 must be a finite number ≥ 0"),
    ({"engine": "annoy"}, "engine=annoy is no search engine"),
    ({"k_max": 512}, "k_max=512 is below k=1024: the growth bound must be at least the first k"),
    ({"grow": "always"}, "grow=always is none of ['none', 'path', 'stable']"),
    ({"stable_for": 0}, "stable_for must be a whole number ≥ 1, got 0"),
    ({"steps": "wide"}, "steps=wide is none of ['thesis', 'online', 'gaps']"),
    ({"skip_cost": -1}, "skip_cost=-1 must be a finite number ≥ 0"),
    ({"verify": "yes"}, "verify=yes must be true or false"),
    ({"steps": "gaps"}, "verify=true needs steps=thesis and normalize=none (got steps=gaps, normalize=none); set "
                        "verify=false"),
    ({"normalize": "length"}, "verify=true needs steps=thesis and normalize=none"),
])
def test_bad_input_is_refused_naming_the_value(overrides: dict, message: str, tmp_path: Path) -> None:
    kwargs = {"data": SYNTHETIC, "query": f"{TAKE}:30-90", "out": tmp_path / "out", **overrides}
    with pytest.raises((SearchInputError, ValueError)) as caught:
        search(kwargs.pop("data"), kwargs.pop("query"), kwargs.pop("out"), **kwargs)
    assert str(caught.value).startswith(message), str(caught.value)
    assert not (tmp_path / "out").exists()


def test_an_unmappable_skeleton_and_an_existing_out_are_one_line(tmp_path: Path, tiny_bvh: str, capsys,
                                                                 monkeypatch) -> None:
    (tmp_path / "tiny.bvh").write_text(tiny_bvh)
    done = command(f"query={tmp_path / 'tiny.bvh'}", "data.takes_per_pair=1", f"out={tmp_path / 'out'}", cwd=tmp_path,
                   capsys=capsys, monkeypatch=monkeypatch)
    message = one_line_error(done, "stylemotion-search")
    assert message.startswith(f"stylemotion-search: query={tmp_path / 'tiny.bvh'}: ") and "joint_map=" in message
    assert not (tmp_path / "out").exists()
    (tmp_path / "taken").mkdir()
    with pytest.raises(OutputExistsError, match="already exists; choose another out="):
        search(SYNTHETIC, TAKE, tmp_path / "taken")


@pytest.mark.realdata
def test_a_bvh_query_of_another_skeleton(other_skeleton_paths, tmp_path: Path) -> None:
    bvh = other_skeleton_paths["cmu21_walk"]
    report = search(SYNTHETIC, f"{bvh}:0-120", tmp_path / "out", top=5)
    query = report["query"]
    assert query["kind"] == "bvh" and query["file_fps"] == 60.0 and query["file_range"] == [0, 120]
    assert query["frames"] == 60 and query["fps"] == 30.0 and query["retargeted_to"] == "normal"
    matches = json.loads((tmp_path / "out" / "matches.json").read_text())
    assert matches and all(list(m) == list(MATCH_KEYS) for m in matches)
    assert matches[0]["content"].startswith("walk") and (tmp_path / "out" / "distance_matrix.png").is_file()


@pytest.mark.realdata
def test_a_bandai_subset(tmp_path: Path, monkeypatch) -> None:
    root = shared_data_dir(BANDAI_ZIP) / BANDAI_ZIP
    data = {"name": "bandai", "root": str(root), "contents": ["walk"], "styles": ["normal"], "fps": 30,
            "cache_dir": None, "use_cache": True, "workers": 1}
    monkeypatch.delenv("STYLEMOTION_CACHE")  # the converted Bandai takes are cached where every test finds them
    takes = load_dataset("bandai", root=str(root), contents=["walk"], styles=["normal"], workers=1).takes
    query = sorted(takes, key=lambda t: t.name)[0]  # walking in frames 60-90 (takes begin standing: docs/search.md)
    report = search(data, f"{query.name}:60-90", tmp_path / "out", features="E15x3", top=10)
    assert report["database"]["takes"] == len(takes) and report["excluded_takes"] == [query.name]
    matches = report["matches"]
    assert len(matches) == 10 and all(m["take"] != query.name and m["content"] == "walk" for m in matches)
    assert all(0 <= m["start"] < m["end"] for m in matches)
    again = search(data, f"{query.name}:60-90", tmp_path / "self", top=1, exclude_query_take=False)
    assert again["matches"][0] | {"cost": 0} == {"take": query.name, "content": "walk", "style": "normal", "start": 60,
                                                 "end": 90, "cost": 0}
    assert again["matches"][0]["cost"] < 1e-3


def test_fewer_matches_than_asked_for_says_that_a_larger_k_finds_more(tmp_path: Path, caplog) -> None:
    with caplog.at_level(logging.INFO, logger="stylemotion"):
        report = search(SYNTHETIC, f"{TAKE}:30-90", tmp_path / "out", k=256, top=500)
    found = len(report["matches"])
    assert 0 < found < 500
    assert any(f"{found} of top=500 found" in line and "larger k" in line for line in caplog.messages)


@pytest.mark.parametrize("steps", ["thesis", "gaps"])
def test_k_grows_from_k_to_k_max_and_search_json_says_which_k_answered(steps: str, tmp_path: Path, caplog) -> None:
    with caplog.at_level(logging.INFO, logger="stylemotion"):
        report = search(SYNTHETIC, f"{TAKE}:30-90", tmp_path / "out", k=2, k_max=64, grow="stable", steps=steps, top=1,
                        verify=steps == "thesis")
    tried = report["k_tried"]
    assert report["verify"] == (steps == "thesis")
    assert (report["takes_verified"] is not None) == ("verify" in report["timing_s"]) == (steps == "thesis")
    assert report["matches"] and tried[0] == 2 and report["k_used"] == tried[-1] <= 64
    assert all(b == 2 * a for a, b in zip(tried, tried[1:]))
    assert (report["k"], report["k_max"], report["grow"], report["steps"]) == (2, 64, "stable", steps)
    assert report["stable_for"] == SearchSettings.stable_for  # the stop the command used, recorded
    if tried[-1] < 64:  # stopped early: at least stable_for + 1 graphs were searched
        assert len(tried) > report["stable_for"]
    assert len(tried) == 1 or any("k grew 2 → " in line for line in caplog.messages)
    fixed = search(SYNTHETIC, f"{TAKE}:30-90", tmp_path / "fixed", k=2, grow="none", top=1)
    assert fixed["k_tried"] == [2] and fixed["k_used"] == 2
