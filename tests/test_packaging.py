"""The built wheel works on its own: configs inside the package, commands run outside the repository.

A wheel is built from this checkout and installed (without dependencies) into a fresh virtual
environment; the dependencies are borrowed from the test's environment through a ``.pth`` line, so
no download is needed. The environment's editable install of stylemotion is not visible there
(``.pth`` files of a borrowed folder are not processed), so the commands run the wheel's code.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest
from conftest import REPO_ROOT


def _run(args: list[str], cwd: Path, env: dict[str, str], timeout: int = 600) -> subprocess.CompletedProcess:
    proc = subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert proc.returncode == 0, f"{args[:3]} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-4000:]}"
    return proc


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    # built from a copy of the source tree: setuptools writes build/ and *.egg-info beside the sources
    source = tmp_path_factory.mktemp("source") / "stylemotion"
    shutil.copytree(REPO_ROOT, source, ignore=shutil.ignore_patterns(
        ".git", ".venv", "runs", "reports", ".cache", "build", "dist", "*.egg-info", "__pycache__", "notebooks"))
    dist = tmp_path_factory.mktemp("dist")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--wheel-dir", str(dist),
          str(source)], dist, env)
    (found,) = dist.glob("stylemotion-*.whl")
    return found


def test_wheel_ships_the_configs_and_joint_maps(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    for required in ("stylemotion/configs/train.yaml", "stylemotion/configs/reproduce.yaml",
                     "stylemotion/configs/experiment/smoke.yaml", "stylemotion/configs/data/synthetic.yaml",
                     "stylemotion/configs/budget/synthetic.yaml", "stylemotion/configs/hydra/launcher/slurm.yaml",
                     "stylemotion/joint_maps/bandai.yaml"):
        assert required in names, f"{required} missing from {wheel.name}"
    shipped = {n for n in names if n.startswith("stylemotion/configs/") and n.endswith(".yaml")}
    in_tree = {p.relative_to(REPO_ROOT).as_posix() for p in (REPO_ROOT / "stylemotion" / "configs").rglob("*.yaml")}
    assert shipped == in_tree


@pytest.mark.slow
def test_train_smoke_from_the_installed_wheel_outside_the_repo(wheel, tmp_path):
    venv = tmp_path / "venv"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    _run([sys.executable, "-m", "venv", str(venv)], tmp_path, env)
    python = venv / "bin" / "python"
    _run([str(python), "-m", "pip", "install", "--no-deps", "--no-index", "--quiet", str(wheel)], tmp_path, env)
    site = Path(subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               capture_output=True, text=True, check=True).stdout.strip())
    (site / "borrowed_dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    work = tmp_path / "elsewhere"
    work.mkdir()
    env["STYLEMOTION_CACHE"] = str(tmp_path / "cache")

    where = _run([str(python), "-c", "import stylemotion; print(stylemotion.__file__)"], work, env).stdout.strip()
    assert Path(where).resolve().is_relative_to(venv.resolve()), where

    run_dir = work / "run"
    _run([str(venv / "bin" / "stylemotion-train"), "experiment=smoke", f"hydra.run.dir={run_dir}"], work, env)
    assert (run_dir / "checkpoints" / "last.ckpt").is_file()
    assert (run_dir / "metrics.json").is_file()
