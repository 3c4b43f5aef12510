"""The one command skeleton: bad input and Ctrl-C in one line with their exit status, bugs keep tracebacks."""

from __future__ import annotations

import pytest

from stylemotion.cli.skeleton import (
    EXIT_BAD_INPUT,
    EXIT_INTERRUPTED,
    argparse_command,
    command_line,
    one_line_errors,
)
from stylemotion.config import ConfigError
from stylemotion.io.outputs import OutputExistsError


@pytest.fixture(autouse=True)
def _no_debug(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("STYLEMOTION_DEBUG", raising=False)
    monkeypatch.delenv("HYDRA_FULL_ERROR", raising=False)


@pytest.mark.parametrize("error", [ConfigError("k=0: must be ≥ 1"), OutputExistsError("out exists")])
def test_user_input_errors_end_in_one_line_and_status_2(error: Exception, capsys: pytest.CaptureFixture) -> None:
    with pytest.raises(SystemExit) as caught, one_line_errors("stylemotion-x"):
        raise error
    assert caught.value.code == EXIT_BAD_INPUT
    assert capsys.readouterr().err == f"stylemotion-x: {error}\n"


def test_ctrl_c_ends_in_one_line_and_status_130(capsys: pytest.CaptureFixture) -> None:
    with pytest.raises(SystemExit) as caught, one_line_errors("stylemotion-x"):
        raise KeyboardInterrupt
    assert caught.value.code == EXIT_INTERRUPTED
    err = capsys.readouterr().err
    assert err.startswith("stylemotion-x: interrupted") and err.count("\n") == 1


def test_bugs_keep_their_traceback_and_debug_shows_user_errors(monkeypatch: pytest.MonkeyPatch) -> None:
    with pytest.raises(ZeroDivisionError), one_line_errors("stylemotion-x"):
        raise ZeroDivisionError
    monkeypatch.setenv("STYLEMOTION_DEBUG", "1")
    with pytest.raises(ConfigError), one_line_errors("stylemotion-x"):
        raise ConfigError("shown with its traceback")


def test_argparse_commands_return_their_status(capsys: pytest.CaptureFixture) -> None:
    def work(argv):
        if argv == ["bad"]:
            raise ConfigError("bad=1: refused")
        return 0

    main = argparse_command("stylemotion-y", work)
    assert main(["good"]) == 0
    assert main(["bad"]) == EXIT_BAD_INPUT and capsys.readouterr().err == "stylemotion-y: bad=1: refused\n"


def test_command_line_is_the_command_and_its_arguments() -> None:
    assert command_line("stylemotion-z", ["a=1", "b=two words"]) == "stylemotion-z a=1 b=two words"


def test_sigterm_is_raised_as_ctrl_c_so_the_same_clean_up_runs(capsys: pytest.CaptureFixture) -> None:
    import os
    import signal

    from stylemotion.cli.skeleton import stop_on_sigterm

    previous = signal.getsignal(signal.SIGTERM)
    try:
        stop_on_sigterm()
        with pytest.raises(SystemExit) as caught, one_line_errors("stylemotion-x"):
            os.kill(os.getpid(), signal.SIGTERM)
        assert caught.value.code == EXIT_INTERRUPTED
        assert capsys.readouterr().err.startswith("stylemotion-x: interrupted")
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_the_run_record_goes_into_the_new_output_folder_without_replacing_anything(tmp_path) -> None:
    from omegaconf import OmegaConf

    from stylemotion.cli.skeleton import keep_run_record

    out = tmp_path / "out"
    out.mkdir()
    (out / "config_resolved.yaml").write_text("the work's own")
    cfg = OmegaConf.create({"out": str(out), "k": 3, "twice": "${k}"})
    keep_run_record(cfg, "out")
    assert (out / "config_resolved.yaml").read_text() == "the work's own"
    (out / "config_resolved.yaml").unlink()
    keep_run_record(cfg, "out")
    assert OmegaConf.load(out / "config_resolved.yaml") == {"out": str(out), "k": 3, "twice": 3}
    keep_run_record(OmegaConf.create({"out": str(tmp_path / "never_made")}), "out")  # the work failed: nothing
    assert not (tmp_path / "never_made").exists()
