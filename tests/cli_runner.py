"""Console commands called in this process, as a test's subprocess would see them.

:func:`run_command` calls a console script's entry function (``stylemotion.cli.<module>.main``) with
``sys.argv`` set to the command line and returns its exit status, stdout and stderr (read through ``capsys``),
without paying a new interpreter's import of the package (seconds per call). Hydra's global state (its
config search, the job's config, the logging it configured), torch's thread count (``threads=N``) and the
environment (e.g. Lightning's ``PL_GLOBAL_SEED``) are put back afterwards, so later tests see none of it.
A subprocess test per console-script family keeps checking that the installed scripts start.
"""

from __future__ import annotations

import importlib
import logging
import os
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pytest

#: Console script → module under stylemotion.cli (its entry function is ``main``).
SCRIPTS = {"train": "stylemotion-train", "evaluate": "stylemotion-eval", "generate": "stylemotion-generate",
           "segment": "stylemotion-segment", "prepare": "stylemotion-data", "reproduce": "stylemotion-reproduce",
           "style": "stylemotion-style", "search": "stylemotion-search", "reconstruct": "stylemotion-reconstruct",
           "texture": "stylemotion-texture", "keyframes": "stylemotion-keyframes", "annotate": "stylemotion-annotate",
           "convert": "stylemotion-convert", "view": "stylemotion-view"}


@dataclass
class Done:
    """What a finished command left: like :class:`subprocess.CompletedProcess`."""

    returncode: int
    stdout: str
    stderr: str


def _exit_status(code: object) -> int:
    if code is None:
        return 0
    return code if isinstance(code, int) else 1  # sys.exit("message") prints it and exits with 1


def run_command(module: str, *args: str, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch,
                cwd: Path | None = None, entry: Callable[[], object] | None = None) -> Done:
    """``stylemotion-<module> args`` in this process (in ``cwd`` if given); its exit status and output.

    Tracebacks are off (``HYDRA_FULL_ERROR`` and ``STYLEMOTION_DEBUG`` unset), as for a user.
    """
    from hydra.core.global_hydra import GlobalHydra
    from hydra.core.hydra_config import HydraConfig

    main = entry or importlib.import_module(f"stylemotion.cli.{module}").main
    monkeypatch.setattr(sys, "argv", [SCRIPTS.get(module, module), *args])
    monkeypatch.delenv("HYDRA_FULL_ERROR", raising=False)
    monkeypatch.delenv("STYLEMOTION_DEBUG", raising=False)
    if cwd is not None:
        monkeypatch.chdir(cwd)
    import torch

    threads, environ = torch.get_num_threads(), dict(os.environ)
    capsys.readouterr()  # only this command's output
    root = logging.getLogger()
    handlers, level = root.handlers[:], root.level
    loggers = {name: (lg.handlers[:], lg.level, lg.propagate, lg.disabled)
               for name, lg in logging.Logger.manager.loggerDict.items() if isinstance(lg, logging.Logger)}
    try:
        try:
            status = _exit_status(main())
        except SystemExit as exc:
            status = _exit_status(exc.code)
    finally:
        torch.set_num_threads(threads)
        for key in set(os.environ) - set(environ):
            del os.environ[key]
        os.environ.update(environ)
        GlobalHydra.instance().clear()
        HydraConfig.instance().cfg = None
        for handler in root.handlers:
            if handler not in handlers:
                handler.close()  # e.g. the job's <name>.log file
        root.handlers[:] = handlers
        root.setLevel(level)
        for name, (kept, lvl, propagate, disabled) in loggers.items():
            lg = logging.getLogger(name)
            for handler in lg.handlers:
                if handler not in kept:
                    handler.close()
            lg.handlers[:], lg.level, lg.propagate, lg.disabled = kept, lvl, propagate, disabled
    out = capsys.readouterr()
    return Done(status, out.out, out.err)
