"""Compare two JSON outputs (two files, or two folders of them) number for number.

    python scripts/compare_reports.py OLD NEW [--rtol 1e-6] [--atol 1e-9] [--ignore KEY ...]

OLD and NEW are two JSON files (``report.json``, ``metrics.json``, …) or two folders: every ``*.json``
(and ``*.jsonl``, line by line) under them is matched by relative path and compared; any other file
is only checked to be present on both sides. Values are compared recursively: floats within
``|old - new| <= atol + rtol * |new|``, everything else exactly. A NaN (or ±inf) in OLD against
``null`` in NEW is the new JSON writer's policy (``stylemotion/io/jsonfile.py`` writes non-finite
numbers as null); it is reported in its own ``nan→null`` category and is not a failure.

Ignored by default, because they differ between any two runs: provenance and run records
(``meta``, ``provenance``, ``git_commit``, ``time``, ``run_id``, ``command``, ``hostname``,
``load_average*``), durations (``seconds``, ``timing_s`` and any key ending in ``_s`` or
``_seconds``), absolute paths (two strings that both start with ``/`` are not compared) and TensorBoard's
event files (named by time and process id).
``--ignore`` adds key names or ``fnmatch`` patterns (``--ignore 'loss*'``); ``--no-default-ignores``
drops the defaults. Prints one line per difference (JSON path, old, new) and a summary line; exits 1
if anything differs beyond tolerance (or a file is missing on one side), 0 otherwise.
"""

from __future__ import annotations

import argparse
import fnmatch
import json
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

DEFAULT_IGNORES: tuple[str, ...] = (
    "meta", "provenance", "git_commit", "commit", "time", "timestamp", "started", "finished",
    "run_id", "command", "argv", "hostname", "host", "load_average*", "python", "torch_version",
    "seconds", "timing_s", "*_s", "*_seconds", "elapsed*", "duration*", "wall*",
    "events.out.tfevents.*",  # TensorBoard names its files by time, host and process id
)
JSON_SUFFIXES = (".json", ".jsonl")


@dataclass
class Result:
    """Differences found, by category: ``differ`` (failures), ``nan_null`` and ``ignored`` (not failures)."""

    differ: list[tuple[str, Any, Any]] = field(default_factory=list)
    nan_null: list[tuple[str, Any, Any]] = field(default_factory=list)
    ignored: int = 0
    compared: int = 0

    def merge(self, other: Result) -> None:
        self.differ += other.differ
        self.nan_null += other.nan_null
        self.ignored += other.ignored
        self.compared += other.compared


def _is_ignored(key: str, patterns: tuple[str, ...]) -> bool:
    return any(fnmatch.fnmatchcase(key, pattern) for pattern in patterns)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _non_finite(value: Any) -> bool:
    return isinstance(value, float) and not math.isfinite(value)


def compare(old: Any, new: Any, *, rtol: float = 1e-6, atol: float = 1e-9,
            ignore: tuple[str, ...] = DEFAULT_IGNORES, where: str = "$") -> Result:
    """Compare two JSON values recursively; ``where`` is the JSON path of ``old``/``new``."""
    result = Result()
    if isinstance(old, dict) and isinstance(new, dict):
        for key in list(old) + [k for k in new if k not in old]:
            path = f"{where}.{key}"
            if _is_ignored(str(key), ignore):
                result.ignored += 1
            elif key not in new:
                result.differ.append((path, old[key], "<missing>"))
            elif key not in old:
                result.differ.append((path, "<missing>", new[key]))
            else:
                result.merge(compare(old[key], new[key], rtol=rtol, atol=atol, ignore=ignore, where=path))
        return result
    if isinstance(old, list) and isinstance(new, list):
        if len(old) != len(new):
            result.differ.append((f"{where}.length", len(old), len(new)))
        for i, (a, b) in enumerate(zip(old, new)):
            result.merge(compare(a, b, rtol=rtol, atol=atol, ignore=ignore, where=f"{where}[{i}]"))
        return result
    result.compared += 1
    if _non_finite(old) and new is None:
        result.nan_null.append((where, old, new))
    elif _is_number(old) and _is_number(new):
        same = (old == new or (math.isnan(old) and math.isnan(new))
                or (math.isfinite(old) and math.isfinite(new) and abs(old - new) <= atol + rtol * abs(new)))
        if not same:
            result.differ.append((where, old, new))
    elif isinstance(old, str) and isinstance(new, str) and old.startswith("/") and new.startswith("/"):
        result.ignored += 1  # absolute paths: the two runs write to different folders
    elif old != new or type(old) is not type(new):
        result.differ.append((where, old, new))
    return result


def load_json(path: Path) -> Any:
    """A ``.json`` file's value, or a ``.jsonl`` file's lines as a list."""
    text = path.read_text()
    if path.suffix == ".jsonl":
        return [json.loads(line) for line in text.splitlines() if line.strip()]
    return json.loads(text)  # json accepts NaN/Infinity, as the old writers wrote them


def compare_paths(old: Path, new: Path, *, rtol: float, atol: float, ignore: tuple[str, ...]) -> Result:
    """Compare two JSON files, or two folders (JSON files by relative path, other files by presence)."""
    if old.is_file() and new.is_file():
        return compare(load_json(old), load_json(new), rtol=rtol, atol=atol, ignore=ignore, where=old.name)
    result = Result()
    old_files = {p.relative_to(old).as_posix() for p in old.rglob("*") if p.is_file()}
    new_files = {p.relative_to(new).as_posix() for p in new.rglob("*") if p.is_file()}
    for rel in sorted(old_files | new_files):
        if _is_ignored(Path(rel).name, ignore):
            result.ignored += 1
        elif rel not in new_files:
            result.differ.append((rel, "<file>", "<missing>"))
        elif rel not in old_files:
            result.differ.append((rel, "<missing>", "<file>"))
        elif rel.endswith(JSON_SUFFIXES):
            result.merge(compare(load_json(old / rel), load_json(new / rel), rtol=rtol, atol=atol,
                                 ignore=ignore, where=rel))
    return result


def _short(value: Any, limit: int = 120) -> str:
    text = json.dumps(value) if not isinstance(value, str) else value
    return text if len(text) <= limit else text[: limit - 1] + "…"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("old", type=Path, help="the old JSON file or folder")
    parser.add_argument("new", type=Path, help="the new JSON file or folder")
    parser.add_argument("--rtol", type=float, default=1e-6, help="relative tolerance for numbers (1e-6)")
    parser.add_argument("--atol", type=float, default=1e-9, help="absolute tolerance for numbers (1e-9)")
    parser.add_argument("--ignore", nargs="*", default=[], metavar="KEY",
                        help="more key names or fnmatch patterns to skip (also matched against file names)")
    parser.add_argument("--no-default-ignores", action="store_true", help="compare run records too")
    args = parser.parse_args(argv)
    for path in (args.old, args.new):
        if not path.exists():
            parser.error(f"{path} does not exist")
    ignore = tuple(args.ignore) + (() if args.no_default_ignores else DEFAULT_IGNORES)
    result = compare_paths(args.old, args.new, rtol=args.rtol, atol=args.atol, ignore=ignore)
    for path, old, new in result.nan_null:
        print(f"nan→null {path}: {_short(old)} -> {_short(new)}")
    for path, old, new in result.differ:
        print(f"DIFFER   {path}: {_short(old)} -> {_short(new)}")
    print(f"summary: {'identical' if not result.differ else 'DIFFERENT'}; {result.compared} values compared, "
          f"{len(result.differ)} differ, {len(result.nan_null)} nan→null, {result.ignored} ignored "
          f"(rtol={args.rtol}, atol={args.atol})")
    return 1 if result.differ else 0


if __name__ == "__main__":
    sys.exit(main())
