"""Suite ``bad_input``: the bad-input probe of issue 26, committed and rerunnable.

Each case runs one installed console script (all 14) as a real subprocess, in its own folder under a temporary
root, on inputs this suite generates (small synthetic BVH files and their broken variants, zips, FIFOs, links,
keyframe/marker/path files, checkpoints) or on a tiny finished run trained once per suite run. A case declares what
it expects — ``refused`` (non-zero exit, one line on stderr naming the file, key or value), ``answered`` (exit 0,
outputs checked: finite numbers, no NaN in JSON), ``either`` (a clear refusal or a checked answer; a warning named
in ``warn`` must be printed) or ``interrupt`` (Ctrl-C mid-run: exit 130, one line, nothing half-written) — and
:func:`classify` turns what happened into one outcome (:data:`OUTCOMES`, explained in benchmarks/bad_input.md).
The temporary root (with a decoy folder that links point into) is snapshotted before and after every case: a file
changed outside the case's output folders is ``wrote-outside``, one changed in a finished run ``touched-earlier``.
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import random
import re
import resource
import shlex
import shutil
import signal
import stat
import sys
import tempfile
import time
import zipfile
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from suites.common import md_table, provenance_line

DESCRIPTION = "bad input over all 14 commands: each case a subprocess, classified (clear, traceback, hang, …)"
DEFAULT_SEEDS = (0,)  # the inputs are generated deterministically; the seed only draws the binary junk

ROOT = Path(__file__).resolve().parents[2]
#: Every outcome, the wanted ones first.
OUTCOMES = ("clear", "correct", "refused-valid", "unclear", "traceback", "silent-wrong", "wrote-outside",
            "touched-earlier", "unbounded", "hang")
#: The outcomes the issue's aim asks to be zero.
AIM_ZERO = ("traceback", "silent-wrong", "wrote-outside", "touched-earlier", "unbounded", "hang")
#: Peak resident memory (kB) above which a case counts as unbounded (every case's input is under a few MB).
RSS_BOUND_KB = 3_000_000
#: Address-space limit of every case (bytes): a runaway allocation fails instead of taking the shared machine.
ADDRESS_LIMIT = 12 * 2**30
COMMANDS = ("stylemotion-data", "stylemotion-train", "stylemotion-reproduce", "stylemotion-eval",
            "stylemotion-generate", "stylemotion-segment", "stylemotion-search", "stylemotion-annotate",
            "stylemotion-reconstruct", "stylemotion-keyframes", "stylemotion-texture", "stylemotion-style",
            "stylemotion-convert", "stylemotion-view")
ARGPARSE = {"stylemotion-convert", "stylemotion-view"}
#: Commands whose output folder legitimately keeps finished parts after Ctrl-C (a rerun resumes from them).
RESUMABLE = {"stylemotion-train", "stylemotion-reproduce"}
TAKE = "synthetic_walk_normal_000"
#: The synthetic data every Hydra case uses (one take per content and style: the cache builds in seconds).
DATA = ["data.takes_per_pair=1"]
#: A few-second training run (train, val and test takes of two contents and two styles).
SMOKE = ["experiment=smoke", "data.takes_per_pair=3", "data.duration_s=4.0", "data.styles=[normal,elderly]",
         "data.contents=[walk,run]", "threads=1"]


# ----------------------------------------------------------------------------------------------------------------
# Cases


@dataclass
class Case:
    """One bad (or good) input to one command (module docstring)."""

    id: str
    command: str
    args: list[str]
    expect: str  # refused | answered | either | interrupt
    kind: str  # what kind of input it is (the issue's list)
    names: tuple[str, ...] = ()  # a refusal's line names one of these
    out: tuple[str, ...] = ("out",)  # paths (relative to the case folder) the command may write
    earlier: tuple[str, ...] = ()  # finished results (relative to the case folder) that must stay untouched
    setup: Callable[[Path], None] | None = None
    check: Callable[[Path], str | None] | None = None  # an answer's extra check: a problem or None
    warn: tuple[str, ...] = ()  # an answer must print one of these (a warning naming the file)
    timeout: float = 180.0
    interrupt_after: float | None = None  # seconds after ``trigger`` appears (or after the start)
    trigger: str | None = None  # a path (relative to the case folder) whose appearance starts that clock
    hydra_dir: bool = True  # append hydra.run.dir=hydra (Hydra commands)
    own_cache: bool = False  # STYLEMOTION_CACHE in the case folder (``cache``, an allowed output), not the shared one

    def argv(self) -> list[str]:
        hydra = self.hydra_dir and self.command not in ARGPARSE
        return [self.command, *self.args, *(["hydra.run.dir=hydra"] if hydra else [])]


@dataclass
class Inputs:
    """Where the generated inputs and finished runs lie (absolute paths)."""

    root: Path
    inputs: Path = field(init=False)
    decoy: Path = field(init=False)
    earlier: Path = field(init=False)

    def __post_init__(self) -> None:
        self.inputs, self.decoy, self.earlier = self.root / "inputs", self.root / "decoy", self.root / "earlier"

    def i(self, name: str) -> str:
        return str(self.inputs / name)


def _bvh_variants(good: str, rng: random.Random) -> dict[str, bytes | None]:
    """Broken, odd and valid variants of a valid BVH text (None: made by :func:`_special_files`)."""
    head, motion = good.split("MOTION\n", 1)
    lines = motion.splitlines()
    frames_line, time_line, rows = lines[0], lines[1], lines[2:]
    row0 = rows[0].split()

    def with_rows(new_rows: list[str], frames: str | None = None, frame_time: str | None = None) -> bytes:
        text = (head + "MOTION\n" + (frames or frames_line) + "\n" + (frame_time or time_line) + "\n"
                + "\n".join(new_rows) + "\n")
        return text.encode()

    def one_value(value: str) -> bytes:
        row = row0.copy()
        row[7] = value
        return with_rows([" ".join(row), *rows[1:]])

    nested = "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation " \
             "Xrotation Yrotation\n" + "".join(f"JOINT J{i}\n{{\nOFFSET 0 1 0\nCHANNELS 3 Zrotation Xrotation " \
                                               f"Yrotation\n" for i in range(3000)) + "}\n" * 3001
    return {
        "empty": b"",
        "binary": rng.randbytes(4096),
        "text_junk": b"hello, this is not a motion capture file\n" * 20,
        "cut_in_hierarchy": good.encode()[: len(head) // 2],
        "cut_in_motion": good.encode()[: len(head) + (len(good) - len(head)) // 2],
        "fewer_rows": with_rows(rows[: len(rows) // 2]),
        "frames_huge": with_rows(rows, frames="Frames: 999999999999"),
        "frames_negative": with_rows(rows, frames="Frames: -5"),
        "frames_zero": with_rows([], frames="Frames: 0"),
        "one_frame": with_rows(rows[:1], frames="Frames: 1"),
        "number_huge": one_value("1e308"),
        "number_overflow": one_value("1e999"),
        "number_nan": one_value("nan"),
        "number_inf": one_value("-inf"),
        "frame_time_zero": with_rows(rows, frame_time="Frame Time: 0"),
        "frame_time_negative": with_rows(rows, frame_time="Frame Time: -0.0333333"),
        "frame_time_nan": with_rows(rows, frame_time="Frame Time: nan"),
        "frame_time_huge": with_rows(rows, frame_time="Frame Time: 1e300"),
        "millisecond": with_rows(rows, frame_time="Frame Time: 33.333333"),
        "channels_wrong": head.replace("CHANNELS 3", "CHANNELS 4", 1).encode() + ("MOTION\n" + motion).encode(),
        "row_too_long": with_rows([r + " 1.0 2.0" for r in rows]),
        "offset_huge": head.replace("OFFSET", "OFFSET 1e300 0 0 #", 1).encode() + ("MOTION\n" + motion).encode(),
        "deep_nesting": nested.encode() + b"MOTION\nFrames: 1\nFrame Time: 0.0333333\n" + b"0 " * 9006 + b"\n",
        "utf16": good.encode("utf-16"),
        "crlf": good.replace("\n", "\r\n").encode(),
        "zup": None, "unknown_skeleton": None,
        "folder": None, "fifo": None, "loop_link": None, "dangling_link": None, "dev_zero": None, "huge_file": None,
    }


#: Variants a reader must accept (exit 0, finite output), and those that load but must warn (file named).
VALID_BVH = {"good", "crlf", "one_frame"}
#: Variants a reader may accept without a warning or refuse: an angle of 1e308° is read modulo 360°.
EITHER_BVH = {"number_huge"}
WARN_BVH = {"zup"}


def _special_files(inputs: Path, name: str) -> None:
    path = inputs / f"{name}.bvh"
    if name == "folder":
        path.mkdir()
    elif name == "fifo":
        os.mkfifo(path)
    elif name == "loop_link":
        path.symlink_to(path.name)
    elif name == "dangling_link":
        path.symlink_to("nowhere/at_all.bvh")
    elif name == "dev_zero":
        path.symlink_to("/dev/zero")
    elif name == "huge_file":
        with open(path, "wb") as fh:  # sparse: 300 MB (above max_file_mb = 256) without using the disk
            fh.truncate(300 * 2**20)


def _write_checkpoints(folder: Path, repro: Path, decoy: Path) -> None:
    """Checkpoints that are not what they claim: empty, junk, cut off, the wrong kind, a malicious pickle."""
    import torch

    good = repro / "vae" / "walk_leftStance" / "checkpoints" / "best.ckpt"
    (folder / "empty.ckpt").write_bytes(b"")
    (folder / "junk.ckpt").write_bytes(b"\x80\x04junk, not a checkpoint" * 10)
    (folder / "cut.ckpt").write_bytes(good.read_bytes()[:5000])
    shutil.copy(repro / "autoencoder" / "checkpoints" / "best.ckpt", folder / "autoencoder.ckpt")
    torch.save({"weights": torch.zeros(3)}, folder / "foreign.ckpt")
    (folder / "malicious.ckpt").write_bytes(pickle.dumps(_Pwn(str(decoy / "PWNED"))))
    state = torch.load(good, map_location="cpu", weights_only=False)
    for value in state["state_dict"].values():
        if value.is_floating_point():
            value.fill_(float("nan"))
    torch.save(state, folder / "nan_weights.ckpt")


class _Pwn:
    """A pickle that, when loaded, creates a file in the decoy folder (a loaded pickle shows as wrote-outside)."""

    def __init__(self, target: str):
        self.target = target

    def __reduce__(self):
        return (os.system, (f"touch {shlex.quote(self.target)}",))


def _zip(path: Path, members: Mapping[str, bytes], compress: bool = True) -> None:
    method = zipfile.ZIP_DEFLATED if compress else zipfile.ZIP_STORED
    with zipfile.ZipFile(path, "w", method) as zf:
        for name, data in members.items():
            zf.writestr(name, data)


def _bomb(path: Path, member: str, mb: int) -> None:
    """A zip whose one member inflates to ``mb`` MB of zeros (about 1/1000 of that on disk)."""
    chunk = b"\0" * 2**20
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf, zf.open(member, "w", force_zip64=True) as fh:
        for _ in range(mb):
            fh.write(chunk)


def make_inputs(paths: Inputs, seed: int, say: Callable[[str], None]) -> dict[str, Any]:
    """Generate every input file, train the tiny runs the reruns need; what was made (for the results)."""
    import numpy as np

    from stylemotion.datasets.registry import load_dataset
    from stylemotion.io.export import write_motion_bvh
    from stylemotion.reconstruct.markers import write_marker_csv

    rng = random.Random(seed)
    inputs, decoy, earlier = paths.inputs, paths.decoy, paths.earlier
    for folder in (inputs, decoy):
        if folder.exists():  # a development root (--root): inputs are made again, finished runs kept
            _make_removable(folder)
            shutil.rmtree(folder)
        folder.mkdir(parents=True)
    earlier.mkdir(exist_ok=True)
    (decoy / "keep.txt").write_text("a file outside every output folder\n")
    (decoy / "sub").mkdir()
    (decoy / "sub" / "keep.json").write_text("{}\n")

    takeset = load_dataset("synthetic", takes_per_pair=1)
    walk = next(t for t in takeset.takes if t.name == TAKE)
    positions = walk.positions[:90]  # 3 s at 30 fps, metres, Y up
    write_motion_bvh(positions, inputs / "good.bvh", takeset.fps)
    good = (inputs / "good.bvh").read_text()
    zup = positions[..., [0, 2, 1]] * np.array([1.0, -1.0, 1.0])
    write_motion_bvh(zup, inputs / "zup.bvh", takeset.fps)
    write_motion_bvh(np.concatenate([walk.positions] * 2), inputs / "document.bvh", takeset.fps)  # 16 s
    long_walk = np.concatenate([walk.positions] * 40)  # 5 min: long enough to be interrupted
    write_motion_bvh(long_walk, inputs / "long.bvh", takeset.fps)
    (inputs / "unknown_skeleton.bvh").write_text(
        "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
        "Yrotation\nJOINT Tail\n{\nOFFSET 0 -10 -5\nCHANNELS 3 Zrotation Xrotation Yrotation\nEnd Site\n{\n"
        "OFFSET 0 -10 0\n}\n}\n}\nMOTION\nFrames: 3\nFrame Time: 0.0333333\n" + "0 90 0 0 0 0 0 0 0\n" * 3)
    for name, data in _bvh_variants(good, rng).items():
        if data is not None:
            (inputs / f"{name}.bvh").write_bytes(data)
        elif not (inputs / f"{name}.bvh").exists():
            _special_files(inputs, name)
    # folders of BVH files for stylemotion-data data=bvh_folder: a valid file beside each odd one
    for name in ("good", "fifo", "loop_link", "dangling_link", "folder", "empty", "binary", "number_nan",
                 "millisecond", "unknown_skeleton"):
        folder = inputs / "folders" / name
        folder.mkdir(parents=True)
        shutil.copy(inputs / "good.bvh", folder / "walk_a.bvh")
        if name != "good":
            source = inputs / f"{name}.bvh"
            if source.is_symlink() or not source.is_file():
                _special_files(folder, name)
            else:
                shutil.copy(source, folder / f"{name}.bvh")
    (inputs / "folders" / "nothing").mkdir()
    # zips
    _zip(inputs / "escape.zip", {"../../escaped.bvh": good.encode(), "walk.bvh": good.encode()})
    _zip(inputs / "absolute.zip", {str(decoy / "absolute.bvh"): good.encode()})
    _bomb(inputs / "bomb.zip", "walk.bvh", 400)
    (inputs / "junk.zip").write_bytes(b"PK\x03\x04 cut off here")
    _zip(inputs / "member.zip", {"walk.bvh": good.encode()})
    # markers (CSV, NPZ), keys (JSON), paths (CSV, JSON)
    joints = ["Hips", "Head", "Hand_L", "Hand_R", "Foot_L", "Foot_R"]
    from stylemotion.skeleton import CANONICAL_JOINTS
    columns = [CANONICAL_JOINTS.index(j) for j in joints]
    write_marker_csv(inputs / "markers.csv", joints, positions[:, columns], takeset.fps)
    text = (inputs / "markers.csv").read_text().splitlines()
    (inputs / "markers_nan.csv").write_text("\n".join(text[:5] + [re.sub(r"[-0-9.]+$", "nan", text[5])] + text[6:]))
    (inputs / "markers_huge.csv").write_text("\n".join(text[:5] + [re.sub(r"[-0-9.]+$", "1e300", text[5])]
                                                       + text[6:]))
    (inputs / "markers_short_rows.csv").write_text("\n".join(text[:4] + [",".join(text[4].split(",")[:5])]
                                                             + text[5:]))
    (inputs / "markers_header_only.csv").write_text("\n".join(text[:2]) + "\n")
    (inputs / "markers_unknown_joint.csv").write_text(text[0] + "\n" + text[1].replace("Head_", "Tail_") + "\n"
                                                      + "\n".join(text[2:]) + "\n")
    (inputs / "markers_no_header.csv").write_text("\n".join(text[2:]) + "\n")
    np.savez(inputs / "markers.npz", positions=positions.astype(np.float32), fps=np.float64(30))
    np.savez(inputs / "markers_wrong_shape.npz", positions=np.zeros((90, 3), np.float32), fps=np.float64(30))
    np.savez(inputs / "markers_nan.npz", positions=np.full_like(positions, np.nan, dtype=np.float32),
             fps=np.float64(30))
    np.savez(inputs / "markers_fps_zero.npz", positions=positions.astype(np.float32), fps=np.float64(0))
    np.savez(inputs / "pickled.npz", positions=np.array([{"x": 1}], dtype=object), fps=np.float64(30))
    (inputs / "pickle.npz").write_bytes(pickle.dumps(_Pwn(str(decoy / "PWNED"))))
    pose = positions[0].round(4).tolist()

    def keys(*items: dict) -> str:
        return json.dumps({"keys": list(items)})

    key_files = {
        "keys_good": keys({"time": 0, "take": TAKE, "frame": 0}, {"time": 1.0, "take": TAKE, "frame": 30}),
        "keys_time_huge": keys({"time": 0, "take": TAKE, "frame": 0}, {"time": 200000, "take": TAKE, "frame": 30}),
        "keys_time_1e9": keys({"time": 0, "take": TAKE, "frame": 0}, {"time": 1e9, "take": TAKE, "frame": 30}),
        "keys_time_negative": keys({"time": -5, "take": TAKE, "frame": 0}, {"time": 1, "take": TAKE, "frame": 30}),
        "keys_time_equal": keys({"time": 1, "take": TAKE, "frame": 0}, {"time": 1, "take": TAKE, "frame": 30}),
        "keys_frame_out_of_range": keys({"time": 0, "take": TAKE, "frame": 0},
                                        {"time": 1, "take": TAKE, "frame": 10**9}),
        "keys_unknown_take": keys({"time": 0, "take": "nope", "frame": 0}, {"time": 1, "take": TAKE, "frame": 3}),
        "keys_positions_wrong_shape": keys({"time": 0, "positions": pose[:20]}, {"time": 1, "positions": pose}),
        "keys_positions_nan": keys({"time": 0, "positions": [[float("nan")] * 3] * 21},
                                   {"time": 1, "positions": pose}),
        "keys_one_key": keys({"time": 0, "take": TAKE, "frame": 0}),
        "keys_empty": json.dumps({"keys": []}),
        "keys_not_object": json.dumps([1, 2, 3]),
        "keys_every_zero": json.dumps({"motion": paths.i("good.bvh"), "every_s": 0}),
        "keys_every_nan": json.dumps({"motion": paths.i("good.bvh"), "every_s": float("nan")}),
        "keys_cut": keys({"time": 0, "take": TAKE, "frame": 0})[:25],
        "keys_turn_huge": json.dumps({"keys": [{"time": 0, "take": TAKE, "frame": 0},
                                               {"time": 1, "take": TAKE, "frame": 30, "turn_deg": 1e308,
                                                "shift_m": [1e308, 0, 0]}]}),
    }
    for name, text in key_files.items():
        (inputs / f"{name}.json").write_text(text)
    for name in ("good", "empty", "binary", "number_nan", "fifo", "frame_time_zero", "millisecond", "zup"):
        (inputs / f"keys_motion_{name}.json").write_text(
            json.dumps({"motion": paths.i(f"{name}.bvh"), "every_s": 1.0}))
    paths_files = {
        "path_good.json": json.dumps({"points": [[0, 0], [1.5, 0.3], [3, 0]]}),
        "path_short.json": json.dumps({"points": [[0, 0], [0.3, 0]]}),
        "path_one_point.json": json.dumps({"points": [[0, 0]]}),
        "path_wrong_shape.json": json.dumps({"points": [[0, 0, 0, 1], [1, 2, 3, 4]]}),
        "path_huge.json": json.dumps({"points": [[0, 0], [1e9, 0]]}),
        "path_nan.csv": "x,z\n0,0\nnan,1\n3,0\n",
        "path_text.csv": "x,z\n0,0\nleft,1\n",
        "path_empty.csv": "",
        "path_cut.json": '{"points": [[0, 0], [1.5',
    }
    for name, text in paths_files.items():
        (inputs / name).write_text(text)
    (inputs / "afile").write_text("a file where a folder is expected\n")
    (inputs / "notes.txt").write_text("not a motion\n")

    # finished results the reruns point at (made once, reused by every case that copies them)
    sys.path.insert(0, str(ROOT / "tests"))
    from reproduce_fixtures import tiny_overrides  # the test suite's tiny run: the same settings

    steps = [("repro", ["stylemotion-reproduce", *tiny_overrides(earlier / "repro")]),
             ("train", ["stylemotion-train", *SMOKE, f"hydra.run.dir={earlier / 'train'}"]),
             ("search", ["stylemotion-search", *DATA, f"query={TAKE}:0-30", f"out={earlier / 'search'}"]),
             ("templates", ["stylemotion-annotate", *DATA, "per_class=2", f"out={earlier / 'templates'}"])]
    for name, argv in steps:
        if not (earlier / name / ".done").exists():
            say(f"finished result earlier/{name}: {argv[0]} (the tiny reproduce run takes about a minute)")
            if (earlier / name).exists():
                shutil.rmtree(earlier / name)
            hydra = [] if any(a.startswith("hydra.run.dir=") for a in argv) else [
                f"hydra.run.dir={earlier / 'hydra' / name}"]
            _must_run([*argv, *hydra], earlier)
            (earlier / name / ".done").write_text("")
    _write_checkpoints(inputs, earlier / "repro", decoy)
    (inputs / "report_cut").mkdir()
    (inputs / "report_cut" / "report").mkdir()
    (inputs / "report_cut" / "report" / "report.json").write_text('{"meta": {"checkpoints": [')
    return {"bvh_variants": sorted(p.name for p in inputs.glob("*.bvh"))}


def _must_run(argv: list[str], cwd: Path) -> None:
    import subprocess

    done = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, env=_environment(cwd.parent / "cache"))
    if done.returncode != 0:
        raise RuntimeError(f"setup step {shlex.join(argv)} failed ({done.returncode}):\n{done.stderr[-3000:]}")


def _environment(cache: Path) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("HYDRA_FULL_ERROR", "STYLEMOTION_DEBUG")}
    env.update(STYLEMOTION_CACHE=str(cache), OMP_NUM_THREADS="1", MKL_NUM_THREADS="1", PYTHONUNBUFFERED="1")
    return env


def _copy(source: Path, name: str) -> Callable[[Path], None]:
    def setup(folder: Path) -> None:
        shutil.copytree(source, folder / name, symlinks=True)
    return setup


def _steps(*setups: Callable[[Path], None]) -> Callable[[Path], None]:
    def setup(folder: Path) -> None:
        for step in setups:
            step(folder)
    return setup


def _file(name: str, text: str = "mine\n") -> Callable[[Path], None]:
    def setup(folder: Path) -> None:
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    return setup


def _link(name: str, target: Path) -> Callable[[Path], None]:
    def setup(folder: Path) -> None:
        (folder / name).symlink_to(target)
    return setup


def _read_only(name: str) -> Callable[[Path], None]:
    """A folder nobody may write, root included (``chattr +i``: the suite runs as root here, for whom a mode
    of 0555 means nothing); :func:`run_case` makes it writable again afterwards."""
    def setup(folder: Path) -> None:
        import subprocess

        (folder / name).mkdir()
        (folder / name).chmod(0o555)
        subprocess.run(["chattr", "+i", str(folder / name)], check=False, capture_output=True)
    return setup


def _unlock(folder: Path) -> None:
    import subprocess

    for path in folder.rglob("*"):
        if path.is_dir() and not path.is_symlink() and path.stat().st_mode & 0o777 == 0o555:
            subprocess.run(["chattr", "-i", str(path)], check=False, capture_output=True)


def build_cases(p: Inputs) -> list[Case]:
    """Every case (ids unique), over all 14 commands."""
    cases: list[Case] = []
    i = p.i
    repro, train_run = p.earlier / "repro", p.earlier / "train"

    def add(command: str, id_: str, args: Sequence[str], expect: str, kind: str, names: Sequence[str] = (),
            **options: Any) -> None:
        cases.append(Case(f"{command.removeprefix('stylemotion-')}/{id_}", command, list(args), expect, kind,
                          tuple(names), **options))

    # --- BVH files of every kind, read by every command that reads one -------------------------------------------
    bvh = ["good", "crlf", "zup", "millisecond", "empty", "binary", "text_junk", "cut_in_hierarchy",
           "cut_in_motion", "fewer_rows", "frames_huge", "frames_negative", "frames_zero", "one_frame",
           "number_huge", "number_overflow", "number_nan", "number_inf", "frame_time_zero",
           "frame_time_negative", "frame_time_nan", "frame_time_huge", "channels_wrong", "row_too_long",
           "offset_huge", "deep_nesting", "utf16", "unknown_skeleton", "folder", "fifo", "loop_link",
           "dangling_link", "dev_zero", "huge_file"]
    #: the readers' kinds for the commands that load a database first (seconds per case)
    fewer = ["good", "zup", "millisecond", "empty", "binary", "frames_huge", "number_nan", "unknown_skeleton",
             "fifo", "huge_file"]
    fewest = ["good", "millisecond", "binary", "fifo"]
    #: the viewer reads BVH files as convert does: the kinds of another path through the reader
    viewed = ["good", "zup", "empty", "binary", "frames_huge", "number_nan", "deep_nesting", "fifo", "loop_link",
              "huge_file"]

    def expect_of(name: str) -> tuple[str, tuple[str, ...]]:
        if name in VALID_BVH:
            return "answered", ()
        if name in WARN_BVH:
            return "either", (f"{name}.bvh",)
        if name in EITHER_BVH:
            return "either", ()
        return "refused", ()

    for name in bvh:
        expect, warn = expect_of(name)
        names = (f"{name}.bvh",)
        add("stylemotion-convert", f"bvh_{name}", [i(f"{name}.bvh"), "out.npz"], expect, "BVH file", names,
            out=("out.npz",), warn=warn, timeout=90)
        if name in viewed:
            add("stylemotion-view", f"bvh_{name}", [i(f"{name}.bvh"), "--out", "out"], expect, "BVH file", names,
                warn=warn, timeout=90)
    for name in fewer:
        expect, warn = expect_of(name)
        names = (f"{name}.bvh",)
        add("stylemotion-search", f"bvh_{name}", [*DATA, f"query={i(name + '.bvh')}", "out=out"], expect,
            "BVH file", names, warn=warn)
        add("stylemotion-reconstruct", f"bvh_{name}", [*DATA, f"markers={i(name + '.bvh')}", "out=out", "gif=false"],
            expect, "BVH file", names, warn=warn)
    for name in fewest:
        expect, warn = expect_of(name)
        names = (f"{name}.bvh",)
        add("stylemotion-texture", f"bvh_{name}", [*DATA, f"motion={i(name + '.bvh')}", "out=out", "gif=false"],
            expect, "BVH file", names, warn=warn)
        document = "document" if name == "good" else name  # longer than every template
        add("stylemotion-annotate", f"bvh_{name}",
            [*DATA, f"document={i(document + '.bvh')}", f"templates={p.earlier / 'templates'}", "out=out"],
            expect, "BVH file", names, warn=warn)
        if name in ("binary", "fifo"):  # a valid example would train CVAEs (minutes): refusals only
            add("stylemotion-style", f"bvh_{name}",
                [f"example={i(name + '.bvh')}", f"run={repro}", "name=mine", "out=out"], expect, "BVH file", names)
    for name in ("good", "binary", "fifo", "millisecond"):
        expect, warn = expect_of(name)
        add("stylemotion-keyframes", f"motion_{name}", [*DATA, f"keys={i(f'keys_motion_{name}.json')}", "out=out",
                                                        "gif=false"],
            expect, "BVH file as keys", (f"{name}.bvh",), warn=warn)

    # --- stylemotion-data --------------------------------------------------------------------------------------
    data = "stylemotion-data"
    for name in ("good", "fifo", "loop_link", "binary"):
        add(data, f"folder_with_{name}", ["data=bvh_folder", f"data.root={p.inputs / 'folders' / name}"],
            "answered" if name == "good" else "either", "BVH folder", (f"{name}.bvh",), out=("hydra",),
            warn=() if name == "good" else (f"{name}.bvh",))
    for override, names in [
        ("data.fps=0", ["data.fps"]), ("data.fps=nan", ["data.fps"]), ("data.fps=1e308", ["data.fps"]),
        ("data.duration_s=1e9", ["data.duration_s"]), ("data.takes_per_pair=-3", ["data.takes_per_pair"]),
        ("data.contents=[fly]", ["fly"]), ("data.styles=[]", ["data.styles"]),
        ("data.split.val_fraction=1.5", ["val_fraction", "1.5"]), ("data.nope=1", ["nope"]),
    ]:
        add(data, f"value_{override}", [override], "refused", "bad Hydra value", names, out=("hydra",))
    for args, names, kind in [
        (["data=bvh_folder", f"data.root={p.inputs / 'folders' / 'nothing'}"], ["nothing"], "empty folder"),
        (["data=bvh_folder", f"data.root={i('afile')}"], ["afile"], "root is a file"),
        (["data=bvh_folder", "data.root=/nonexistent/mocap"], ["/nonexistent/mocap"], "missing folder"),

        (["data=bvh_folder", f"data.root={i('bomb.zip')}"], ["bomb.zip", "max_file_mb"], "zip bomb"),
        (["data=bvh_folder", f"data.root={i('junk.zip')}"], ["junk.zip"], "truncated zip"),
        (["data=bandai", "data.root=/nonexistent/data.zip"], ["data.zip"], "missing Bandai zip"),
        (["data=bandai", f"data.root={i('junk.zip')}"], ["junk.zip"], "truncated zip"),
        (["data=bandai", f"data.root={i('bomb.zip')}"], ["bomb.zip"], "zip bomb"),
        (["data=bvh_folder", f"data.root={p.inputs / 'folders' / 'good'}", "data.pattern='[z-a]'"],
         ["data.pattern"], "bad regex"),
        (["data=bvh_folder", f"data.root={p.inputs / 'folders' / 'good'}", "+data.default_labels={style: ../x}"],
         ["../x"], "unsafe label"),
        (["data=bvh_folder", f"data.root={p.inputs / 'folders' / 'good'}", "data.max_file_mb=-1"],
         ["max_file_mb"], "negative limit"),
        (["data=bvh_folder", f"data.root={p.inputs / 'folders' / 'good'}", "data.workers=0"], ["workers"],
         "zero count"),
    ]:
        add(data, f"input_{kind.replace(' ', '_')}_{len(cases)}", args, "refused", kind, names, out=("hydra",),
            timeout=240)
    for zip_name, kind in [("escape.zip", "zip with ../ member"), ("absolute.zip", "zip with absolute member")]:
        # a member is read, never extracted: answering is fine as long as nothing is written outside
        add(data, f"input_{zip_name}", ["data=bvh_folder", f"data.root={i(zip_name)}"], "either", kind,
            (zip_name,), out=("hydra",))
    add(data, "interrupt", ["data.takes_per_pair=40"], "interrupt", "Ctrl-C mid-run", out=("hydra", "cache"),
        trigger="hydra", interrupt_after=1.5, own_cache=True)

    # --- stylemotion-train --------------------------------------------------------------------------------------
    tr = "stylemotion-train"
    smoke = SMOKE
    for override, names in [("seed=abc", ["seed"]), ("model.hidden_units=0", ["hidden_units"])]:
        add(tr, f"value_{override}", [*smoke, override], "refused", "bad Hydra value", names, out=("hydra",))
    for name in ("junk", "foreign", "malicious"):
        # the tiny run's autoencoder is a smoke autoencoder of the same shapes: resuming from it is allowed
        add(tr, f"ckpt_{name}", [*smoke, f"ckpt_path={i(name + '.ckpt')}"],
            "either" if name == "autoencoder" else "refused", "checkpoint", (f"{name}.ckpt",), out=("hydra",))
    add(tr, "ckpt_missing", [*smoke, "ckpt_path=/nonexistent/best.ckpt"], "refused", "checkpoint",
        ("/nonexistent/best.ckpt",), out=("hydra",))
    finished = _copy(train_run, "run")
    add(tr, "rerun_finished", [*smoke], "refused", "rerun into finished output", ("run",),
        earlier=("run",), setup=finished, hydra_dir=False, out=())
    cases[-1].args.append("hydra.run.dir=run")
    for extra, expect in [("ckpt_path=auto", "either"), ("ckpt_path=last model.hidden_units=64", "refused")]:
        add(tr, f"resume_finished_{extra.replace(' ', '_')}", [*smoke, *extra.split(), "hydra.run.dir=run"],
            expect, "rerun into finished output", ("run", "hidden_units", "last.ckpt"), earlier=("run",),
            setup=finished, hydra_dir=False, out=())

    def linked_checkpoints(folder: Path) -> None:
        finished(folder)
        shutil.move(folder / "run" / "checkpoints", folder / "elsewhere")
        (folder / "run" / "checkpoints").symlink_to(folder / "elsewhere", target_is_directory=True)

    add(tr, "force_checkpoints_link_out", [*smoke, "force=true", "hydra.run.dir=run"], "refused",
        "out folder links out", ("checkpoints",), setup=linked_checkpoints, hydra_dir=False, out=("run",),
        earlier=("elsewhere",))
    add(tr, "run_dir_is_file", [*smoke, "hydra.run.dir=afile"], "refused", "out is a file", ("afile",),
        setup=_file("afile"), hydra_dir=False, out=())
    add(tr, "run_dir_link_to_decoy", [*smoke, "hydra.run.dir=linked"], "either", "out folder links out",
        ("linked",), setup=_link("linked", p.decoy), hydra_dir=False, out=())
    add(tr, "interrupt", [*smoke, "trainer.max_epochs=50", "trainer.max_steps=-1"], "interrupt", "Ctrl-C mid-run",
        out=("hydra",), trigger="hydra/checkpoints", interrupt_after=0.5, timeout=240)

    # --- stylemotion-reproduce ----------------------------------------------------------------------------------
    rp = "stylemotion-reproduce"
    tiny = ["data.takes_per_pair=2", "data.duration_s=3.0", "data.styles=[normal,elderly]", "data.contents=[walk]"]
    for override, names in [("styles=[nope]", ["nope"]), ("seed=abc", ["seed"])]:
        add(rp, f"value_{override}", [*tiny, override, "out=out"], "refused", "bad Hydra value", names,
            out=("out", "hydra"))
    add(rp, "out_is_file", [*tiny, "out=afile"], "refused", "out is a file", ("afile",), setup=_file("afile"),
        out=("hydra",))

    def cut_record(stage: str, text: str) -> Callable[[Path], None]:
        def setup(folder: Path) -> None:
            _copy(repro, "run")(folder)
            (folder / "run" / stage).write_text(text)
        return setup

    repro_args = [a for a in _tiny_repro_overrides(repro) if not a.startswith("out=")]
    add(rp, "cut_done_json", [*repro_args, "out=run"], "refused", "cut-off record", ("done.json",),
        setup=cut_record("autoencoder/done.json", '{"settings_hash": "ab'), earlier=("run",), out=())
    add(rp, "cut_evaluation_json", [*repro_args, "out=run"], "either", "cut-off record",
        ("evaluation.json", "report"), setup=cut_record("evaluation.json", '{"settings_hash": '), earlier=("run",),
        out=())
    add(rp, "rerun_finished", [*repro_args, "out=run"], "answered", "rerun into finished output",
        setup=_copy(repro, "run"), earlier=("run",), out=(), timeout=300)
    add(rp, "finished_other_settings", [*repro_args, "seed=1", "out=run"], "refused", "rerun into finished output",
        ("run", "seed"), setup=_copy(repro, "run"), earlier=("run",), out=(), timeout=300)
    add(rp, "out_link_to_decoy", [*tiny, "out=linked"], "refused", "out folder links out", ("linked",),
        setup=_link("linked", p.decoy), out=("hydra",))
    add(rp, "value_evaluation.samples.table_5_1=0", [*repro_args, "evaluation.samples.table_5_1=0", "out=out"],
        "refused", "bad Hydra value", ("table_5_1",), out=("out", "hydra"), timeout=300)
    add(rp, "interrupt", [*repro_args, "out=out", "workers=1"], "interrupt", "Ctrl-C mid-run", out=("out", "hydra"),
        trigger="out/autoencoder", interrupt_after=3.0, timeout=240)

    # --- stylemotion-eval ---------------------------------------------------------------------------------------
    ev = "stylemotion-eval"
    small = ["evaluation.samples.table_5_1=50", "evaluation.samples.variance=50", "evaluation.samples.metrics=50",
             "evaluation.classifier.components=4"]
    for name in ("cut", "autoencoder", "malicious"):
        add(ev, f"ckpt_{name}", [f"checkpoints=[{i(name + '.ckpt')}]", "out=out"], "refused", "checkpoint",
            (f"{name}.ckpt",))
    good_ckpt = repro / "vae" / "walk_leftStance" / "checkpoints" / "best.ckpt"
    add(ev, "ckpt_missing", ["checkpoints=[/nonexistent/best.ckpt]", "out=out"], "refused", "checkpoint",
        ("/nonexistent/best.ckpt",))
    add(ev, "ckpt_folder_without", [f"checkpoints=[{p.decoy}]", "out=out"], "refused", "checkpoint",
        (str(p.decoy),))
    for override, names in [("evaluation.samples.table_5_1=0", ["table_5_1"]), ("seed=abc", ["seed"])]:
        add(ev, f"value_{override}", [f"checkpoints=[{good_ckpt}]", *small, override, "out=out"], "refused",
            "bad Hydra value", names)
    add(ev, "out_exists", [f"checkpoints=[{good_ckpt}]", *small, "out=out"], "refused", "out exists", ("out",),
        setup=_file("out/mine.txt"), earlier=("out",), out=())
    add(ev, "good", [f"checkpoints=[{good_ckpt}]", *small, "out=out"], "answered", "valid input", timeout=300)

    # --- stylemotion-generate -----------------------------------------------------------------------------------
    gn = "stylemotion-generate"
    run = f"run={repro}"
    quick = ["outputs.gif=false"]
    for override, names in [("follow.max_steps=0", ["max_steps"]), ("seed=abc", ["seed"]),
                            ("path.points=[[0,0],[nan,1]]", ["path", "nan"])]:
        add(gn, f"value_{override}", [run, *quick, override.strip("'"), "out=out"], "refused", "bad Hydra value",
            names)
    for name in ("malicious",):
        add(gn, f"ckpt_{name}", [run, *quick, f"+models={{walk_leftStance: {i(name + '.ckpt')}, walk_rightStance: "
                                                  f"{i(name + '.ckpt')}}}", "out=out"],
            "refused", "checkpoint", (f"{name}.ckpt",))
    add(gn, "run_missing", ["run=/nonexistent/run", *quick, "out=out"], "refused", "missing run", ("/nonexistent",))
    add(gn, "run_report_cut", [f"run={p.inputs / 'report_cut'}", *quick, "out=out"], "refused", "cut-off record",
        ("report.json",))
    for name in ("path_wrong_shape.json", "path_huge.json"):
        add(gn, f"path_{name}", [run, *quick, f"path.file={i(name)}", "out=out"], "refused", "path file", (name,))
    add(gn, "path_missing", [run, *quick, "path.file=/nonexistent/path.csv", "out=out"], "refused", "path file",
        ("path.csv",))
    add(gn, "out_exists", [run, *quick, "out=out"], "refused", "out exists", ("out",), setup=_file("out/mine.txt"),
        earlier=("out",), out=())
    add(gn, "force_out_link_to_decoy", [run, *quick, "out=linked", "force=true"], "refused", "out folder links out",
        ("linked",), setup=_link("linked", p.decoy), out=())
    add(gn, "short_path", [run, *quick, f"path.file={i('path_short.json')}", "out=out"], "either", "short walk",
        ("path_short.json", "the path"), timeout=240)
    add(gn, "good", [run, *quick, f"path.file={i('path_good.json')}", "out=out"], "answered", "valid input",
        timeout=240)
    add(gn, "interrupt", [run, *quick, "out=out"], "interrupt", "Ctrl-C mid-run", trigger="hydra",
        interrupt_after=2.0, timeout=240)

    # --- stylemotion-segment ------------------------------------------------------------------------------------
    sg = "stylemotion-segment"
    for override, names in [("timeline=bogus", ["bogus"]), ("plot_takes=-3", ["plot_takes"]),
                            ("sheet_clips=-1", ["sheet_clips"]), ("plot_rejected=abc", ["plot_rejected"]),
                            ("data.fps=0", ["data.fps"])]:
        add(sg, f"value_{override}", [*DATA, override, "out=out"], "refused", "bad Hydra value", names)
    add(sg, "out_below_file", [*DATA, "out=afile/report"], "refused", "out is a file", ("afile",),
        setup=_file("afile"), out=())
    add(sg, "out_exists", [*DATA, "out=out"], "refused", "out exists", ("out",), setup=_file("out/mine.txt"),
        earlier=("out",), out=())
    add(sg, "force_out_link_to_decoy", [*DATA, "out=linked", "force=true"], "refused", "out folder links out",
        ("linked",), setup=_link("linked", p.decoy), out=())
    add(sg, "out_read_only", [*DATA, "out=ro/report"], "refused", "read-only out", ("ro",), setup=_read_only("ro"),
        out=())
    add(sg, "good", [*DATA, "out=out", "plot_takes=0", "plot_rejected=0", "sheet_clips=1"], "answered",
        "valid input", timeout=240)

    # --- stylemotion-search -------------------------------------------------------------------------------------
    se = "stylemotion-search"
    q = f"query={TAKE}:0-30"
    for override, names in [("k=0", ["k"]), ("features=bogus", ["bogus"]), ("k=1e12", ["k"]),
                            ("verify=maybe", ["verify"]), ("steps=gaps", ["verify", "steps=gaps"])]:
        add(se, f"value_{override}", [*DATA, q, override, "out=out"], "refused", "bad Hydra value", names)
    for query, names in [(f"{TAKE}:0-99999", ["99999"]), (f"{i('good.bvh')}:50-10", ["50-10"]),
                         (f"{i('notes.txt')}", ["notes.txt"]),
                         (f"{i('member.zip')}::../walk.bvh", ["../walk.bvh"]),
                         (f"{i('member.zip')}::missing.bvh", ["missing.bvh"])]:
        add(se, f"query_{query.replace(str(p.inputs) + '/', '')}", [*DATA, f"query={query}", "out=out"], "refused",
            "out-of-range cut", names)
    add(se, "out_exists", [*DATA, q, "out=out"], "refused", "out exists", ("out",), setup=_copy(p.earlier / "search",
                                                                                             "out"),
        earlier=("out",), out=())
    add(se, "force_out_link_to_decoy", [*DATA, q, "out=linked", "force=true"], "refused", "out folder links out",
        ("linked",), setup=_link("linked", p.decoy), out=())
    add(se, "out_read_only", [*DATA, q, "out=ro/hits"], "refused", "read-only out", ("ro",),
        setup=_read_only("ro"), out=())
    add(se, "out_below_file", [*DATA, q, "out=afile/hits"], "refused", "out is a file", ("afile",),
        setup=_file("afile"), out=())
    add(se, "good_take", [*DATA, q, "out=out"], "answered", "valid input")
    add(se, "interrupt", [*DATA, f"query={i('long.bvh')}", "out=out"], "interrupt", "Ctrl-C mid-run",
        trigger="hydra", interrupt_after=2.0)

    # --- stylemotion-annotate -----------------------------------------------------------------------------------
    an = "stylemotion-annotate"
    tpl = f"templates={p.earlier / 'templates'}"
    doc = f"document={i('document.bvh')}"

    def damaged_templates(name: str, data: bytes) -> Callable[[Path], None]:
        def setup(folder: Path) -> None:
            _copy(p.earlier / "templates", "tpl")(folder)
            (folder / "tpl" / name).write_bytes(data)
        return setup

    for name, data_ in [("templates.npz", b"PK\x03\x04cut"), ("templates.npz", pickle.dumps({"walk": [1.0]})),
                        ("model.json", b'{"format": 1, "feat'), ("tensors.npz", b"")]:
        add(an, f"damaged_{name}_{len(data_)}", [*DATA, doc, "templates=tpl", "out=out"], "refused",
            "damaged model", (name,), setup=damaged_templates(name, data_), earlier=("tpl",))
    for override, names in [("tau=nan", ["tau"]), ("keyframes.tolerance=5", ["tolerance"])]:
        add(an, f"value_{override}", [*DATA, doc, tpl, "keyframes.use=true", override, "out=out"], "refused",
            "bad Hydra value", names)
    add(an, "templates_missing", [*DATA, doc, "templates=/nonexistent/tpl", "out=out"], "refused", "missing model",
        ("/nonexistent/tpl",))
    add(an, "out_exists", [*DATA, doc, tpl, "out=out"], "refused", "out exists", ("out",),
        setup=_file("out/mine.txt"), earlier=("out",), out=())
    add(an, "learn_into_templates", [*DATA, "per_class=2", "out=tpl"], "refused", "rerun into finished output",
        ("tpl",), setup=_copy(p.earlier / "templates", "tpl"), earlier=("tpl",), out=())

    # --- stylemotion-reconstruct --------------------------------------------------------------------------------
    rc = "stylemotion-reconstruct"
    for name in ("markers.csv", "markers.npz"):
        add(rc, f"file_{name}", [*DATA, f"markers={i(name)}", "out=out", "gif=false"], "answered", "valid input")
    for name in ("markers_nan.csv", "markers_huge.csv", "markers_short_rows.csv", "markers_wrong_shape.npz",
                 "markers_fps_zero.npz", "pickle.npz"):
        # one gap may be filled (named); a marker 1e300 m away may be answered as long as every number is finite
        expect = "either" if name in ("markers_nan.csv", "markers_huge.csv") else "refused"
        add(rc, f"file_{name}", [*DATA, f"markers={i(name)}", "out=out", "gif=false"], expect, "marker file",
            (name,), warn=(name,) if name == "markers_nan.csv" else ())
    for override, names in [(f"markers={TAKE}:a-b", ["a-b"]), ("k=0", ["k"]), ("joints=[Nope]", ["Nope"]),
                            ("noise_mm=nan", ["noise_mm"])]:
        args = [*DATA, override] if override.startswith("markers=") else [*DATA, f"markers={TAKE}:0-60", override]
        add(rc, f"value_{override}", [*args, "out=out", "gif=false"], "refused", "bad Hydra value", names)
    add(rc, "good_take", [*DATA, f"markers={TAKE}:0-60", "out=out", "gif=false"], "answered", "valid input")

    # --- stylemotion-keyframes ----------------------------------------------------------------------------------
    kf = "stylemotion-keyframes"
    for name in ("keys_time_huge", "keys_time_1e9", "keys_time_negative", "keys_frame_out_of_range",
                 "keys_positions_wrong_shape", "keys_positions_nan", "keys_every_zero", "keys_cut", "keys_turn_huge"):
        # key times are relative: a first key at -5 s is an offset, not an error
        add(kf, f"file_{name}", [*DATA, f"keys={i(name + '.json')}", "out=out", "gif=false"],
            "either" if name == "keys_time_negative" else "refused", "keys file",
            (f"{name}.json", *(("every_s",) if "every" in name else ())))
    add(kf, "keys_missing", [*DATA, "keys=/nonexistent/keys.json", "out=out"], "refused", "keys file",
        ("keys.json",))
    add(kf, "keys_fifo", [*DATA, f"keys={i('fifo.bvh')}", "out=out"], "refused", "FIFO", ("fifo.bvh",))
    for override, names in [("model.k=0", ["model.k", "k"]), ("model.voxel_m=0", ["voxel_m"])]:
        add(kf, f"value_{override}", [*DATA, f"keys={i('keys_good.json')}", override, "out=out"], "refused",
            "bad Hydra value", names)
    add(kf, "good", [*DATA, f"keys={i('keys_good.json')}", "out=out", "gif=false"], "either", "valid input",
        ("keys_good.json",), timeout=240)

    # --- stylemotion-texture ------------------------------------------------------------------------------------
    tx = "stylemotion-texture"
    for override, names in [("mode=bogus", ["bogus"]), ("k=0", ["k"]), ("model.weights={pose: nan}", ["pose", "nan"])]:
        add(tx, f"value_{override}", [*DATA, f"motion={TAKE}:0-60", override, "out=out"], "refused",
            "bad Hydra value", names)
    for name in ("markers_nan.npz", "pickled.npz"):
        add(tx, f"file_{name}", [*DATA, f"motion={i(name)}", "out=out"], "refused", "motion file", (name,))
    add(tx, "good_take", [*DATA, f"motion={TAKE}:0-60", "out=out", "gif=false"], "answered", "valid input")

    # --- stylemotion-style --------------------------------------------------------------------------------------
    st = "stylemotion-style"
    ex = f"example={i('good.bvh')}"
    for args, names, kind in [
        ([ex, "run=/nonexistent/run", "name=mine"], ["/nonexistent/run"], "missing run"),
        ([ex, f"run={repro}", "name=normal"], ["normal"], "bad Hydra value"),
        ([ex, f"run={repro}", "name=../x"], ["../x"], "unsafe label"),

        ([f"example={i('good.bvh')}:0-99999", f"run={repro}", "name=mine"], ["99999"], "out-of-range cut"),

    ]:
        add(st, f"{kind.replace(' ', '_')}_{len(cases)}", [*args, "out=out"], "refused", kind, names)
    add(st, "out_exists", [ex, f"run={repro}", "name=mine", "out=out"], "refused", "out exists", ("out",),
        setup=_file("out/mine.txt"), earlier=("out",), out=())

    # --- stylemotion-convert (beyond the BVH kinds) -------------------------------------------------------------
    cv = "stylemotion-convert"
    good_bvh = i("good.bvh")
    for args, names, kind, setup, earlier in [
        ([good_bvh, "out.txt"], ["out.txt"], "bad argument", None, ()),
        ([good_bvh, "out.npz", "--fps", "0"], ["--fps"], "bad argument", None, ()),
        ([good_bvh, "out.npz", "--fps", "nan"], ["--fps"], "bad argument", None, ()),
        ([good_bvh, "out.npz", "--fps", "1e9"], ["--fps", "1e+09", "1000000000"], "bad argument", None, ()),
        ([good_bvh, "out.npz", "--joint-map", "nope"], ["nope"], "bad argument", None, ()),
        ([good_bvh, "out.npz", "--unit-scale", "-1"], ["--unit-scale", "-1"], "bad argument", None, ()),
        ([good_bvh, "missing/deeper/out.npz"], ["out.npz"], "either", None, ()),
        ([good_bvh, "afile/out.npz"], ["afile"], "out is a file", _file("afile"), ()),
        ([good_bvh, "linked.npz"], ["linked.npz"], "out links out", _link("linked.npz", p.decoy / "keep.txt"), ()),
        ([good_bvh, "ro/out.npz"], ["ro"], "read-only out", _read_only("ro"), ()),
        ([f"{i('member.zip')}::../walk.bvh", "out.npz"], ["../walk.bvh"], "zip with ../ member", None, ()),
        ([f"{i('bomb.zip')}::walk.bvh", "out.npz"], ["walk.bvh", "bomb.zip"], "zip bomb", None, ()),
        ([f"{i('junk.zip')}::walk.bvh", "out.npz"], ["junk.zip"], "truncated zip", None, ()),
    ]:
        expect = "either" if kind == "either" else "refused"
        add(cv, f"{kind.replace(' ', '_')}_{len(cases)}", args, expect, kind, names, setup=setup, earlier=earlier,
            out=("out.npz", "missing"))
    add(cv, "dst_exists", [good_bvh, "mine.npz"], "either", "out exists", ("mine.npz",),
        setup=_file("mine.npz", "my own file\n"), earlier=("mine.npz",), out=())
    add(cv, "zip_member", [f"{i('member.zip')}::walk.bvh", "out.npz"], "answered", "valid input", out=("out.npz",))
    add(cv, "interrupt", [i("long.bvh"), "out.npz"], "interrupt", "Ctrl-C mid-run", out=("out.npz",),
        interrupt_after=2.5)

    # --- stylemotion-view (beyond the BVH kinds) ----------------------------------------------------------------
    vw = "stylemotion-view"
    for extra, names in [(["--spacing", "nan"], ["--spacing"]), (["--spacing", "1e308"], ["--spacing"]),
                         (["--fps", "0"], ["--fps"]), (["--max-samples", "0"], ["--max-samples"])]:
        add(vw, f"value_{'_'.join(extra)}", [good_bvh, "--out", "out", *extra], "refused", "bad argument", names)
    for name in ("pickled.npz", "pickle.npz", "markers_wrong_shape.npz", "markers_nan.npz"):
        add(vw, f"file_{name}", [i(name), "--out", "out"], "refused", "motion file", (name,))
    add(vw, "run_folder", [str(repro), "--out", "out"], "either", "run folder", (str(repro),))
    add(vw, "missing", ["/nonexistent/walk.bvh", "--out", "out"], "refused", "missing file", ("walk.bvh",))
    add(vw, "out_exists", [good_bvh, "--out", "out"], "refused", "out exists", ("out",), setup=_file("out/mine.txt"),
        earlier=("out",), out=())
    add(vw, "force_out_link_to_decoy", [good_bvh, "--out", "linked", "--force"], "refused", "out folder links out",
        ("linked",), setup=_link("linked", p.decoy), out=())
    add(vw, "out_is_file", [good_bvh, "--out", "afile"], "refused", "out is a file", ("afile",),
        setup=_file("afile"), earlier=("afile",), out=())
    add(vw, "interrupt", [i("long.bvh"), "--out", "out"], "interrupt", "Ctrl-C mid-run", interrupt_after=2.5)

    ids = Counter(c.id for c in cases)
    assert not [k for k, n in ids.items() if n > 1], [k for k, n in ids.items() if n > 1]
    return cases


def _tiny_repro_overrides(repro: Path) -> list[str]:
    sys.path.insert(0, str(ROOT / "tests"))
    from reproduce_fixtures import tiny_overrides

    return tiny_overrides(repro)


# ----------------------------------------------------------------------------------------------------------------
# Running and classifying


def snapshot(folder: Path, skip: Sequence[Path] = ()) -> dict[str, tuple]:
    """Every entry under ``folder`` (links not followed): kind, size, mtime, inode, link target; folders by kind
    only (their mtime changes whenever an entry is added)."""
    skipped = {str(s) for s in skip}
    entries: dict[str, tuple] = {}
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames[:] = [d for d in dirnames if os.path.join(dirpath, d) not in skipped]
        for name in dirnames + filenames:
            path = os.path.join(dirpath, name)
            try:
                st = os.lstat(path)
            except OSError:
                continue
            kind = stat.S_IFMT(st.st_mode)
            if stat.S_ISDIR(kind):
                entries[os.path.relpath(path, folder)] = ("dir",)
            elif stat.S_ISLNK(kind):
                entries[os.path.relpath(path, folder)] = ("link", os.readlink(path))
            else:
                entries[os.path.relpath(path, folder)] = (kind, st.st_size, st.st_mtime_ns, st.st_ino)
    return entries


def changes(before: Mapping[str, tuple], after: Mapping[str, tuple]) -> list[str]:
    """Paths added, removed or changed between two snapshots."""
    return sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k))


def _under(path: str, prefix: str) -> bool:
    return path == prefix or path.startswith(prefix.rstrip("/") + "/")


def _temporary_sibling(path: str, allowed: Sequence[str]) -> bool:
    """A temporary name the atomic writers give an output (``.<name>.xyz`` or ``.<name>.xyz.tmp``)."""
    head, _, name = path.rpartition("/")
    for out in allowed:
        o_head, _, o_name = out.rpartition("/")
        if head == o_head and name.startswith(f".{o_name}."):
            return True
    return False


def sort_changes(changed: Sequence[str], allowed: Sequence[str], earlier: Sequence[str]) -> dict[str, list[str]]:
    """Changed paths (relative to the root) split into ``earlier`` (in a finished result), ``outside`` (outside
    the allowed outputs) and ``leftover`` (a temporary output name still there afterwards)."""
    sorted_: dict[str, list[str]] = {"earlier": [], "outside": [], "leftover": []}
    for path in changed:
        if any(_under(path, e) for e in earlier):
            sorted_["earlier"].append(path)
        elif _temporary_sibling(path, allowed) or path.rpartition("/")[2].endswith(".tmp"):
            sorted_["leftover"].append(path)
        elif any(_under(path, a) for a in allowed):
            continue
        else:
            sorted_["outside"].append(path)
    return sorted_


def _json_has_nonfinite(text: str) -> bool:
    bad: list[str] = []
    json.loads(text, parse_constant=lambda token: bad.append(token) or 0.0)
    return bool(bad)


def check_outputs(folder: Path, outs: Sequence[str]) -> str | None:
    """An answer's generic check: its outputs exist, JSON holds no NaN/Infinity, NPZ float arrays and BVH numbers
    are finite. A problem in words, or None."""
    import numpy as np

    files = []
    for out in outs:
        path = folder / out
        if path.is_file():
            files.append(path)
        elif path.is_dir():
            files.extend(f for f in path.rglob("*") if f.is_file() and not f.is_symlink())
    if not files:
        return f"no output in {', '.join(outs)}"
    for f in files:
        try:
            if f.suffix == ".json":
                if _json_has_nonfinite(f.read_text()):
                    return f"{f.relative_to(folder)} holds NaN or Infinity"
            elif f.suffix == ".npz":
                with np.load(f, allow_pickle=False) as arrays:
                    for key in arrays.files:
                        a = arrays[key]
                        if a.dtype.kind == "f" and not np.isfinite(a).all():
                            return f"{f.relative_to(folder)}[{key}] holds NaN or inf"
            elif f.suffix in (".bvh", ".csv") and f.stat().st_size < 50 * 2**20:
                if re.search(r"(?i)(?<![a-z])(nan|inf)(?![a-z])", f.read_text(errors="replace")):
                    return f"{f.relative_to(folder)} holds nan or inf"
            elif f.name == "index.html" and re.search(r"\bNaN\b|\bInfinity\b", f.read_text(errors="replace")):
                return f"{f.relative_to(folder)} holds NaN"
        except (OSError, ValueError) as exc:
            return f"{f.relative_to(folder)} is not readable: {exc}"
    return None


TRACEBACK = "Traceback (most recent call last)"
MEMORY = ("MemoryError", "Unable to allocate", "Cannot allocate memory", "std::bad_alloc")


def message_line(command: str, stderr: str) -> str:
    """The line a refusal ends in: the last line starting with ``<command>:``, else the last non-empty line."""
    lines = [ln for ln in stderr.splitlines() if ln.strip()]
    ours = [ln for ln in lines if ln.startswith(f"{command}:")]
    return (ours or lines or [""])[-1]


def classify(case: Case | Mapping[str, Any], result: Mapping[str, Any]) -> tuple[str, str]:
    """One outcome of :data:`OUTCOMES` and a note, from what a case expected and what happened.

    ``result``: ``returncode``, ``stderr``, ``timed_out``, ``peak_rss_kb``, ``earlier`` / ``outside`` /
    ``leftover`` (changed paths), ``problem`` (an answer's failed check, or None), ``signalled`` (Ctrl-C sent
    while the command ran). The worst finding wins: hang, unbounded, traceback, touched-earlier, wrote-outside,
    then the exit status and message.
    """
    get = case.get if isinstance(case, Mapping) else lambda k, d=None: getattr(case, k, d)
    command, expect, names = get("command"), get("expect"), tuple(get("names", ()) or ())
    warn = tuple(get("warn", ()) or ())
    rc, stderr = result.get("returncode"), result.get("stderr") or ""
    line = message_line(command, stderr)
    if result.get("timed_out"):
        return "hang", f"no exit within {result.get('timeout', '?')} s"
    if any(m in stderr for m in MEMORY) or (result.get("peak_rss_kb") or 0) > RSS_BOUND_KB:
        return "unbounded", f"peak {result.get('peak_rss_kb', 0) / 1e6:.1f} GB" + (
            "; allocation failed" if any(m in stderr for m in MEMORY) else "")
    if TRACEBACK in stderr:
        last = [ln for ln in stderr.splitlines() if ln.strip()][-1:] or [""]
        return "traceback", last[0][:160]
    if result.get("earlier"):
        return "touched-earlier", ", ".join(result["earlier"][:3])
    if result.get("outside"):
        return "wrote-outside", ", ".join(result["outside"][:3])
    if result.get("leftover"):
        return "silent-wrong", "left half-written: " + ", ".join(result["leftover"][:3])
    if expect == "interrupt":
        if result.get("finished_before_signal"):
            return "correct", "finished before Ctrl-C could stop it"
        if rc == 0 and not result.get("signalled"):
            return ("silent-wrong", result["problem"]) if result.get("problem") else (
                "correct", "finished before Ctrl-C could be sent")
        if result.get("problem"):
            return "silent-wrong", result["problem"]
        one = line.startswith(f"{command}:") and "interrupted" in line
        return ("clear", "") if rc == 130 and one else ("unclear", f"exit {rc}: {line[:160]}")
    if rc == 0:
        if expect == "refused":
            return "silent-wrong", "exit 0 on input that must be refused"
        if result.get("problem"):
            return "silent-wrong", result["problem"]
        if warn and not any(w in stderr or w in (result.get("stdout") or "") for w in warn):
            return "silent-wrong", f"answered without naming {warn[0]} in a warning"
        return "correct", ""
    prefix = line.startswith(f"{command}:")
    named = any(n in line for n in names) if names else True
    clear = prefix and named and sum(ln.startswith(f"{command}:") for ln in stderr.splitlines()) == 1
    if expect == "answered":
        return ("refused-valid" if clear else "unclear"), f"exit {rc}: {line[:160]}"
    if clear:
        return "clear", ""
    why = "no command prefix" if not prefix else ("names none of " + ", ".join(names[:3]) if not named
                                                  else "more than one error line")
    return "unclear", f"{why}: {line[:160]}"


def run_case(case: Case, root: Path, cache: Path, logs: Path) -> dict[str, Any]:
    """Run one case as a subprocess in ``root/cases/<id>``; its result record (:func:`classify`'s input)."""
    folder = root / "cases" / case.id
    folder.mkdir(parents=True)
    if case.setup is not None:
        case.setup(folder)
    env = _environment(cache)
    if case.own_cache:
        env["STYLEMOTION_CACHE"] = str(folder / "cache")
    rel = os.path.relpath(folder, root)
    skip = [cache, logs]
    before = snapshot(root, skip)
    stdout_path, stderr_path = logs / f"{case.id.replace('/', '_')}.out", logs / f"{case.id.replace('/', '_')}.err"

    def limits() -> None:
        # a suite started in the background (nohup, &) ignores Ctrl-C, and its children would inherit that
        signal.signal(signal.SIGINT, signal.SIG_DFL)
        resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_LIMIT, ADDRESS_LIMIT))
        os.nice(5)

    import subprocess

    start = time.monotonic()
    with open(stdout_path, "wb") as out, open(stderr_path, "wb") as err:
        proc = subprocess.Popen(case.argv(), cwd=folder, stdin=subprocess.DEVNULL, stdout=out, stderr=err, env=env,
                                start_new_session=True, preexec_fn=limits)
    timed_out = signalled = False
    signalled_at = 0.0
    trigger_seen: float | None = None if case.trigger else start
    status, usage = None, None
    while status is None:
        pid, status_, usage_ = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            status, usage = status_, usage_
            break
        now = time.monotonic()
        if case.interrupt_after is not None and not signalled:
            if trigger_seen is None and (folder / case.trigger).exists():
                trigger_seen = now
            if trigger_seen is not None and now - trigger_seen >= case.interrupt_after:
                _signal_group(proc.pid, signal.SIGINT)
                signalled, signalled_at = True, time.time()
        if now - start > case.timeout:
            timed_out = True
            _signal_group(proc.pid, signal.SIGKILL)
            _, status, usage = os.wait4(proc.pid, 0)
            break
        time.sleep(0.05)
    seconds = time.monotonic() - start
    _signal_group(proc.pid, signal.SIGKILL)  # workers a command left behind
    _unlock(folder)
    proc.returncode = os.waitstatus_to_exitcode(status)
    after = snapshot(root, skip)
    allowed = [f"{rel}/{o}" for o in (*case.out, "hydra") if o]
    earlier = [f"{rel}/{e}" for e in case.earlier] + ["earlier"]
    sorted_ = sort_changes(changes(before, after), allowed, earlier)
    stderr = stderr_path.read_text(errors="replace")
    stdout = stdout_path.read_text(errors="replace")
    problem = None
    if proc.returncode == 0 and case.expect in ("answered", "either", "interrupt") and case.out:
        problem = check_outputs(folder, case.out)
        if problem is None and case.check is not None:
            problem = case.check(folder)
    finished_first = False
    if case.expect == "interrupt" and proc.returncode != 0 and case.command not in RESUMABLE:
        left = [o for o in case.out if o not in ("hydra", "cache") and (folder / o).exists()]
        late = [o for o in left if _newest_mtime(folder / o) >= signalled_at]
        if late:
            problem = f"left {', '.join(late)} after Ctrl-C"
        finished_first = bool(left) and not late  # complete before the signal came
    result_extra = {"finished_before_signal": finished_first}
    result = {"returncode": proc.returncode, "stderr": stderr, "stdout": stdout[-2000:], "timed_out": timed_out,
              "timeout": case.timeout, "peak_rss_kb": usage.ru_maxrss if usage else None, "signalled": signalled,
              "problem": problem, **sorted_, **result_extra}
    outcome, note = classify(case, result)
    return {"id": case.id, "command": case.command,
            "argv": shlex.join(a.replace(str(root), "$ROOT") for a in case.argv()),
            "kind": case.kind, "expected": case.expect, "outcome": outcome, "note": note,
            "returncode": proc.returncode, "message": message_line(case.command, stderr)[:300].replace(
                str(root), "$ROOT"),
            "seconds": round(seconds, 2), "peak_rss_mb": round((usage.ru_maxrss if usage else 0) / 1024, 1),
            "changed_outside": sorted_["outside"][:10], "changed_earlier": sorted_["earlier"][:10]}


def _newest_mtime(path: Path) -> float:
    """The latest modification time (s since the epoch) of ``path`` or any file below it."""
    times = [path.lstat().st_mtime] + [p.lstat().st_mtime for p in path.rglob("*")] if path.is_dir() else [
        path.lstat().st_mtime]
    return max(times)


def _signal_group(pid: int, sig: int) -> None:
    try:
        os.killpg(pid, sig)
    except (ProcessLookupError, PermissionError):
        pass


# ----------------------------------------------------------------------------------------------------------------
# The suite's contract


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--only", default=None, help="run only cases whose id matches this regular expression")
    parser.add_argument("--keep", action="store_true", help="keep the temporary root and the logs (printed)")
    parser.add_argument("--root", default=None,
                        help="(development) an existing root whose inputs and tiny runs are reused; kept")
    parser.add_argument("--list-cases", action="store_true", help="print the case ids and stop")


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    reuse = getattr(args, "root", None)
    root = Path(reuse).resolve() if reuse else Path(tempfile.mkdtemp(prefix="stylemotion_bad_input_"))
    root.mkdir(parents=True, exist_ok=True)
    root.chmod(0o755)
    paths = Inputs(root)
    cache, logs = root / "cache", Path(tempfile.mkdtemp(prefix="stylemotion_bad_input_logs_"))
    keep = bool(getattr(args, "keep", False) or reuse)
    say = lambda line: print(f"[bad_input] {line}", file=sys.stderr, flush=True)  # noqa: E731
    try:
        cases = build_cases(paths)
        if getattr(args, "only", None):
            cases = [c for c in cases if re.search(args.only, c.id)]
        if getattr(args, "list_cases", False):
            print("\n".join(f"{c.id}  {c.expect}" for c in cases))
            return {"splits": {"kind": "none"}, "cases": []}
        made = make_inputs(paths, seeds[0] if seeds else 0, say)
        if (root / "cases").exists():
            _make_removable(root / "cases")
            shutil.rmtree(root / "cases")
        (root / "cases").mkdir()
        records = []
        for n, case in enumerate(cases, 1):
            record = run_case(case, root, cache, logs)
            records.append(record)
            say(f"{n}/{len(cases)} {case.id}: {record['outcome']} ({record['seconds']} s) {record['note'][:100]}")
            if not keep:
                _make_removable(root / "cases" / case.id)
                shutil.rmtree(root / "cases" / case.id, ignore_errors=True)
    finally:
        if keep:
            say(f"kept {root} and {logs}")
        else:
            for folder in (root, logs):
                _make_removable(folder)
                shutil.rmtree(folder, ignore_errors=True)
    return summarize(records, made)


def _make_removable(folder: Path) -> None:
    for dirpath, dirnames, _ in os.walk(folder):
        for name in dirnames:
            p = Path(dirpath) / name
            if not p.is_symlink():
                p.chmod(0o755)


def summarize(records: Sequence[Mapping[str, Any]], made: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Totals per outcome and per command beside the cases."""
    totals = Counter(r["outcome"] for r in records)
    by_command = {c: dict(Counter(r["outcome"] for r in records if r["command"] == c)) for c in COMMANDS}
    return {"splits": {"kind": "none: no data split; every case runs on inputs the suite generates (synthetic "
                                "motion, broken files) or on one tiny synthetic run trained for it"},
            "rss_bound_mb": RSS_BOUND_KB // 1000, "outcomes": list(OUTCOMES), "aim_zero": list(AIM_ZERO),
            "totals": {o: totals.get(o, 0) for o in OUTCOMES}, "cases_run": len(records),
            "by_command": by_command, "inputs": dict(made or {}), "cases": list(records)}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    totals, n = r["totals"], r["cases_run"]
    missed = {o: totals[o] for o in r["aim_zero"] if totals.get(o)}
    headline = md_table(["outcome", "cases"], [[o, str(totals.get(o, 0))] for o in r["outcomes"]])
    aim = ("every aim met: " if not missed else "aim missed: ") + ", ".join(
        f"{totals.get(o, 0)} {o}" for o in r["aim_zero"])
    headline = (f"{n} cases over {sum(1 for c in r['by_command'].values() if c)} commands. {aim}.\n\n{headline}\n\n"
                f"{provenance_line(record)}")
    by_command = md_table(["command", "cases", *r["outcomes"]],
                          [[c, str(sum(v.values())), *[str(v.get(o, 0) or "") for o in r["outcomes"]]]
                           for c, v in r["by_command"].items()])
    rows = [[c["id"], f"`{c['argv']}`", c["expected"], c["outcome"] + (f": {c['note']}" if c["note"] else ""),
             c["message"][:140], f"{c['seconds']:.1f}"] for c in r["cases"]]
    cases = md_table(["case", "command line", "expected", "outcome", "stderr line", "s"], rows)
    return {"headline": headline, "by_command": f"{by_command}\n\n{provenance_line(record)}",
            "cases": f"{cases}\n\n{provenance_line(record)}"}
