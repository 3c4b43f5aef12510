"""Start-up cost of importing stylemotion modules, each in a fresh interpreter (JSON lines).

    python scripts/bench_imports.py [--repeat 5] [--module stylemotion.search.command ...]

For each module: the wall-clock seconds of ``import <module>`` in ``--repeat`` new processes (min, median,
max), and what it loaded (stylemotion modules, all modules, whether torch / lightning / sklearn / matplotlib).
Run it alone on an idle machine; compare versions as ratios in one run (``PYTHONPATH=<worktree>`` imports an
older checkout's package).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys

DEFAULT_MODULES = ("stylemotion.config", "stylemotion.search.command", "stylemotion.reconstruct.command",
                   "stylemotion.annotate.command", "stylemotion.cli.search")
PROBE = """
import json, sys, time
t = time.perf_counter()
import {module}
seconds = time.perf_counter() - t
names = list(sys.modules)
print(json.dumps({{"seconds": seconds, "stylemotion_modules": sum(n.startswith("stylemotion") for n in names),
        "modules": len(names), **{{k: k in sys.modules for k in ("torch", "lightning", "sklearn", "matplotlib")}}}}))
"""


def measure(module: str, repeat: int) -> dict:
    """Import ``module`` in ``repeat`` fresh interpreters; the timings and what the last one loaded."""
    runs = []
    for _ in range(repeat):
        done = subprocess.run([sys.executable, "-c", PROBE.format(module=module)], capture_output=True, text=True,
                              check=True)
        runs.append(json.loads(done.stdout.strip().splitlines()[-1]))
    seconds = [r["seconds"] for r in runs]
    last = {k: v for k, v in runs[-1].items() if k != "seconds"}
    return {"module": module, "repeat": repeat, "min_s": round(min(seconds), 3),
            "median_s": round(statistics.median(seconds), 3), "max_s": round(max(seconds), 3), **last}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="fresh interpreters per module (default 5)")
    parser.add_argument("--module", action="append", help="a module to import (repeatable; default: a set)")
    args = parser.parse_args(argv)
    for module in args.module or DEFAULT_MODULES:
        print(json.dumps(measure(module, args.repeat)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
