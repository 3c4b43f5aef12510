"""Compare two evaluation ``report.json`` files number for number, ignoring provenance.

    python scripts/compare_reports.py runs/reproduce/synthetic/report/report.json other/report/report.json

Skipped: ``meta`` (timings, paths, commit, command, machine load) and any key that names a path,
a checkpoint or a duration. Everything else (Tables 5.1–5.3, recognition, Fréchet, diversity, foot
skating, nearest clip, autoencoder test error, definitions) must be equal; ``--rtol`` allows a
relative tolerance (default 0: bit-identical). Prints one JSON line and exits 1 on a difference.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

IGNORED_TOP = {"meta"}
IGNORED_WORDS = ("path", "checkpoint", "seconds", "command", "git_commit")


def _ignored(key: str) -> bool:
    return any(word in key.lower() for word in IGNORED_WORDS)


def differences(a: Any, b: Any, rtol: float = 0.0, where: str = "") -> list[str]:
    """Every place where ``a`` and ``b`` differ (JSON values), as ``key.path: a != b`` lines."""
    if isinstance(a, dict) and isinstance(b, dict):
        out = []
        for key in sorted(set(a) | set(b)):
            if (not where and key in IGNORED_TOP) or _ignored(str(key)):
                continue
            if key not in a or key not in b:
                out.append(f"{where}.{key}: only in {'second' if key not in a else 'first'}")
                continue
            out += differences(a[key], b[key], rtol, f"{where}.{key}")
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: length {len(a)} != {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in differences(x, y, rtol, f"{where}[{i}]")]
    if isinstance(a, float) and isinstance(b, float) and rtol > 0:
        return [] if math.isclose(a, b, rel_tol=rtol, abs_tol=0.0) else [f"{where}: {a!r} != {b!r}"]
    return [] if a == b else [f"{where}: {a!r} != {b!r}"]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("first", type=Path)
    parser.add_argument("second", type=Path)
    parser.add_argument("--rtol", type=float, default=0.0, help="relative tolerance for floats (default 0)")
    args = parser.parse_args(argv)
    first, second = (json.loads(p.read_text()) for p in (args.first, args.second))
    diffs = differences(first, second, args.rtol)
    print(json.dumps({"first": str(args.first), "second": str(args.second), "rtol": args.rtol,
                      "identical": not diffs, "differences": len(diffs), "examples": diffs[:20]}))
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main())
