"""A dataset build over bad input: every broken file reported (any exception), skipped on request,
duplicate and unsafe take names refused, limits from the data config, labels that are safe names,
a cache keyed on content that rebuilds a corrupt entry, and checked options."""

from __future__ import annotations

import functools
import json
import os
import warnings
import zipfile
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from stylemotion.datasets import DatasetBuildError, build_dataset, load_dataset
from stylemotion.datasets import loading as loading_mod
from stylemotion.datasets.loading import CacheWarning
from stylemotion.datasets.synthetic import generate_takes
from stylemotion.io.bvh import format_bvh
from stylemotion.io.errors import MotionDataError, MotionDataWarning
from stylemotion.io.export import canonical_skeleton
from stylemotion.io.outputs import safe_name
from stylemotion.motion import Motion
from stylemotion.skeleton import CANONICAL_PARENTS

TO_Z_UP = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])  # (x, y, z) → (x, -z, y): Y-up body stands along +Z


@functools.lru_cache(maxsize=1)
def _rest_offsets() -> np.ndarray:
    """``(21, 3)`` bone offsets (metres) of an adult from the synthetic generator's first frame."""
    take = generate_takes(takes_per_pair=1, contents=["walk"], styles=["normal"], duration_s=1.0)[0]
    pos = take.positions[0].astype(np.float64)
    return pos - pos[[max(p, 0) for p in CANONICAL_PARENTS]]


def canonical_bvh(frames: int = 20, frame_time: str = "0.0333333", z_up: bool = False,
                  root_scale: float = 1.0) -> str:
    """A canonical-skeleton BVH (metres) gliding forward in its rest pose; Y up unless ``z_up``."""
    sk = canonical_skeleton(_rest_offsets())
    rotations = np.zeros((frames, 21, 4))
    rotations[..., 3] = 1.0
    translations = np.broadcast_to(sk.offsets, (frames, 21, 3)).copy()
    translations[:, 0] = np.stack([np.zeros(frames), np.full(frames, 0.95), 0.04 * np.arange(frames)], -1)
    translations[:, 0] *= root_scale
    if z_up:
        rotations[:, 0] = Rotation.from_matrix(TO_Z_UP).as_quat()
        translations[:, 0] = translations[:, 0] @ TO_Z_UP.T
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # scipy: gimbal lock of the Z-up root (harmless here)
        text = format_bvh(Motion(sk, rotations, translations, 30.0))
    return text.replace("Frame Time: 0.03333333", f"Frame Time: {frame_time}")


def _folder(tmp_path: Path, files: dict[str, str | bytes]) -> Path:
    root = tmp_path / "bvh"
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(text.encode() if isinstance(text, str) else text)
    return root


def _load(root: Path, tmp_path: Path, **options):
    options = {"cache_dir": tmp_path / "cache", "workers": 1, **options}
    return load_dataset("bvh_folder", root=root, **options)


# ---------------------------------------------------------------------------------------------
# One bad file cannot sink a build


def test_any_exception_of_one_file_is_reported_with_its_type(tmp_path, monkeypatch):
    root = _folder(tmp_path, {"good.bvh": canonical_bvh(), "deep.bvh": canonical_bvh(),
                              "huge.bvh": canonical_bvh()})
    real = loading_mod.to_canonical_positions

    def flaky(motion, **kwargs):
        if motion.source.endswith("deep.bvh"):
            raise RecursionError("maximum recursion depth exceeded")
        if motion.source.endswith("huge.bvh"):
            raise MemoryError()
        return real(motion, **kwargs)

    monkeypatch.setattr(loading_mod, "to_canonical_positions", flaky)
    with pytest.raises(DatasetBuildError) as err:
        _load(root, tmp_path)
    message = str(err.value)
    assert "2 broken input file(s)" in message and "data.skip_broken=true" in message
    assert f"{root / 'deep.bvh'}: RecursionError: maximum recursion depth exceeded" in message
    assert f"{root / 'huge.bvh'}: MemoryError" in message
    ts = _load(root, tmp_path, skip_broken=True)
    assert [t.name for t in ts.takes] == ["good"]
    assert sorted(Path(src).name for src, _ in ts.skipped) == ["deep.bvh", "huge.bvh"]


def test_every_broken_file_is_listed_labels_and_conversion_alike(tmp_path):
    root = _folder(tmp_path, {"walk_1.bvh": canonical_bvh(), "walk_x.bvh": canonical_bvh(),
                              "walk_2.bvh": "HIERARCHY\n"})
    with pytest.raises(DatasetBuildError) as err:
        _load(root, tmp_path, pattern=r"walk_(?P<take>\d+)")
    message = str(err.value)
    # The label failure (pattern) and the conversion failure are both reported, in one error.
    assert "walk_x.bvh" in message and "does not match pattern" in message
    assert "walk_2.bvh" in message and "2 broken input file(s)" in message
    assert "\n" not in message  # one line: a command's error is one line (issue 26)


def test_overflowing_positions_are_an_error_naming_the_file(tmp_path):
    root = _folder(tmp_path, {"ok.bvh": canonical_bvh(), "inf.bvh": canonical_bvh(root_scale=1e307)})
    with pytest.raises(DatasetBuildError) as err:
        _load(root, tmp_path, unit_scale=1000.0)  # 1e307 file units × 1000 m per unit: inf in float64
    assert f"{root / 'inf.bvh'}: joint positions overflow to inf/NaN" in str(err.value)
    # Finite in float64 but not in float32.
    root2 = _folder(tmp_path / "2", {"f32.bvh": canonical_bvh(root_scale=1e39)})
    with pytest.raises(DatasetBuildError, match="overflow to inf/NaN.*float32"):
        _load(root2, tmp_path, unit_scale="m")


# ---------------------------------------------------------------------------------------------
# Limits, from the data config


def test_resampled_length_limit_is_checked_before_resampling(tmp_path, monkeypatch):
    # 3 frames 10000 s apart (a 5 KB file) would become 600,001 frames at 30 fps.
    root = _folder(tmp_path, {"ok.bvh": canonical_bvh(), "slow.bvh": canonical_bvh(frames=3, frame_time="10000")})
    real = Motion.resample

    def checked_first(self, fps):
        assert not self.source.endswith("slow.bvh"), "resampled before the limit was checked"
        return real(self, fps)

    monkeypatch.setattr(Motion, "resample", checked_first)
    with pytest.raises(DatasetBuildError) as err:
        _load(root, tmp_path)
    message = str(err.value)
    assert "1 broken input file(s)" in message and f"{root / 'slow.bvh'}: 3 frames" in message
    assert "600001 frames, more than the limit data.max_frames=324000" in message
    ts = _load(root, tmp_path, skip_broken=True)
    assert [t.name for t in ts.takes] == ["ok"]
    with pytest.raises(DatasetBuildError, match=r"ok\.bvh: .*data\.max_frames=10 "):
        _load(root, tmp_path, max_frames=10)


def test_file_size_limit_from_the_config(tmp_path):
    archive = tmp_path / "takes.zip"
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("ok.bvh", canonical_bvh())
        zf.writestr("bomb.bvh", canonical_bvh() + " " * 3_000_000)
    assert archive.stat().st_size < 100_000
    with pytest.raises(DatasetBuildError) as err:
        load_dataset("bvh_folder", root=archive, cache_dir=tmp_path / "c", workers=1, max_file_mb=1)
    assert f"{archive}::bomb.bvh: file is 3.0 MB" in str(err.value) and "data.max_file_mb=1" in str(err.value)


@pytest.mark.parametrize(("key", "value"), [("max_file_mb", 0), ("max_frames", -5), ("max_frames", "abc"),
                                            ("max_joint_frames", True), ("fps", float("nan"))])
def test_bad_limit_values_name_the_key(tmp_path, key, value):
    with pytest.raises(ValueError, match=f"data.{key} must be"):
        _load(tmp_path, tmp_path, **{key: value})


# ---------------------------------------------------------------------------------------------
# Silent wrong results become warnings (relayed from workers and from the cache)


@pytest.mark.parametrize("workers", [1, 2])
def test_z_up_file_read_as_y_up_warns_naming_it(tmp_path, workers):
    root = _folder(tmp_path, {"y.bvh": canonical_bvh(), "z.bvh": canonical_bvh(z_up=True)})
    with pytest.warns(MotionDataWarning, match="data.up_axis=z") as record:
        ts = _load(root, tmp_path, workers=workers)
    messages = [str(w.message) for w in record if issubclass(w.category, MotionDataWarning)]
    assert len(messages) == 1 and messages[0].startswith(f"{root / 'z.bvh'}: read as Y-up")
    assert ts.warnings == messages
    with pytest.warns(MotionDataWarning, match="z.bvh"):  # from the cache too
        again = _load(root, tmp_path)
    assert again.warnings == messages
    # Declared Z up: the Z-up file is quiet, the Y-up one warns.
    with pytest.warns(MotionDataWarning) as record:
        ts_z = _load(root, tmp_path, up_axis="z")
    warned = [str(w.message) for w in record if issubclass(w.category, MotionDataWarning)]
    assert len(warned) == 1 and warned[0].startswith(f"{root / 'y.bvh'}: read as Z-up") and "up_axis=y" in warned[0]
    z = {t.name: t for t in ts_z.takes}["z"].positions
    y = {t.name: t for t in ts.takes}["y"].positions
    np.testing.assert_allclose(z, y, atol=1e-5)  # read right, the Z-up file is the Y-up one


def test_upright_files_do_not_warn(tmp_path):
    root = _folder(tmp_path, {"y.bvh": canonical_bvh()})
    with warnings.catch_warnings():
        warnings.simplefilter("error", MotionDataWarning)
        assert _load(root, tmp_path).warnings == []


# ---------------------------------------------------------------------------------------------
# Names become file names


def test_duplicate_take_names_are_refused_naming_both_paths(tmp_path):
    root = _folder(tmp_path, {"sub/a.bvh": canonical_bvh(), "sub_a.bvh": canonical_bvh(),
                              "Walk.bvh": canonical_bvh(), "walk.bvh": canonical_bvh(), "ok.bvh": canonical_bvh()})
    with pytest.raises(DatasetBuildError) as err:
        _load(root, tmp_path)
    message = str(err.value)
    assert "4 broken input file(s)" in message
    assert f"{root / 'sub' / 'a.bvh'}: take name 'sub_a' is also the take name of {root / 'sub_a.bvh'}" in message
    assert f"{root / 'Walk.bvh'}: take name 'Walk' is also the take name of {root / 'walk.bvh'}" in message
    ts = _load(root, tmp_path, skip_broken=True)
    assert [t.name for t in ts.takes] == ["ok"] and len(ts.skipped) == 4


def test_take_names_from_zip_paths_are_safe_and_keep_their_source(tmp_path):
    archive = tmp_path / "evil.zip"
    with zipfile.ZipFile(archive, "w") as zf:
        zf.writestr("../../outside/x.bvh", canonical_bvh())
        zf.writestr("/abs/y z.bvh", canonical_bvh())
    ts = load_dataset("bvh_folder", root=archive, cache_dir=tmp_path / "c", workers=1)
    assert {t.name: t.source for t in ts.takes} == {
        "outside_x": f"{archive}::../../outside/x.bvh", "abs_y_z": f"{archive}::/abs/y z.bvh"}


def _bandai_like(tmp_path: Path, members: dict[str, str], labels: dict[str, bytes] | None = None) -> Path:
    """A Bandai-style zip (one content, one style) with its label tables beside it."""
    cfg = tmp_path / "cfg"
    cfg.mkdir()
    (cfg / "content_label.txt").write_text("dataset-2_walk\n")
    (cfg / "style_label.txt").write_text("dataset-2_normal\n")
    archive = tmp_path / "data.zip"
    with zipfile.ZipFile(archive, "w") as zf:
        for member, text in members.items():
            zf.writestr(member, text)
            label = (labels or {}).get(member, json.dumps({"content": 0, "style": 0}).encode())
            zf.writestr(member.replace(".bvh", ".json"), label)
    return archive


def test_bandai_same_file_name_in_two_folders_is_refused(tmp_path):
    bvh = canonical_bvh()
    archive = _bandai_like(tmp_path, {"a/dataset-2_walk_normal_001.bvh": bvh, "b/dataset-2_walk_normal_001.bvh": bvh,
                                      "dataset-2_walk_normal_002.bvh": bvh})
    with pytest.raises(DatasetBuildError) as err:
        load_dataset("bandai", root=archive, cache_dir=tmp_path / "c", workers=1)
    message = str(err.value)
    assert (f"{archive}::a/dataset-2_walk_normal_001.bvh: take name 'dataset-2_walk_normal_001' is also the take "
            f"name of {archive}::b/dataset-2_walk_normal_001.bvh") in message
    assert f"{archive}::b/dataset-2_walk_normal_001.bvh: take name" in message
    ts = load_dataset("bandai", root=archive, cache_dir=tmp_path / "c", workers=1, skip_broken=True)
    assert [t.name for t in ts.takes] == ["dataset-2_walk_normal_002"] and len(ts.skipped) == 2


def test_bandai_label_file_of_any_shape_is_reported(tmp_path):
    names = [f"dataset-2_walk_normal_00{i}.bvh" for i in range(1, 5)]
    archive = _bandai_like(tmp_path, dict.fromkeys(names, canonical_bvh()), {
        names[1]: b"\x80\x81 not UTF-8", names[2]: b"[0, 0]", names[3]: b'{"content": true, "style": 0}'})
    ts = load_dataset("bandai", root=archive, cache_dir=tmp_path / "c", workers=1, skip_broken=True)
    assert [t.name for t in ts.takes] == ["dataset-2_walk_normal_001"]
    reasons = [why for _, why in ts.skipped]
    assert len(reasons) == 3
    assert "normal_002.json" in reasons[0] and "not UTF-8" in reasons[0]
    assert "normal_003.json" in reasons[1] and "holds a list" in reasons[1]
    assert "normal_004.json" in reasons[2] and "'content' = True is not an index" in reasons[2]


def test_unsafe_labels_from_a_csv_name_the_line(tmp_path):
    root = _folder(tmp_path, {"a.bvh": canonical_bvh(), "b.bvh": canonical_bvh()})
    for bad in ["../x", "a/b", ""]:
        csv = tmp_path / "labels.csv"
        csv.write_text(f"file,content,style\na,walk,neutral\nb,walk,{bad}\n")
        with pytest.raises(MotionDataError) as err:
            _load(root, tmp_path, labels_csv=csv)
        assert str(err.value).startswith(f"{csv}:3: style label {bad!r} is not a safe file name")
    csv.write_bytes("\ufefffile,content,style\na,walk,neutral\nb,run,elderly\n".encode())  # spreadsheet BOM
    assert {t.name: t.style for t in _load(root, tmp_path, labels_csv=csv).takes} == {"a": "neutral", "b": "elderly"}


def test_unsafe_labels_from_a_pattern_name_the_file_and_pattern(tmp_path):
    root = _folder(tmp_path, {"walk_01.bvh": canonical_bvh(), "walk .._02.bvh": canonical_bvh()})
    pattern = r"(?P<content>.+)_(?P<take>\d+)"
    with pytest.raises(DatasetBuildError) as err:
        _load(root, tmp_path, pattern=pattern)
    message = str(err.value)
    assert f"{root / 'walk .._02.bvh'}: content label 'walk ..' is not a safe file name" in message
    assert repr(pattern) in message and "1 broken input file(s)" in message
    with pytest.raises(ValueError, match="data.default_labels: style label 'a/b'"):
        _load(root, tmp_path, default_labels={"style": "a/b"})
    with pytest.raises(ValueError, match="data.pattern"):
        _load(root, tmp_path, pattern="(?P<x")


def test_synthetic_take_names_are_safe_as_they_are():
    names = [t.name for t in build_dataset({"name": "synthetic", "takes_per_pair": 1, "duration_s": 1.0}).takes]
    assert len(names) > 10 and all(safe_name(n) == n for n in names)


@pytest.mark.realdata
def test_bandai_take_names_stay_the_file_stems(bandai_zip_path, tmp_path):
    with zipfile.ZipFile(bandai_zip_path) as zf:
        stems = [Path(m).stem for m in zf.namelist() if m.endswith(".bvh")]
    assert len(stems) > 2000 and all(safe_name(s) == s for s in stems)  # sanitizing changes no name
    ts = load_dataset("bandai", root=bandai_zip_path, contents=["walk"], styles=["masculine"],
                      cache_dir=tmp_path, workers=1)
    assert [t.name for t in ts.takes] == sorted(s for s in stems if "_walk_masculine_" in s)


# ---------------------------------------------------------------------------------------------
# The cache follows content and survives damage


def test_same_size_same_mtime_edit_is_not_served_stale(tmp_path):
    root = _folder(tmp_path, {"a.bvh": canonical_bvh()})
    path = root / "a.bvh"
    first = _load(root, tmp_path).takes[0].positions
    stat = path.stat()
    text = path.read_text()
    edited = text.replace("0.950000", "0.850000", 1)  # lower the root 10 cm in the first frame
    assert len(edited) == len(text) and edited != text
    path.write_text(edited)
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    again = _load(root, tmp_path).takes[0].positions
    assert again[0, 0, 1] == pytest.approx(first[0, 0, 1] - 0.1, abs=1e-6)


def _entry(cache: Path) -> Path:
    (entry,) = [p for p in cache.iterdir() if not p.name.startswith(".")]
    return entry


@pytest.mark.parametrize("damage", ["truncate_npy", "garbage_npy", "flip_npy_data", "garbage_index",
                                    "missing_npy", "bad_span", "file_not_folder"])
def test_corrupt_cache_entry_is_rebuilt_with_a_warning(tmp_path, damage):
    root = _folder(tmp_path, {"a.bvh": canonical_bvh(), "b.bvh": canonical_bvh(frames=30)})
    first = _load(root, tmp_path)
    entry = _entry(tmp_path / "cache")
    npy, index = entry / "positions.npy", entry / "index.json"
    if damage == "truncate_npy":
        npy.write_bytes(npy.read_bytes()[:200])
    elif damage == "garbage_npy":
        npy.write_bytes(b"not a numpy file at all")
    elif damage == "flip_npy_data":
        raw = bytearray(npy.read_bytes())
        raw[-5] ^= 0xFF
        npy.write_bytes(bytes(raw))
    elif damage == "garbage_index":
        index.write_text("{ half an ind")
    elif damage == "missing_npy":
        npy.unlink()
    elif damage == "file_not_folder":
        npy.unlink()
        index.unlink()
        entry.rmdir()
        entry.write_text("a file where the entry's folder belongs")
    else:
        data = json.loads(index.read_text())
        data["takes"][0]["stop"] = 10_000
        index.write_text(json.dumps(data))
    with pytest.warns(CacheWarning, match=f"{entry}: corrupt dataset cache entry"):
        again = _load(root, tmp_path)
    for a, b in zip(first.takes, again.takes):
        np.testing.assert_array_equal(a.positions, b.positions)
    with warnings.catch_warnings():
        warnings.simplefilter("error", CacheWarning)
        _load(root, tmp_path)  # the rebuilt entry is sound


# ---------------------------------------------------------------------------------------------
# Options are checked before any work


@pytest.mark.parametrize("workers", ["abc", 0, -2, True, 1.5])
def test_bad_workers_value_names_the_key(tmp_path, workers):
    root = _folder(tmp_path, {"a.bvh": canonical_bvh()})
    with pytest.raises(ValueError, match=r"data\.workers .*got " + repr(workers).replace(".", r"\.")):
        load_dataset("bvh_folder", root=root, cache_dir=tmp_path / "c", workers=workers)
    with pytest.raises(ValueError, match=r"data\.workers"):
        build_dataset({"name": "bandai", "root": tmp_path / "missing.zip", "workers": workers})


@pytest.mark.parametrize("key", ["skip_broken", "use_cache"])
def test_flags_must_be_booleans(tmp_path, key):
    root = _folder(tmp_path, {"a.bvh": canonical_bvh()})
    with pytest.raises(ValueError, match=f"data.{key} must be true or false, got 'abc'"):
        _load(root, tmp_path, **{key: "abc"})
