"""Any labelled folder (or zip) of BVH files.

Labels come either from a regular expression with named groups matched against each file's stem
(e.g. ``(?P<style>[a-z]+)_(?P<content>[a-z]+)_(?P<take>\\d+)``) or from a CSV file with a ``file``
column (the file's stem or its path relative to the root) and one column per label. Content and
style labels become folder and file names downstream, so they must be safe names (an error names
the CSV line, or the file and the pattern, otherwise).
"""

from __future__ import annotations

import csv
import os
import re
from pathlib import Path, PurePosixPath

from stylemotion.config import ConfigError
from stylemotion.datasets.base import TakeSet
from stylemotion.datasets.loading import (
    ConversionSettings,
    TakeSpec,
    build_takeset,
    check_workers,
    describe_failure,
)
from stylemotion.io.errors import MotionDataError
from stylemotion.io.outputs import safe_name
from stylemotion.io.sources import FileSource, list_sources

#: Labels that become folder and file names downstream (reports, per-style runs): must be safe names.
NAME_LABELS = ("content", "style")


def unsafe_label(labels: dict[str, str]) -> tuple[str, str] | None:
    """The first ``(key, value)`` of :data:`NAME_LABELS` that is not a safe file name, or None."""
    for key in NAME_LABELS:
        value = labels.get(key)
        if value is None:
            continue
        try:
            ok = safe_name(value) == value
        except ValueError:
            ok = False
        if not ok:
            return key, value
    return None


def _unsafe_message(key: str, value: str) -> str:
    return (f"{key} label {value!r} is not a safe file name (it names output folders and files): use "
            "letters, digits and ._+- only, not empty and not starting with '.'")


def read_label_csv(path: str | os.PathLike) -> dict[str, dict[str, str]]:
    """``{file stem or relative path: {label: value}}`` from a CSV with a ``file`` column.

    A UTF-8 byte-order mark (as spreadsheet programs write) is accepted.

    Raises:
        MotionDataError: naming the CSV file and line, for a malformed table or a content/style
            label that is not a safe file name.
    """
    path = Path(path).expanduser()
    try:
        with path.open(newline="", encoding="utf-8-sig") as fh:
            reader = csv.DictReader(fh)
            if reader.fieldnames is None or "file" not in reader.fieldnames:
                raise MotionDataError(str(path), f"CSV needs a 'file' column, has {reader.fieldnames}", 1)
            table: dict[str, dict[str, str]] = {}
            for row in reader:
                lineno = reader.line_num
                key = (row.pop("file") or "").strip()
                if not key:
                    raise MotionDataError(str(path), "empty 'file' value", lineno)
                if key in table:
                    raise MotionDataError(str(path), f"file {key!r} listed twice", lineno)
                if any(v is None for v in row.values()) or None in row:
                    raise MotionDataError(str(path), f"row has {len(row) + 1 + len(row.get(None) or [])} "
                                          f"fields, header has {len(reader.fieldnames)}", lineno)
                labels = {k: v.strip() for k, v in row.items()}
                bad = unsafe_label(labels)
                if bad is not None:
                    raise MotionDataError(str(path), _unsafe_message(*bad), lineno)
                table[key] = labels
            return table
    except OSError as exc:
        raise MotionDataError(str(path), f"cannot read label CSV ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise MotionDataError(str(path), f"label CSV is not UTF-8 text ({exc.reason})") from None
    except csv.Error as exc:
        raise MotionDataError(str(path), f"malformed CSV ({exc})") from None


def _compile(pattern: str) -> re.Pattern[str]:
    try:
        return re.compile(pattern)
    except re.error as exc:
        raise ConfigError(f"data.pattern {pattern!r} is not a valid regular expression ({exc})") from None


def load_bvh_folder(
    root: str | os.PathLike,
    pattern: str | None = r"(?P<take>.+)",
    labels_csv: str | os.PathLike | None = None,
    default_labels: dict[str, str] | None = None,
    glob: str = "*.bvh",
    settings: ConversionSettings | None = None,
    skip_broken: bool = False,
    cache_dir: str | os.PathLike | None = None,
    use_cache: bool = True,
    workers: int | None = None,
) -> TakeSet:
    """Takes from every BVH file under ``root`` (folder, single file or zip).

    Take names are the file paths relative to ``root`` without suffix, made safe file names
    (:func:`stylemotion.io.outputs.safe_name`: ``sub/walk.bvh`` → ``sub_walk``); two files whose
    names coincide are both refused, naming both paths.

    Args:
        root: folder, file or zip.
        pattern: regex with named groups matched (fully) against each file stem; a file that does
            not match is a broken input. Ignored when ``labels_csv`` is given.
        labels_csv: CSV with a ``file`` column; every BVH must be listed.
        default_labels: labels every take gets unless the pattern or CSV sets them
            (``content``/``style`` default to ``unknown``).
        glob: file name pattern.
        settings, skip_broken, cache_dir, use_cache, workers: see :func:`build_takeset`.
    """
    settings = settings or ConversionSettings()
    check_workers(workers)
    root_path = Path(root).expanduser()
    base = {"content": "unknown", "style": "unknown", **(default_labels or {})}
    bad = unsafe_label(base)
    if bad is not None:
        raise ConfigError(f"data.default_labels: {_unsafe_message(*bad)}")
    table = read_label_csv(labels_csv) if labels_csv else None
    regex = _compile(pattern) if pattern and table is None else None
    specs: list[TakeSpec] = []
    failures: list[tuple[str, str]] = []
    for source in list_sources(root_path, glob):
        try:
            specs.append(_spec(source, root_path, base, table, labels_csv, regex))
        except Exception as exc:  # noqa: BLE001 - one file's failure of any kind is reported for that file
            failures.append((source.name, describe_failure(source.name, exc)))
    return build_takeset("bvh_folder", specs, settings, failures, skip_broken, cache_dir, use_cache, workers)


def _spec(source: FileSource, root: Path, base: dict[str, str], table: dict[str, dict[str, str]] | None,
          labels_csv: str | os.PathLike | None, regex: re.Pattern[str] | None) -> TakeSpec:
    """The take of one file: its safe name and labels (MotionDataError naming the file otherwise)."""
    if source.member is not None:
        rel = source.member
    else:
        rel = str(Path(source.path).relative_to(root)) if root.is_dir() else Path(source.path).name
    labels = dict(base)
    if table is not None:
        row = table.get(source.stem, table.get(rel))
        if row is None:
            raise MotionDataError(source.name, f"not listed in {labels_csv}")
        labels.update(row)
    elif regex is not None:
        match = regex.fullmatch(source.stem)
        if match is None:
            raise MotionDataError(source.name, f"file name does not match pattern {regex.pattern!r}")
        labels.update({k: v for k, v in match.groupdict().items() if v is not None})
        bad = unsafe_label(labels)
        if bad is not None:
            raise MotionDataError(source.name, f"{_unsafe_message(*bad)} (from the file name by pattern "
                                  f"{regex.pattern!r})")
    labels.setdefault("take", source.stem)
    name = safe_name(str(PurePosixPath(rel.replace("\\", "/")).with_suffix("")), f"take name of {source.name}")
    return TakeSpec(name, source, labels)
