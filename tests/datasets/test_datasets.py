"""Datasets: registry, Bandai labels, folders with broken files, cache keys, take-based splits."""

from __future__ import annotations

import json
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest

from stylemotion.datasets import DatasetBuildError, Take, TakeSet, load_dataset
from stylemotion.datasets import loading as loading_mod
from stylemotion.datasets.canonical import to_canonical_positions
from stylemotion.io.bvh import read_bvh
from stylemotion.io.errors import MotionDataError

pytestmark = pytest.mark.realdata

BANDAI_WALKS = ["dataset-2_walk_normal_001", "dataset-2_walk_elderly_001"]


def _bandai_tables(dst: Path, src_zip: Path) -> None:
    """Put the label tables beside a small test zip (as in the real dataset layout)."""
    shutil.copytree(src_zip.parent / "cfg", dst / "cfg")


def _small_bandai_zip(tmp_path: Path, src_zip: Path, stems: list[str],
                      json_override: dict[str, dict] | None = None) -> Path:
    _bandai_tables(tmp_path, src_zip)
    out = tmp_path / "data.zip"
    with zipfile.ZipFile(src_zip) as src, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for stem in stems:
            dst.writestr(f"{stem}.bvh", src.read(f"{stem}.bvh"))
            label = src.read(f"{stem}.json")
            if json_override and stem in json_override:
                label = json.dumps(json_override[stem]).encode()
            dst.writestr(f"{stem}.json", label)
    return out


def test_bandai_subset_labels_and_filter(bandai_zip_path: Path, tmp_path: Path) -> None:
    ts = load_dataset("bandai", root=bandai_zip_path, contents=["walk"], styles=["elderly"],
                      cache_dir=tmp_path, workers=1)
    assert len(ts) > 5
    assert {t.content for t in ts.takes} == {"walk"} and {t.style for t in ts.takes} == {"elderly"}
    take = ts.takes[0]
    assert take.positions.shape[1:] == (21, 3) and take.positions.dtype == np.float32
    assert take.fps == 30.0 and take.labels["take"].isdigit()
    assert take.source.endswith(f"::{take.name}.bvh")
    with pytest.raises(MotionDataError, match="unknown style"):
        load_dataset("bandai", root=bandai_zip_path, styles=["sleepy"], cache_dir=tmp_path)


def test_bandai_label_file_disagreeing_with_name(bandai_zip_path: Path, tmp_path: Path) -> None:
    # style index 1 is 'elderly' in the dataset's table; the file name says 'normal'.
    bad = _small_bandai_zip(tmp_path, bandai_zip_path, BANDAI_WALKS,
                            {"dataset-2_walk_normal_001": {"content": 0, "style": 1}})
    with pytest.raises(DatasetBuildError) as err:
        load_dataset("bandai", root=bad, cache_dir=tmp_path / "cache", workers=1)
    text = str(err.value)
    assert "dataset-2_walk_normal_001.json" in text and "'style'" in text and "'elderly'" in text
    ts = load_dataset("bandai", root=bad, cache_dir=tmp_path / "cache", workers=1, skip_broken=True)
    assert [t.name for t in ts.takes] == ["dataset-2_walk_elderly_001"]
    assert len(ts.skipped) == 1 and "normal_001.json" in ts.skipped[0][1]


def test_unreadable_zip_member_is_named(bandai_zip_path: Path, tmp_path: Path) -> None:
    good = _small_bandai_zip(tmp_path, bandai_zip_path, BANDAI_WALKS)
    raw = bytearray(good.read_bytes())
    with zipfile.ZipFile(good) as zf:
        info = zf.getinfo("dataset-2_walk_normal_001.bvh")
    # Corrupt the compressed bytes of one member (after its local header).
    start = info.header_offset + 30 + len(info.filename) + 20
    raw[start:start + 200] = bytes(200)
    good.write_bytes(bytes(raw))
    with pytest.raises(DatasetBuildError) as err:
        load_dataset("bandai", root=good, cache_dir=tmp_path / "cache", workers=1)
    assert "data.zip::dataset-2_walk_normal_001.bvh" in str(err.value)


def _copy_other_skeletons(src: dict[str, Path], dst: Path) -> Path:
    dst.mkdir()
    for path in src.values():
        shutil.copy(path, dst / path.name)
    return dst


def test_folder_with_broken_files_lists_every_one(other_skeleton_paths: dict[str, Path], tmp_path: Path) -> None:
    folder = _copy_other_skeletons(other_skeleton_paths, tmp_path / "bvh")
    (folder / "empty.bvh").write_text("")
    text = (folder / "walk_21joint_60fps.bvh").read_text().splitlines()
    (folder / "truncated.bvh").write_text("\n".join(text[:140]))
    with pytest.raises(DatasetBuildError) as err:
        load_dataset("bvh_folder", root=folder, cache_dir=tmp_path / "cache", workers=1)
    message = str(err.value)
    assert "2 broken input file(s)" in message
    assert "empty.bvh" in message and "truncated.bvh" in message and "truncated" in message
    ts = load_dataset("bvh_folder", root=folder, cache_dir=tmp_path / "cache", workers=2, skip_broken=True)
    assert len(ts) == 3 and len(ts.skipped) == 2


def test_bvh_folder_pattern_and_csv_labels(other_skeleton_paths: dict[str, Path], tmp_path: Path) -> None:
    folder = _copy_other_skeletons(other_skeleton_paths, tmp_path / "bvh")
    ts = load_dataset("bvh_folder", root=folder, pattern=r"(?P<style>[a-z]+)[-_](?P<take>.+)",
                      cache_dir=tmp_path / "c", workers=1)
    assert {t.name: (t.style, t.labels["take"]) for t in ts.takes} == {
        "female-walk_21joint_60fps": ("female", "walk_21joint_60fps"),
        "walk_21joint_60fps": ("walk", "21joint_60fps"),
        "xia_neutral_01_000_31joint_120fps": ("xia", "neutral_01_000_31joint_120fps"),
    }
    with pytest.raises(DatasetBuildError, match="does not match pattern"):
        load_dataset("bvh_folder", root=folder, pattern=r"walk_(?P<take>.+)", cache_dir=tmp_path / "c")
    csv = tmp_path / "labels.csv"
    csv.write_text("file,content,style\nwalk_21joint_60fps,walk,neutral\nfemale-walk_21joint_60fps,walk,female\n")
    with pytest.raises(DatasetBuildError, match="not listed in"):
        load_dataset("bvh_folder", root=folder, labels_csv=csv, cache_dir=tmp_path / "c", workers=1)
    ts = load_dataset("bvh_folder", root=folder, labels_csv=csv, cache_dir=tmp_path / "c", workers=1,
                      skip_broken=True)
    assert {t.name: t.style for t in ts.takes} == {"female-walk_21joint_60fps": "female",
                                                   "walk_21joint_60fps": "neutral"}
    bad_csv = tmp_path / "bad.csv"
    bad_csv.write_text("name,style\nx,y\n")
    with pytest.raises(MotionDataError, match="'file' column"):
        load_dataset("bvh_folder", root=folder, labels_csv=bad_csv, cache_dir=tmp_path / "c")


def test_cache_hit_and_invalidation(other_skeleton_paths: dict[str, Path], tmp_path: Path,
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    folder = _copy_other_skeletons(other_skeleton_paths, tmp_path / "bvh")
    cache = tmp_path / "cache"
    first = load_dataset("bvh_folder", root=folder, cache_dir=cache, workers=1)
    assert len(list(cache.iterdir())) == 1

    calls: list[str] = []
    real_convert = loading_mod._convert

    def counting_convert(args):
        calls.append(args[0].name)
        return real_convert(args)

    monkeypatch.setattr(loading_mod, "_convert", counting_convert)
    again = load_dataset("bvh_folder", root=folder, cache_dir=cache, workers=1)
    assert calls == []  # served from the cache
    for a, b in zip(first.takes, again.takes):
        np.testing.assert_array_equal(a.positions, b.positions)

    # A changed setting builds anew.
    at_60 = load_dataset("bvh_folder", root=folder, cache_dir=cache, workers=1, fps=60)
    assert len(calls) == 3 and at_60.takes[0].num_frames > first.takes[0].num_frames

    # A changed file builds anew and its new content shows.
    calls.clear()
    path = folder / "walk_21joint_60fps.bvh"
    lines = path.read_text().splitlines()
    motion_at = lines.index("MOTION")
    row = lines[motion_at + 3].split()
    row[1] = f"{float(row[1]) + 50.0:.6f}"  # lift the root 50 cm in the first frame
    lines[motion_at + 3] = " ".join(row)
    path.write_text("\n".join(lines) + "\n")
    changed = load_dataset("bvh_folder", root=folder, cache_dir=cache, workers=1)
    assert len(calls) == 3
    before = {t.name: t for t in first.takes}["walk_21joint_60fps"].positions
    after = {t.name: t for t in changed.takes}["walk_21joint_60fps"].positions
    assert after[0, 0, 1] - before[0, 0, 1] == pytest.approx(0.5, abs=1e-3)


def _toy_takeset(groups: dict[tuple[str, str], int]) -> TakeSet:
    takes = []
    for (content, style), n in groups.items():
        for i in range(n):
            takes.append(Take(f"{content}_{style}_{i:03d}", np.zeros((4, 21, 3), np.float32), 30.0,
                              {"content": content, "style": style, "take": f"{i:03d}"}))
    return TakeSet("toy", takes, 30.0)


def test_split_is_by_take_seeded_and_stratified() -> None:
    ts = _toy_takeset({("walk", "normal"): 20, ("walk", "elderly"): 10, ("run", "normal"): 2})
    split = ts.split(seed=3, val_fraction=0.1, test_fraction=0.2)
    names = {part: [t.name for t in takes] for part, takes in split.items()}
    all_names = sum(names.values(), [])
    assert sorted(all_names) == sorted(t.name for t in ts.takes) and len(set(all_names)) == len(all_names)
    assert len(names["test"]) == 4 + 2 and len(names["val"]) == 2 + 1
    assert sorted(n for n in names["train"] if n.startswith("run_")) == ["run_normal_000", "run_normal_001"]
    assert {t.style for t in split["test"]} == {"normal", "elderly"}
    assert split == ts.split(seed=3, val_fraction=0.1, test_fraction=0.2)
    assert names["test"] != [t.name for t in ts.split(seed=4, val_fraction=0.1, test_fraction=0.2)["test"]]
    with pytest.raises(ValueError, match="fractions"):
        ts.split(val_fraction=0.6, test_fraction=0.5)


def test_registry_errors() -> None:
    with pytest.raises(KeyError, match="unknown dataset 'cmu'.*registered"):
        load_dataset("cmu")
    with pytest.raises(KeyError, match="no option.*'colour'.*valid options"):
        load_dataset("bvh_folder", root=".", colour="red")


def test_convert_cli_matches_dataset_path(other_skeleton_paths: dict[str, Path], tmp_path: Path) -> None:
    from stylemotion.cli.convert import main

    src = other_skeleton_paths["xia_cmu31"]
    dst = tmp_path / "out.npz"
    assert main([str(src), str(dst), "--fps", "30"]) == 0
    data = np.load(dst)
    assert list(data["joint_names"])[:3] == ["Hips", "Spine", "Chest"] and float(data["fps"]) == 30.0
    expected = to_canonical_positions(read_bvh(src), fps=30)
    np.testing.assert_array_equal(data["positions"], expected)
    assert data["positions"].dtype == np.float32 and data["positions"].shape == expected.shape
    assert main([str(tmp_path / "missing.bvh"), str(tmp_path / "x.npz")]) == 2
    assert not (tmp_path / "x.npz").exists()


def test_prepare_cli_writes_summary(other_skeleton_paths: dict[str, Path], tmp_path: Path, capsys,
                                    monkeypatch) -> None:
    from cli_runner import run_command

    folder = next(iter(other_skeleton_paths.values())).parent
    out = tmp_path / "run"
    result = run_command("prepare", "data=bvh_folder", f"data.root={folder}", f"data.cache_dir={tmp_path / 'cache'}",
                         f"hydra.run.dir={out}", capsys=capsys, monkeypatch=monkeypatch)
    assert result.returncode == 0, result.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["takes"] == 3 and summary["fps"] == 30
    assert sum(v["takes"] for v in summary["split"].values()) == 3
    bad = run_command("prepare", "data=bvh_folder", f"data.root={folder}", "+data.colour=red",
                      f"hydra.run.dir={tmp_path / 'bad'}", capsys=capsys, monkeypatch=monkeypatch)
    assert bad.returncode != 0 and "colour" in bad.stderr
