"""Suite ``startup``: every console script of pyproject.toml answering ``--help`` and a bad argument, as a new
user meets them (issue 29: ``--help`` ≤ 1.5 s, a bad argument answered ≤ 2 s) — measured ALONE.

Each command runs as a real subprocess (the installed console script, ``.venv/bin/stylemotion-<command>``), in a
scratch folder, ``--repeat`` times for each of the two cases, round-robin over the commands so that a change of
load touches all of them alike; one unrecorded warm-up round first (the page cache after a boot is not start-up).
Per case: wall seconds (median and max), the child's CPU seconds (user + system, median; less sensitive to other
processes than wall time, though not blind to them), the exit status and the stderr lines. Checked, not timed:
``--help`` exits 0 with text; a bad argument exits 2 (Hydra commands: one line ``stylemotion-<command>: …``).
Then, once per case, the same entry point under ``python -X importtime`` in a wrapper that records which heavy
modules (torch, Lightning, scikit-learn, matplotlib, scipy) the case imported, how many modules, and the sum of
the import self-times (``-X importtime`` clocks wall time inside the interpreter: as load-sensitive as the wall
figures; the CPU seconds are the steadier measure for ratios between versions).

``--compare DIR`` measures the package of another checkout (``git archive <commit> stylemotion | tar -x -C
DIR``; put on ``PYTHONPATH``) interleaved with this one, so that the two are compared as ratios in one run.
No randomness: the seeds are not used (``--repeat`` sets the repetitions).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from suites.common import md_table, provenance_line

DESCRIPTION = "start-up of every console script: --help and a bad argument, and what they import (run alone)"
DEFAULT_SEEDS = (0,)
ROOT = Path(__file__).resolve().parents[2]
#: The aims of issue 29 (seconds, wall, alone on the machine).
AIMS = {"help": 1.5, "bad": 2.0}
#: Modules whose import marks a heavy start-up.
HEAVY = ("torch", "lightning", "sklearn", "matplotlib", "scipy")
#: A bad argument per argparse command (a flag that does not exist, after the required arguments so that the
#: flag is what is refused); every other command is a Hydra command and gets an unknown key.
BAD_ARGUMENTS = {"stylemotion-convert": ["walk.bvh", "walk.npz", "--nosuchflag"],
                 "stylemotion-view": ["walk.bvh", "--out", "viewer", "--nosuchflag"]}
HYDRA_BAD = ["nosuchkey=1"]
#: Hydra commands answer a bad key in exactly one stderr line (argparse prints its usage above its error).
ARGPARSE = set(BAD_ARGUMENTS)

WRAPPER = """
import atexit, importlib, json, os, sys
module, function, *argv = sys.argv[1:]
def record():
    with open(os.environ["STARTUP_PROBE_OUT"], "w") as f:
        json.dump({"modules": len(sys.modules), "stylemotion_modules": sum(n.startswith("stylemotion") for n in
                   sys.modules), "heavy": [m for m in HEAVY_MODULES if m in sys.modules]}, f)
atexit.register(record)
sys.argv = [module, *argv]
sys.exit(getattr(importlib.import_module(module), function)())
""".replace("HEAVY_MODULES", repr(HEAVY))


def console_scripts() -> dict[str, str]:
    """``[project.scripts]`` of pyproject.toml: command → ``module:function``."""
    import tomllib

    return dict(tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["scripts"])


def case_arguments(command: str, case: str) -> list[str]:
    return ["--help"] if case == "help" else list(BAD_ARGUMENTS.get(command, HYDRA_BAD))


def environment(source: str | None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("STYLEMOTION_DEBUG", "HYDRA_FULL_ERROR")}
    if source:
        env["PYTHONPATH"] = os.pathsep.join([source, *filter(None, [os.environ.get("PYTHONPATH")])])
    return env


def executable(command: str, entry: str) -> list[str]:
    """The installed console script; a ``python -c`` of its entry point where it is not installed."""
    script = Path(sys.executable).parent / command
    if script.is_file():
        return [str(script)]
    module, _, function = entry.partition(":")
    return [sys.executable, "-c", f"import sys; from {module} import {function}; sys.exit({function}())"]


def run_once(argv: list[str], env: dict[str, str], cwd: str, timeout: float) -> dict[str, Any]:
    """One subprocess: wall and CPU seconds, exit status, stderr lines (the first one kept)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    clock = time.perf_counter()
    try:
        done = subprocess.run(argv, env=env, cwd=cwd, capture_output=True, text=True, timeout=timeout)
        code, out, err = done.returncode, done.stdout, done.stderr
    except subprocess.TimeoutExpired as exc:
        code, out, err = None, str(exc.stdout or ""), f"timed out after {timeout:g} s"
    wall = time.perf_counter() - clock
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    return {"wall_s": wall, "cpu_s": cpu, "exit": code, "stdout_chars": len(out), "stderr_lines": len(lines),
            "stderr_last": lines[-1][:300] if lines else ""}


def probe(entry: str, args: list[str], env: dict[str, str], cwd: str, timeout: float) -> dict[str, Any]:
    """The entry point under ``-X importtime`` in :data:`WRAPPER`: heavy modules, module count, import self-time."""
    module, _, function = entry.partition(":")
    with tempfile.NamedTemporaryFile(suffix=".json", delete=False) as handle:
        out = handle.name
    try:
        done = subprocess.run([sys.executable, "-X", "importtime", "-c", WRAPPER, module, function, *args],
                              env={**env, "STARTUP_PROBE_OUT": out}, cwd=cwd, capture_output=True, text=True,
                              timeout=timeout)
        loaded = json.loads(Path(out).read_text() or "{}")
    except (subprocess.TimeoutExpired, json.JSONDecodeError, OSError) as exc:
        return {"error": f"{type(exc).__name__}: {exc}"}
    finally:
        Path(out).unlink(missing_ok=True)
    self_us = [int(ln.split("|")[0].split(":")[1]) for ln in done.stderr.splitlines()
               if ln.startswith("import time:") and "self [us]" not in ln]
    return {**loaded, "import_self_s": round(sum(self_us) / 1e6, 3)}


def checked(command: str, case: str, runs: list[dict[str, Any]]) -> list[str]:
    """What is wrong with the answers (not their speed): exit status, text, one line."""
    problems = []
    for r in runs:
        if case == "help" and (r["exit"] != 0 or r["stdout_chars"] == 0):
            problems.append(f"--help exit {r['exit']}, {r['stdout_chars']} characters")
        if case == "bad":
            if r["exit"] != 2:
                problems.append(f"bad argument exit {r['exit']}: {r['stderr_last']}")
            elif command not in ARGPARSE and (r["stderr_lines"] != 1 or not r["stderr_last"].startswith(command)):
                problems.append(f"bad argument: {r['stderr_lines']} stderr lines, last {r['stderr_last']!r}")
    return sorted(set(problems))


def summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    wall = [r["wall_s"] for r in runs]
    cpu = [r["cpu_s"] for r in runs]
    return {"median_s": round(statistics.median(wall), 3), "max_s": round(max(wall), 3),
            "min_s": round(min(wall), 3), "cpu_median_s": round(statistics.median(cpu), 3), "n": len(runs),
            "wall_s": [round(w, 3) for w in wall], "exit": sorted({r["exit"] for r in runs}, key=str),
            "stderr_last": runs[-1]["stderr_last"]}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--repeat", type=int, default=7, help="recorded runs of each command and case (default 7)")
    parser.add_argument("--warmup", type=int, default=1, help="unrecorded rounds first (default 1)")
    parser.add_argument("--commands", nargs="+", default=None,
                        help="only these console scripts (default: all of pyproject.toml)")
    parser.add_argument("--compare", default=None, metavar="DIR",
                        help="also measure the stylemotion package in DIR (on PYTHONPATH), interleaved")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds before a run counts as hung")


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    scripts = console_scripts()
    unknown = sorted(set(args.commands or ()) - set(scripts))
    if unknown:
        raise SystemExit(f"not a console script of pyproject.toml: {', '.join(unknown)}")
    commands = [c for c in scripts if not args.commands or c in args.commands]
    versions = {"this": None, **({"compare": str(Path(args.compare).resolve())} if args.compare else {})}
    cases = ("help", "bad")
    runs: dict[tuple[str, str, str], list[dict[str, Any]]] = {}
    with tempfile.TemporaryDirectory(prefix="startup_") as scratch:
        envs = {v: environment(src) for v, src in versions.items()}
        for round_ in range(args.warmup + args.repeat):
            for command in commands:
                for case in cases:
                    for version in versions:  # the two versions side by side: the same load for both
                        result = run_once([*executable(command, scripts[command]), *case_arguments(command, case)],
                                          envs[version], scratch, args.timeout)
                        if round_ >= args.warmup:
                            runs.setdefault((version, command, case), []).append(result)
            print(f"round {round_ + 1}/{args.warmup + args.repeat} done", flush=True)
        rows = []
        for command in commands:
            for version in versions:
                row: dict[str, Any] = {"command": command, "version": version}
                for case in cases:
                    measured = runs[(version, command, case)]
                    row[case] = {**summary(measured), "problems": checked(command, case, measured),
                                 "arguments": case_arguments(command, case),
                                 "imports": probe(scripts[command], case_arguments(command, case), envs[version],
                                                  scratch, args.timeout)}
                rows.append(row)
    return {"splits": {"kind": "none: start-up of the console scripts, no data"}, "aims_s": AIMS,
            "repeat": args.repeat, "warmup": args.warmup, "versions": versions, "commands": rows}


def _cell(case: dict[str, Any], aim: float) -> str:
    mark = "" if case["max_s"] <= aim else " ✗" if case["median_s"] > aim else " (max over)"
    return f"{case['median_s']:.2f} / {case['max_s']:.2f} s{mark}"


def _heavy(case: dict[str, Any]) -> str:
    imports = case["imports"]
    if "error" in imports:
        return f"probe failed: {imports['error']}"
    return ", ".join(imports["heavy"]) or "none"


def _table(record: dict[str, Any], version: str) -> str:
    rows = []
    for r in (x for x in record["results"]["commands"] if x["version"] == version):
        help_, bad = r["help"], r["bad"]
        problems = "; ".join(help_["problems"] + bad["problems"]) or "ok"
        rows.append([f"`{r['command']}`", _cell(help_, AIMS["help"]), f"{help_['cpu_median_s']:.2f} s",
                     _heavy(help_), f"{help_['imports'].get('import_self_s', float('nan')):.2f} s",
                     f"`{' '.join(bad['arguments'])}`", _cell(bad, AIMS["bad"]), f"{bad['cpu_median_s']:.2f} s",
                     _heavy(bad), problems])
    return md_table(["command", "`--help` median / max (aim ≤ 1.5 s)", "CPU (median)", "heavy modules loaded",
                     "import self-time", "bad argument", "median / max (aim ≤ 2 s)", "CPU (median)",
                     "heavy modules loaded", "exit status and lines"], rows)


def _compare(record: dict[str, Any]) -> str:
    results = record["results"]
    by = {(r["version"], r["command"]): r for r in results["commands"]}
    rows = []
    for command in dict.fromkeys(r["command"] for r in results["commands"]):
        this, other = by[("this", command)], by[("compare", command)]
        cells = [f"`{command}`"]
        for case in ("help", "bad"):
            a, b = this[case], other[case]
            ai, bi = a["imports"].get("import_self_s"), b["imports"].get("import_self_s")
            cells += [f"{b['median_s']:.2f} → {a['median_s']:.2f} s (×{a['median_s'] / b['median_s']:.2f})",
                      f"×{a['cpu_median_s'] / b['cpu_median_s']:.2f}",
                      f"×{ai / bi:.2f}" if ai and bi else "n/a", f"{_heavy(b)} → {_heavy(a)}"]
        rows.append(cells)
    return (md_table(["command", "`--help` wall median, compared → this", "CPU ratio", "import self-time ratio",
                      "heavy modules", "bad argument wall median", "CPU ratio", "import self-time ratio",
                      "heavy modules"], rows)
            + f"\n\nCompared: the package in `{results['versions']['compare']}` (on `PYTHONPATH`), run interleaved "
              "with this one; ratios below 1 are faster now.")


def render(record: dict[str, Any]) -> dict[str, str]:
    line = provenance_line(record)
    results = record["results"]
    mine = [r for r in results["commands"] if r["version"] == "this"]
    note = (f"\n\n{results['repeat']} runs of each command and case after {results['warmup']} warm-up round(s), "
            "round-robin; wall median / max, ✗ where the median misses the aim, (max over) where only the slowest "
            "run does. Heavy modules: which of torch, Lightning, scikit-learn, matplotlib and scipy the case "
            "imported; import self-time: the sum of `python -X importtime` self-times of that one run (wall "
            "clock: noisy under load). CPU: the child's user + system seconds.")
    blocks = {"commands": f"{_table(record, 'this')}{note}\n\n{line}"}
    if "compare" in results["versions"]:
        blocks["compare"] = f"{_compare(record)}\n\n{line}"
    help_ok = sum(r["help"]["median_s"] <= AIMS["help"] for r in mine)
    bad_ok = sum(r["bad"]["median_s"] <= AIMS["bad"] for r in mine)
    worst_help = max(mine, key=lambda r: r["help"]["median_s"])
    worst_bad = max(mine, key=lambda r: r["bad"]["median_s"])
    heavy = sorted({m for r in mine for m in r["help"]["imports"].get("heavy", [])})
    wrong = [r["command"] for r in mine if r["help"]["problems"] or r["bad"]["problems"]]
    head = [[f"`--help` within 1.5 s (median), of {len(mine)} commands",
             f"{help_ok}; slowest `{worst_help['command']}` {worst_help['help']['median_s']:.2f} s "
             f"(max {worst_help['help']['max_s']:.2f} s)"],
            [f"a bad argument answered within 2 s (median), of {len(mine)} commands",
             f"{bad_ok}; slowest `{worst_bad['command']}` {worst_bad['bad']['median_s']:.2f} s "
             f"(max {worst_bad['bad']['max_s']:.2f} s)"],
            ["heavy modules any `--help` loads", ", ".join(heavy) or "none"],
            ["wrong exit status or more than one line", ", ".join(wrong) or "none"]]
    blocks["headline"] = f"{md_table(['figure (measured alone)', 'result'], head)}\n\n{line}"
    return blocks
