"""Every command says what it is and what it did, and turns a bad value into one line naming it.

``--help`` of each Hydra command (description, main keys, examples); ``stylemotion-data`` writes its
summary to ``prepare.log``; ``threads=abc|0|-1`` (eval, generate), ``stylemotion-convert --fps 0|nan|inf|-5``
and convert outputs that are a folder or not ``.npz`` end in ``stylemotion-<command>: …`` without a
traceback. The commands' entry functions run in-process (:func:`cli_runner.run_command`); one subprocess per
family checks that the installed console scripts start (a Hydra command's ``--help``, convert's one-line error).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from cli_runner import Done, run_command

from stylemotion.cli.convert import main as convert_main

COMMANDS = {  # module → (console script, a phrase of its description, a key of its main keys)
    "train": ("stylemotion-train", "fit a model", "ckpt_path=last|auto"),
    "evaluate": ("stylemotion-eval", "evaluate trained primitive models", "checkpoints=[...]"),
    "generate": ("stylemotion-generate", "synthesize a walk along a ground path", "path.file="),
    "segment": ("stylemotion-segment", "segment walks and runs into motion primitives", "timeline="),
    "prepare": ("stylemotion-data", "build a dataset", "data.skip_broken=true"),
    "reproduce": ("stylemotion-reproduce", "resumable command", "workers=N"),
    "style": ("stylemotion-style", "add a new style to a finished stylemotion-reproduce run", "example=<BVH>"),
    "search": ("stylemotion-search", "find the segments of a motion database most similar", "query=<BVH>"),
    "reconstruct": ("stylemotion-reconstruct", "reconstruct full 21-joint poses from a few marker tracks",
                    "markers=<BVH[:start-end]|NPZ|CSV|C3D|take>"),
    "texture": ("stylemotion-texture", "complete or texture a motion with a motion database",
                "motion=<BVH[:start-end]|NPZ|take>"),
    "keyframes": ("stylemotion-keyframes", "a motion through a few keyframes", "keys=<keys.json>"),
}


def command(module: str, *args: str, cwd: Path, timeout: float = 120) -> subprocess.CompletedProcess:
    env = {**os.environ, "HYDRA_FULL_ERROR": "0", "PYTHONWARNINGS": "ignore"}
    return subprocess.run([sys.executable, "-m", f"stylemotion.cli.{module}", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)


def one_line_error(done: subprocess.CompletedProcess | Done, script: str) -> str:
    """The message of a command that refused its input: exit status 2, one line, no traceback."""
    assert done.returncode == 2, done.stdout[-2000:] + done.stderr[-2000:]
    assert "Traceback" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"{script}: "), done.stderr
    return lines[0]


@pytest.mark.parametrize("module", COMMANDS)
def test_help_describes_the_command_its_keys_and_examples(module: str, tmp_path: Path, capsys, monkeypatch) -> None:
    script, phrase, key = COMMANDS[module]
    done = run_command(module, "--help", cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    assert done.returncode == 0, done.stderr[-2000:]
    text = done.stdout
    assert text.startswith(f"{script}: ") and phrase in text
    assert "== Main keys ==" in text and key in text
    assert "== Examples ==" in text and f"\n  {script}" in text
    assert "is powered by Hydra" not in text  # not Hydra's generic help
    assert not list(tmp_path.iterdir())  # --help runs nothing


def test_an_installed_hydra_console_script_starts_and_prints_its_help(tmp_path: Path) -> None:
    """The one subprocess of the Hydra commands: the script pip installed, not ``python -m``."""
    script = Path(sys.executable).parent / "stylemotion-search"
    done = subprocess.run([str(script), "--help"], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          env={**os.environ, "PYTHONWARNINGS": "ignore"})
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("stylemotion-search: ") and "== Main keys ==" in done.stdout
    assert not list(tmp_path.iterdir())


def test_data_command_logs_its_summary_to_the_run_folder(tmp_path: Path, capsys, monkeypatch) -> None:
    out = tmp_path / "run"
    done = run_command("prepare", "data.takes_per_pair=3", "data.duration_s=2.0", "data.contents=[walk]",
                       "data.styles=[normal]", f"hydra.run.dir={out}", cwd=tmp_path, capsys=capsys,
                       monkeypatch=monkeypatch)
    assert done.returncode == 0, done.stderr[-2000:]
    log = (out / "prepare.log").read_text()
    assert "summary written to" in log and "walk" in log and "[INFO]" in log
    assert "summary written to" in done.stdout and "[INFO]" not in done.stdout  # plain on the console


@pytest.mark.parametrize("module, threads", [("evaluate", "abc"), ("generate", "0"), ("generate", "-1")])
def test_bad_threads_is_one_line_naming_the_key(module: str, threads: str, tmp_path: Path, capsys,
                                               monkeypatch) -> None:
    script = COMMANDS[module][0]
    extra = ["checkpoints=[nothing]"] if module == "evaluate" else []
    done = run_command(module, f"threads={threads}", f"out={tmp_path / 'out'}", *extra,
                       f"hydra.run.dir={tmp_path / 'hydra'}", cwd=tmp_path, capsys=capsys, monkeypatch=monkeypatch)
    value = threads if threads == "abc" else int(threads)  # as Hydra parses it
    assert one_line_error(done, script) == f"{script}: threads must be a whole number ≥ 1, got {value!r}"
    assert not (tmp_path / "out").exists()


def convert(capsys: pytest.CaptureFixture, *args: str) -> str:
    """``stylemotion-convert args`` in-process; the one line it wrote to stderr (it must exit 2)."""
    assert convert_main(list(args)) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("stylemotion-convert: "), err
    return err[0]


@pytest.mark.parametrize("fps", ["0", "nan", "inf", "-5"])
def test_convert_refuses_a_bad_frame_rate(fps: str, tmp_path: Path, capsys) -> None:
    message = convert(capsys, "missing.bvh", str(tmp_path / "x.npz"), f"--fps={fps}")
    assert "--fps must be a positive finite frame rate" in message and fps.lstrip("-") in message
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("dst, reason", [(".", "is a folder"), ("x.fbx", "unknown extension '.fbx'"),
                                         ("x", "unknown extension '(none)'"), ("x.bvh", "unknown extension '.bvh'")])
def test_convert_refuses_an_output_that_is_not_an_npz_file(dst: str, reason: str, tmp_path: Path, capsys,
                                                           monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    message = convert(capsys, "missing.bvh", dst)
    assert reason in message and "npz" in message
    assert not list(tmp_path.iterdir())


def test_convert_names_a_missing_source(tmp_path: Path, capsys) -> None:
    assert "missing.bvh" in convert(capsys, str(tmp_path / "missing.bvh"), str(tmp_path / "x.npz"))
    assert not list(tmp_path.iterdir())


def test_convert_console_script_exits_with_one_line(tmp_path: Path) -> None:
    done = command("convert", "missing.bvh", str(tmp_path / "x.fbx"), cwd=tmp_path)
    assert "unknown extension '.fbx'" in one_line_error(done, "stylemotion-convert")
