"""What produced a result: the commit (``+dirty`` with uncommitted changes to tracked files, ``unknown`` without
git), the load averages, and the JSON-ready record every command writes."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import torch

import stylemotion
from stylemotion import provenance as provenance_module
from stylemotion.provenance import git_commit, load_average, provenance


def git(folder: Path, *args: str) -> str:
    env = {**os.environ, "GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t", "GIT_COMMITTER_NAME": "t",
           "GIT_COMMITTER_EMAIL": "t@t", "GIT_CONFIG_GLOBAL": os.devnull, "GIT_CONFIG_NOSYSTEM": "1"}
    return subprocess.run(["git", *args], cwd=folder, env=env, capture_output=True, text=True, check=True).stdout


@pytest.fixture
def repo(tmp_path: Path) -> Path:
    git(tmp_path, "init", "-q")
    (tmp_path / "code.py").write_text("x = 1\n")
    git(tmp_path, "add", "code.py")
    git(tmp_path, "commit", "-q", "-m", "first")
    return tmp_path


def test_the_commit_of_a_clean_tree_is_head(repo: Path) -> None:
    head = git(repo, "rev-parse", "HEAD").strip()
    assert len(head) == 40 and git_commit(repo) == head


def test_untracked_files_do_not_make_a_tree_dirty_but_changed_tracked_files_do(repo: Path) -> None:
    head = git(repo, "rev-parse", "HEAD").strip()
    (repo / "notes.txt").write_text("scratch")
    assert git_commit(repo) == head
    (repo / "code.py").write_text("x = 2\n")
    assert git_commit(repo) == head + "+dirty"


def test_no_repository_or_no_git_is_unknown(tmp_path: Path, monkeypatch) -> None:
    plain = tmp_path / "not_a_repo"
    plain.mkdir()
    monkeypatch.setenv("GIT_CEILING_DIRECTORIES", str(tmp_path))  # git must not find a repository above
    assert git_commit(plain) == "unknown"
    assert git_commit(tmp_path / "missing") == "unknown"  # cwd does not exist: OSError
    monkeypatch.setenv("PATH", str(tmp_path))  # no git executable
    assert git_commit(plain) == "unknown"


def test_load_average_is_three_rounded_numbers_or_none(monkeypatch) -> None:
    values = load_average()
    assert isinstance(values, list) and len(values) == 3
    assert all(isinstance(v, float) and v >= 0 and round(v, 2) == v for v in values)
    monkeypatch.setattr(provenance_module.os, "getloadavg", lambda: (1.23456, 0.5, 0.0))
    assert load_average() == [1.23, 0.5, 0.0]

    def unavailable():
        raise OSError("no load average here")

    monkeypatch.setattr(provenance_module.os, "getloadavg", unavailable)
    assert load_average() is None


def test_the_record_names_version_commit_command_and_machine(monkeypatch) -> None:
    monkeypatch.setattr(provenance_module, "git_commit", lambda: "abc123+dirty")
    record = provenance("stylemotion-train experiment=smoke")
    assert record["stylemotion_version"] == stylemotion.__version__ and record["git_commit"] == "abc123+dirty"
    assert record["command"] == "stylemotion-train experiment=smoke"
    assert record["python"] == ".".join(map(str, sys.version_info[:3])) and record["torch"] == torch.__version__
    assert record["torch_threads"] == torch.get_num_threads()
    assert json.loads(json.dumps(record, allow_nan=False)) == record  # JSON-ready as it is


def test_without_a_command_the_record_takes_the_command_line(monkeypatch) -> None:
    monkeypatch.setattr(provenance_module, "git_commit", lambda: "abc123")
    monkeypatch.setattr(sys, "argv", ["/usr/local/bin/stylemotion-eval", "checkpoints=[a,b]", "threads=2"])
    assert provenance()["command"] == "stylemotion-eval checkpoints=[a,b] threads=2"


def test_this_checkout_records_its_own_commit() -> None:
    commit = provenance_module.git_commit()
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=provenance_module.SOURCE_ROOT, capture_output=True,
                          text=True).stdout.strip()
    assert commit.removesuffix("+dirty") == head and len(head) == 40
