"""Every figure of BENCHMARKS.md and benchmarks/*.md, from one runner.

    python scripts/benchmarks.py run <suite> [--seeds 0 1 2] [suite options]
    python scripts/benchmarks.py render [--check] [DOCUMENT ...]
    python scripts/benchmarks.py list

``run`` imports ``scripts/suites/<suite>.py`` and writes ``benchmarks/results/<suite>.json``: the suite's
results with the command line, commit, machine, load before and after, seeds and seconds. It refuses to start
when a tracked file differs from the commit (results files of other suites included: commit them first), unless
``--out`` sends the results elsewhere (a trial, which no document renders). ``render``
rewrites every block between ``<!-- begin: <suite>/<block> -->`` and ``<!-- end: <suite>/<block> -->`` in
BENCHMARKS.md and benchmarks/*.md from those files (nothing else in the documents is touched); ``--check``
writes nothing and exits 1 when a document would change. A marker naming a suite without a results file or a
block its suite does not render is an error, so no table outlives the command that made it.

A suite module defines ``DESCRIPTION`` (one line), ``run(args, seeds) -> dict`` (JSON-ready; it must hold a
``"splits"`` entry saying which data each figure was chosen and reported on) and ``render(record) -> dict``
(block name → Markdown); optionally ``DEFAULT_SEEDS`` and ``add_arguments(parser)``. Protocol and helpers:
docs/benchmarks.md and ``scripts/suites/common.py``.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import platform
import re
import shlex
import sys
import time
from datetime import datetime, timezone
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parents[1]
SUITES = ROOT / "scripts" / "suites"
RESULTS = ROOT / "benchmarks" / "results"
DOCUMENTS = (ROOT / "BENCHMARKS.md", *sorted((ROOT / "benchmarks").glob("*.md")))
MARKER = re.compile(r"<!-- begin: (?P<suite>[a-z0-9_]+)/(?P<block>[a-z0-9_]+) -->\n(?P<body>.*?)"
                    r"<!-- end: (?P=suite)/(?P=block) -->", re.S)

sys.path.insert(0, str(ROOT / "scripts"))


class BenchmarkError(Exception):
    """A bad suite name, a missing results file or an unknown block: one line for the user."""


def suite_names() -> list[str]:
    """Every suite under ``scripts/suites`` (``common`` is the helpers, not a suite)."""
    return sorted(p.stem for p in SUITES.glob("*.py") if p.stem not in {"common", "__init__"})


def load_suite(name: str) -> ModuleType:
    """The module of suite ``name``; :class:`BenchmarkError` listing the suites when there is none."""
    path = SUITES / f"{name}.py"
    if not re.fullmatch(r"[a-z0-9_]+", name) or name == "common" or not path.is_file():
        raise BenchmarkError(f"no suite {name!r}; suites: {', '.join(suite_names())}")
    spec = importlib.util.spec_from_file_location(f"suites.{name}", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # a suite's dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def machine() -> dict:
    """CPU model, core count, Python, and the versions of the numeric libraries that decide the figures."""
    try:
        info = Path("/proc/cpuinfo").read_text().splitlines()
    except OSError:
        info = []
    cpu = next((ln.split(":", 1)[1].strip() for ln in info if ln.startswith("model name")),
               platform.processor() or "unknown")
    flags = next((ln for ln in info if ln.startswith("flags")), "")
    import numpy

    record = {"cpu": cpu, "cores": os.cpu_count(), "avx512": "avx512f" in flags.split(),
              "python": platform.python_version(), "numpy": numpy.__version__}
    if "torch" in sys.modules:
        record["torch"] = sys.modules["torch"].__version__
    return record


def uncommitted() -> list[str]:
    """Tracked files that differ from HEAD when the suite ran (a ``+dirty`` commit names which)."""
    import subprocess

    try:
        out = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT, capture_output=True,
                             text=True, timeout=10, check=True).stdout
    except (OSError, subprocess.SubprocessError):
        return []
    return sorted(line[3:] for line in out.splitlines() if line.strip())


def results_path(name: str) -> Path:
    return RESULTS / f"{name}.json"


def run(argv: list[str]) -> int:
    from stylemotion.io.jsonfile import write_json
    from stylemotion.provenance import git_commit, load_average

    name = argv[0] if argv and not argv[0].startswith("-") else ""
    suite = load_suite(name)
    parser = argparse.ArgumentParser(prog=f"benchmarks.py run {name}", description=suite.DESCRIPTION)
    parser.add_argument("--seeds", type=int, nargs="+", default=list(getattr(suite, "DEFAULT_SEEDS", (0, 1, 2))),
                        help="seeds of training, sampling and query choice (headline figures need ≥ 3)")
    parser.add_argument("--out", type=Path, default=None, help="results file (default benchmarks/results/<suite>.json)")
    if hasattr(suite, "add_arguments"):
        suite.add_arguments(parser)
    args = parser.parse_args(argv[1:])
    started, clock, load = datetime.now(timezone.utc), time.perf_counter(), load_average()
    commit, changed = git_commit(ROOT), uncommitted()  # the code as the run starts
    if changed and args.out is None:
        raise BenchmarkError(f"{len(changed)} tracked file(s) differ from the commit ({', '.join(changed[:3])}"
                             f"{', …' if len(changed) > 3 else ''}): a figure in benchmarks/results must come from "
                             "committed code and documents; commit first, or write a trial with --out <file>")
    results = suite.run(args, list(args.seeds))
    if "splits" not in results:
        raise BenchmarkError(f"suite {name} returned no 'splits' entry: every figure must say its split")
    record = {"suite": name, "description": suite.DESCRIPTION,
              "command": "python scripts/benchmarks.py run " + shlex.join([name, *argv[1:]]),
              "commit": commit, "uncommitted": changed,
              "started": started.isoformat(timespec="seconds"),
              "seconds": round(time.perf_counter() - clock, 1), "seeds": list(args.seeds),
              "load_average_start": load, "load_average_end": load_average(), "machine": machine(),
              "results": results}
    out = args.out or results_path(name)
    write_json(out, record)
    print(f"wrote {out.relative_to(ROOT) if out.is_relative_to(ROOT) else out} ({record['seconds']} s)")
    return 0


def rendered(text: str, document: Path, blocks: dict[str, dict[str, str]]) -> str:
    """``text`` with every marked block replaced by its suite's rendering."""
    def replace(match: re.Match) -> str:
        suite, block = match["suite"], match["block"]
        if suite not in blocks:
            if not results_path(suite).is_file():
                raise BenchmarkError(f"{document.name}: block {suite}/{block} has no results file "
                                     f"{results_path(suite).relative_to(ROOT)}; run `python scripts/benchmarks.py "
                                     f"run {suite}` or remove the block")
            from stylemotion.io.jsonfile import read_json_object

            record = read_json_object(results_path(suite), f"results of suite {suite}",
                                      f"rerun `python scripts/benchmarks.py run {suite}`")
            blocks[suite] = load_suite(suite).render(record)
        if block not in blocks[suite]:
            raise BenchmarkError(f"{document.name}: suite {suite} renders no block {block!r} "
                                 f"(it renders: {', '.join(sorted(blocks[suite]))})")
        body = blocks[suite][block].strip("\n") + "\n"
        return f"<!-- begin: {suite}/{block} -->\n{body}<!-- end: {suite}/{block} -->"

    return MARKER.sub(replace, text)


def render(argv: list[str]) -> int:
    from stylemotion.io.atomic import atomic_write_bytes

    parser = argparse.ArgumentParser(prog="benchmarks.py render")
    parser.add_argument("--check", action="store_true", help="write nothing; exit 1 when a document would change")
    parser.add_argument("documents", nargs="*", type=Path, help="only these documents (default: all)")
    args = parser.parse_args(argv)
    chosen = [d.resolve() for d in args.documents]
    unknown = [str(d) for d in chosen if d not in DOCUMENTS]
    if unknown:
        raise BenchmarkError(f"not a benchmark document: {', '.join(unknown)} (BENCHMARKS.md and benchmarks/*.md)")
    blocks: dict[str, dict[str, str]] = {}
    changed = []
    for document in chosen or DOCUMENTS:
        text = document.read_text(encoding="utf-8")
        new = rendered(text, document, blocks)
        if new != text:
            changed.append(document.relative_to(ROOT))
            if not args.check:
                atomic_write_bytes(document, new.encode("utf-8"))
    for path in changed:
        print(f"{'would change' if args.check else 'rendered'} {path}")
    return 1 if args.check and changed else 0


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    commands = {"run": run, "render": render,
                "list": lambda _: print("\n".join(f"{n}: {load_suite(n).DESCRIPTION}" for n in suite_names())) or 0}
    if not argv or argv[0] not in commands:
        print(__doc__.strip().splitlines()[0] + "\nusage: benchmarks.py {run <suite>,render [--check],list}",
              file=sys.stderr)
        return 2
    from stylemotion.io.errors import UserInputError

    try:
        return commands[argv[0]](argv[1:])
    except (BenchmarkError, UserInputError) as exc:  # bad input to the runner or a suite: one line, as commands do
        if os.environ.get("STYLEMOTION_DEBUG") and not isinstance(exc, BenchmarkError):
            raise
        print(f"error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
