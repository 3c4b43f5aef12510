"""Config errors Hydra reports itself (issue 26): an unknown key, an unknown config group option, an override its
grammar refuses and a missing mandatory value end in one line naming it, exit status 2, no traceback — not in
Hydra's several lines and exit status 1. ``HYDRA_FULL_ERROR=1`` still shows Hydra's own error."""

from __future__ import annotations

import pytest
from cli_runner import run_command

from stylemotion.cli.skeleton import hydra_message


@pytest.mark.parametrize("module, override, message", [
    ("prepare", "data.nope=1", "Could not override 'data.nope'. To append to your config use +data.nope=1 — "
                               "Key 'nope' is not in struct"),
    ("train", "experiment=nope", "In 'train': Could not find 'experiment/nope' Available options in 'experiment': "
                                 "autoencoder, "),
    ("search", "query=[1,2", "no viable alternative at input '[1,2'"),
    ("search", "out=x", "missing mandatory value: query"),
])
def test_hydra_config_errors_end_in_one_line(module, override, message, tmp_path, capsys, monkeypatch):
    done = run_command(module, override, "hydra.run.dir=hydra", capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-") and message in line, line
    assert "HYDRA_FULL_ERROR" not in line and "provider=" not in line


def test_hydra_full_error_still_shows_hydras_error(tmp_path, capsys, monkeypatch):
    from hydra.errors import MissingConfigException

    monkeypatch.setenv("HYDRA_FULL_ERROR", "1")
    from stylemotion.cli.train import main

    monkeypatch.setattr("sys.argv", ["stylemotion-train", "experiment=nope", "hydra.run.dir=hydra"])
    monkeypatch.chdir(tmp_path)
    try:
        with pytest.raises(MissingConfigException):
            main()
    finally:
        from hydra.core.global_hydra import GlobalHydra

        GlobalHydra.instance().clear()


def test_a_several_line_message_becomes_one():
    class Composed(Exception):
        pass

    error = Composed("Could not find 'x'\n\nAvailable options in 'g':\n\ta\n\tb\nConfig search path:\n\tprovider=p")
    error.__cause__ = ValueError("Key 'x'\n    full_key: g.x")
    assert hydra_message(error) == "Could not find 'x' Available options in 'g': a, b — Key 'x' full_key: g.x"


@pytest.mark.parametrize("run_dir, message", [
    ("afile", "hydra.run.dir: cannot write afile (File exists); choose another hydra.run.dir"),
    ("afile/run", "hydra.run.dir: cannot write afile/run (Not a directory)"),
    ("linked", "hydra.run.dir=linked: linked is a link to "),
])
def test_a_run_folder_hydra_cannot_make_or_that_links_out_is_one_line(run_dir, message, tmp_path, capsys,
                                                                       monkeypatch):
    (tmp_path / "afile").write_text("mine")
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "linked").symlink_to(tmp_path / "elsewhere", target_is_directory=True)
    done = run_command("prepare", f"hydra.run.dir={run_dir}", capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-data: ") and message in line, line
    assert (tmp_path / "afile").read_text() == "mine" and not any((tmp_path / "elsewhere").iterdir())


@pytest.mark.parametrize("module, args", [("reproduce", ["data.takes_per_pair=2"]),
                                          ("segment", ["data.takes_per_pair=1", "force=true"])])
def test_an_out_that_is_a_link_is_refused_before_anything_is_written(module, args, tmp_path, capsys, monkeypatch):
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "linked").symlink_to(tmp_path / "elsewhere", target_is_directory=True)
    done = run_command(module, *args, "out=linked", "hydra.run.dir=hydra", capsys=capsys, monkeypatch=monkeypatch,
                       cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    line = done.stderr.strip().splitlines()[-1]
    assert line.startswith(f"stylemotion-{module}: out=linked: linked is a link to "), line
    assert not any((tmp_path / "elsewhere").iterdir())


@pytest.mark.parametrize("module, args", [("evaluate", ["checkpoints=[x.ckpt]"]), ("generate", []),
                                          ("reproduce", ["data.takes_per_pair=2"])])
@pytest.mark.parametrize("seed", ["abc", "-1", "1.5", "true"])
def test_a_seed_that_is_not_a_whole_number_is_refused_before_any_work(module, args, seed, tmp_path, capsys,
                                                                      monkeypatch):
    done = run_command(module, *args, f"seed={seed}", "out=out", "hydra.run.dir=hydra", capsys=capsys,
                       monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    line = done.stderr.strip().splitlines()[-1]
    assert line.startswith("stylemotion-") and "seed must be a whole number ≥ 0, got " in line, line
    assert not (tmp_path / "out").exists()
