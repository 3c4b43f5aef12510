"""The one skeleton every console script runs on.

A command is its library function plus this skeleton: :func:`hydra_command` (the Hydra commands) or
:func:`argparse_command` (``stylemotion-convert``, ``stylemotion-view``) give the console-script entry
point. Both

* turn a :class:`~stylemotion.io.errors.UserInputError` (a bad value, file, folder or checkpoint, or an
  existing output) into ONE line ``stylemotion-<command>: <message>`` on stderr and exit status 2
  (:data:`EXIT_BAD_INPUT`);
* turn Ctrl-C — and SIGTERM (``kill``, ``timeout``, a scheduler's preemption), which it raises as Ctrl-C so that
  the same clean-up runs — into one line and exit status 130 (:data:`EXIT_INTERRUPTED`); outputs are written
  atomically (:mod:`stylemotion.io.atomic`), so an interrupted command leaves nothing half-written;
* show the full traceback instead when asked: ``STYLEMOTION_DEBUG=1`` or ``HYDRA_FULL_ERROR=1``;
* hand the work the command line as typed (:func:`command_line`), which it records in its provenance.

Any other exception is a bug and keeps its traceback. Messages go through :mod:`logging` (Hydra sends
them to the console and to ``<job>.log``).
"""

from __future__ import annotations

import functools
import logging
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from stylemotion.io.errors import UserInputError

#: Exit status of a command stopped by bad input (argparse uses the same for a bad argument).
EXIT_BAD_INPUT = 2
#: Exit status of a command stopped by Ctrl-C (128 + SIGINT).
EXIT_INTERRUPTED = 130
#: Environment variables that ask for full tracebacks instead of one-line messages.
DEBUG_VARIABLES = ("STYLEMOTION_DEBUG", "HYDRA_FULL_ERROR")


def debugging() -> bool:
    """True when :data:`DEBUG_VARIABLES` ask for tracebacks (set to anything but empty or ``0``)."""
    return any(os.environ.get(name, "").strip() not in ("", "0") for name in DEBUG_VARIABLES)


def command_line(command: str, argv: Sequence[str] | None = None) -> str:
    """``command`` and its arguments as typed (``sys.argv[1:]`` unless ``argv`` is given)."""
    return " ".join([command, *(sys.argv[1:] if argv is None else argv)])


@contextmanager
def one_line_errors(command: str) -> Iterator[None]:
    """Run the block; bad input and Ctrl-C end it in one line on stderr (module docstring).

    Raises:
        SystemExit: :data:`EXIT_BAD_INPUT` after a :class:`UserInputError`, :data:`EXIT_INTERRUPTED`
            after Ctrl-C (unless :func:`debugging`, which re-raises the original).
    """
    try:
        yield
    except UserInputError as exc:
        if debugging():
            raise
        print(f"{command}: {exc}", file=sys.stderr, flush=True)
        raise SystemExit(EXIT_BAD_INPUT) from None
    except KeyboardInterrupt:
        if debugging():
            raise
        print(f"{command}: interrupted; finished outputs are untouched and nothing half-written was kept",
              file=sys.stderr, flush=True)
        raise SystemExit(EXIT_INTERRUPTED) from None


#: Hydra's message lines that only describe Hydra itself (its config search path, its grammar page).
_HYDRA_NOISE = ("Config search path", "provider=", "See https://hydra.cc")


def hydra_message(exc: BaseException) -> str:
    """One line of Hydra's (or OmegaConf's) several-line message: blank and Hydra-internal lines dropped, a
    line ending in ``:`` followed by its items joined with commas, the OmegaConf cause appended."""
    parts: list[str] = []
    for error in (exc, exc.__cause__):
        if error is None:
            continue
        lines = [ln.strip() for ln in str(error).splitlines() if ln.strip()]
        text, listing = "", False
        for line in lines:
            if line.startswith(_HYDRA_NOISE):
                break
            text += (", " if listing and not text.endswith(":") else " ") + line
            listing = listing or line.endswith(":")
        if text.strip() and text.strip() not in " ".join(parts):
            parts.append(text.strip())
    return " — ".join(parts) or type(exc).__name__


@contextmanager
def hydra_errors_in_one_line(started: Callable[[], bool] = lambda: True) -> Iterator[None]:
    """Within the block, a config Hydra cannot compose (an unknown key or config group option, an override its
    grammar refuses) and a missing or mistyped value (``???``) raise :class:`~stylemotion.config.ConfigError`
    with :func:`hydra_message`, and a file Hydra cannot write before the work has ``started()`` (its run folder
    below a file or in a read-only folder) :class:`~stylemotion.io.errors.OutputWriteError`, instead of Hydra's
    several lines and exit status 1; other exceptions keep Hydra's reporting. (Hydra offers no hook for this:
    its ``run_and_report`` is wrapped for the block.)"""
    from hydra._internal import utils
    from hydra.errors import HydraException
    from omegaconf.errors import MissingMandatoryValue, ValidationError

    from stylemotion.config import ConfigError

    original = utils.run_and_report

    def run_and_report(func: Callable[[], Any]) -> Any:
        try:
            return func()
        except (HydraException, MissingMandatoryValue, ValidationError) as exc:
            if debugging():
                raise
            raise ConfigError(hydra_message(exc)) from None
        except OSError as exc:
            if started() or debugging():
                raise
            from stylemotion.io.errors import OutputWriteError

            raise OutputWriteError(f"hydra.run.dir: cannot write {exc.filename or 'the run folder'} "
                                   f"({exc.strerror or exc}); choose another hydra.run.dir") from None
        except Exception as exc:  # noqa: BLE001 - handed back to Hydra's own reporting
            caught = exc

            def again() -> Any:
                raise caught

            return original(again)

    utils.run_and_report = run_and_report
    try:
        yield
    finally:
        utils.run_and_report = original


def template_names(template: str) -> set[str]:
    """The ``$NAME`` / ``${NAME}`` placeholders of a :class:`string.Template` text (``$$`` is no placeholder)."""
    import string

    pattern = string.Template.pattern
    return {m["named"] or m["braced"] for m in pattern.finditer(template) if m["named"] or m["braced"]}


@contextmanager
def help_computes_only_what_it_shows() -> Iterator[None]:
    """Within the block, Hydra's ``--help`` (and ``--hydra-help``) fills only the placeholders its template names.

    Hydra computes all four (``$FLAGS_HELP``, ``$HYDRA_CONFIG_GROUPS``, ``$APP_CONFIG_GROUPS``, ``$CONFIG``) before
    it fills the template; listing the config groups reads every group option of the package (most of a second,
    over a second on two busy cores), though the commands' help templates (``configs/hydra/help/``) name none of
    them. A placeholder the template names is computed exactly as Hydra does, so the text is the same. (Hydra has
    no hook for this: its ``Hydra.get_help`` is replaced for the block.)"""
    import string

    from hydra._internal.hydra import Hydra
    from omegaconf import OmegaConf

    original = Hydra.get_help

    def get_help(self: Any, help_cfg: Any, cfg: Any, args_parser: Any, resolve: bool) -> str:
        template = help_cfg.template
        names = template_names(template)

        def is_hydra_group(x: str) -> bool:
            return x.startswith("hydra/") or x == "hydra"

        values: dict[str, str] = {}
        if "FLAGS_HELP" in names:
            values["FLAGS_HELP"] = self.format_args_help(args_parser)
        if "HYDRA_CONFIG_GROUPS" in names:
            values["HYDRA_CONFIG_GROUPS"] = self.format_config_groups(is_hydra_group)
        if "APP_CONFIG_GROUPS" in names:
            values["APP_CONFIG_GROUPS"] = self.format_config_groups(lambda x: not is_hydra_group(x))
        if "CONFIG" in names:
            values["CONFIG"] = OmegaConf.to_yaml(cfg, resolve=resolve)
        return string.Template(template).substitute(values)

    Hydra.get_help = get_help
    try:
        yield
    finally:
        Hydra.get_help = original


def check_not_a_link(value: Any, key: str) -> None:
    """Refuse an output folder ``key=value`` that is a link (every command writes its outputs into ``out``):
    nothing is written through a link, wherever it points.

    Raises:
        UnsafePathError: naming the key, the link and where it points.
    """
    from stylemotion.io.outputs import UnsafePathError

    path = Path(str(value)).expanduser() if value not in (None, "") else None
    if path is not None and path.is_symlink():
        raise UnsafePathError(f"{key}={value}: {path} is a link to {path.resolve()}; nothing is written through a "
                              f"link: choose another {key}=…")


def check_seed(seed: Any, key: str = "seed") -> None:
    """Refuse a ``seed`` that is not a whole number ≥ 0 (None: the command's default) before any work.

    Raises:
        ConfigError: naming the key and the value.
    """
    from stylemotion.config import ConfigError

    if seed is not None and (not isinstance(seed, int) or isinstance(seed, bool) or seed < 0):
        raise ConfigError(f"{key} must be a whole number ≥ 0, got {seed!r}")


def check_run_dir(overrides: Sequence[str]) -> None:
    """Refuse a ``hydra.run.dir=`` that is a link: Hydra would write its ``.hydra/`` and log through it, out of
    the run folder (train, data and reproduce keep their run there).

    Raises:
        UnsafePathError: naming the link and where it points.
    """
    from stylemotion.io.outputs import UnsafePathError

    for override in overrides:
        key, _, value = override.partition("=")
        if key.lstrip("+~") == "hydra.run.dir" and value:
            path = Path(value.strip("'\"")).expanduser()
            if path.is_symlink():
                raise UnsafePathError(f"hydra.run.dir={value}: {path} is a link to {path.resolve()}; nothing is "
                                      "written through a link: give the folder itself")


def finished_run_overrides(overrides: Sequence[str], finished: str | None) -> list[str]:
    """Hydra overrides that keep a finished run's folder as it is: when ``hydra.run.dir=`` names a folder holding
    ``finished``, Hydra's ``.hydra/`` record and its job log stay those of the run's first start (the console
    still shows the log; a start the work accepts is recorded by the work, e.g. train's ``run.json``)."""
    if not finished:
        return []
    for override in overrides:
        key, _, value = override.partition("=")
        if key.lstrip("+~") == "hydra.run.dir" and value:
            if (Path(value.strip("'\"")).expanduser() / finished).is_file():
                return ["hydra.output_subdir=null", "hydra/job_logging=stdout"]
    return []


def _interrupt(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt


def stop_on_sigterm() -> None:
    """Raise SIGTERM in the main thread as :class:`KeyboardInterrupt` (module docstring); elsewhere (a command
    run from another thread) signals cannot be handled and nothing changes."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _interrupt)


def _job_log() -> Path | None:
    """The file Hydra's job logging writes (``<job>.log`` in the Hydra run folder), if any."""
    for handler in logging.getLogger().handlers:
        if isinstance(handler, logging.FileHandler):
            handler.flush()
            return Path(handler.baseFilename)
    return None


def keep_run_record(cfg: Any, key: str) -> None:
    """Put the resolved config (``config_resolved.yaml``) and the job's log (``<job>.log``) into the new output
    folder ``cfg[key]`` after the work has made it, beside its results. Nothing is replaced: a name the folder
    already holds is left alone, as is a link or a folder the work did not make."""
    from omegaconf import OmegaConf

    from stylemotion.io.atomic import atomic_write_bytes

    folder = Path(str(cfg.get(key) or "")).expanduser()
    if not str(cfg.get(key) or "") or folder.is_symlink() or not folder.is_dir():
        return
    records = {"config_resolved.yaml": OmegaConf.to_yaml(cfg, resolve=True).encode()}
    log = _job_log()
    if log is not None and log.is_file():
        records[log.name] = log.read_bytes()
    for name, data in records.items():
        if not (folder / name).exists():
            atomic_write_bytes(folder / name, data)


def hydra_command(command: str, config_name: str, work: Callable[[Any, str], Any],
                  record_in: str | None = None, finished: str | None = None) -> Callable[[], None]:
    """The console-script entry point of a Hydra command.

    Args:
        command: its name, e.g. ``stylemotion-search`` (the prefix of every error line).
        config_name: its config in ``stylemotion/configs`` (``search`` → ``search.yaml``).
        work: ``work(cfg, command_line) -> value``; the value is the job's return value (a sweep's
            objective for ``stylemotion-train``). Hydra names the job after ``work``'s module, so the log
            of ``stylemotion/cli/search.py`` is ``search.log``.
        record_in: the config key of the new output folder the work makes (``out``): when it finished, the
            resolved config and the log go into it (:func:`keep_run_record`); None when the folder holds them
            already (the Hydra run folder is the run's folder: train, data, reproduce).
        finished: a file whose presence in the ``hydra.run.dir=`` given on the command line marks a finished
            run (train: ``metrics.json``): Hydra then writes neither its ``.hydra/`` nor its job log there, so
            the run's files are touched only once the work accepts the run (:func:`finished_run_overrides`).
    """

    started: list[bool] = []
    typed: list[str] = []  # the command line as typed, without the overrides added here

    @functools.wraps(work)
    def task(cfg: Any) -> Any:
        started.append(True)
        with one_line_errors(command):
            if hasattr(cfg, "get"):
                check_not_a_link(cfg.get("out"), "out")
                check_seed(cfg.get("seed"))
            value = work(cfg, command_line(command, typed or None))
            if record_in is not None:
                keep_run_record(cfg, record_in)
            return value

    def main() -> None:
        import hydra

        from stylemotion.cli.schemas import check_overrides, register_schemas_for
        from stylemotion.config import CONFIG_PACKAGE

        stop_on_sigterm()
        started.clear()  # main runs once per process, but more than once in-process (tests, a notebook)
        with one_line_errors(command):
            register_schemas_for(config_name)
            check_overrides(config_name, sys.argv[1:])
            check_run_dir(sys.argv[1:])
            typed[:] = sys.argv[1:]
            sys.argv[1:] = [*typed, *finished_run_overrides(typed, finished)]
            with hydra_errors_in_one_line(lambda: bool(started)), help_computes_only_what_it_shows():
                hydra.main(config_path=CONFIG_PACKAGE, config_name=config_name, version_base="1.3")(task)()

    main.__doc__ = f"Console script ``{command}``."
    return main


def argparse_command(command: str, work: Callable[[Sequence[str] | None], int]) -> Callable[..., int]:
    """``main(argv=None) -> exit status`` of an argparse command: ``work(argv)`` under :func:`one_line_errors`.

    A :class:`UserInputError` returns :data:`EXIT_BAD_INPUT` after its one line (argparse's own errors
    exit with the same status).
    """

    @functools.wraps(work)
    def main(argv: Sequence[str] | None = None) -> int:
        stop_on_sigterm()
        try:
            with one_line_errors(command):
                return work(argv)
        except SystemExit as exc:
            return exc.code if isinstance(exc.code, int) else EXIT_BAD_INPUT

    return main
