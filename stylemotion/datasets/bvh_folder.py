"""Any labelled folder (or zip) of BVH files.

Labels come either from a regular expression with named groups matched against each file's stem
(e.g. ``(?P<style>[a-z]+)_(?P<content>[a-z]+)_(?P<take>\\d+)``) or from a CSV file with a ``file``
column (the file's stem or its path relative to the root) and one column per label.
"""

from __future__ import annotations

import csv
import os
import re
from pathlib import Path

from stylemotion.datasets.base import TakeSet
from stylemotion.datasets.loading import ConversionSettings, TakeSpec, build_takeset
from stylemotion.io.errors import MotionDataError
from stylemotion.io.sources import list_sources


def read_label_csv(path: str | os.PathLike) -> dict[str, dict[str, str]]:
    """``{file stem or relative path: {label: value}}`` from a CSV with a ``file`` column."""
    path = Path(path)
    try:
        with path.open(newline="") as fh:
            reader = csv.DictReader(fh)
            if reader.fieldnames is None or "file" not in reader.fieldnames:
                raise MotionDataError(str(path), f"CSV needs a 'file' column, has {reader.fieldnames}", 1)
            table: dict[str, dict[str, str]] = {}
            for lineno, row in enumerate(reader, start=2):
                key = (row.pop("file") or "").strip()
                if not key:
                    raise MotionDataError(str(path), "empty 'file' value", lineno)
                if key in table:
                    raise MotionDataError(str(path), f"file {key!r} listed twice", lineno)
                if any(v is None for v in row.values()) or None in row:
                    raise MotionDataError(str(path), f"row has {len(row) + 1 + len(row.get(None) or [])} "
                                          f"fields, header has {len(reader.fieldnames)}", lineno)
                table[key] = {k: v.strip() for k, v in row.items()}
            return table
    except OSError as exc:
        raise MotionDataError(str(path), f"cannot read label CSV ({exc.strerror or exc})") from None


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
    root_path = Path(root)
    base = {"content": "unknown", "style": "unknown", **(default_labels or {})}
    table = read_label_csv(labels_csv) if labels_csv else None
    regex = re.compile(pattern) if pattern and table is None else None
    specs: list[TakeSpec] = []
    failures: list[tuple[str, str]] = []
    names: dict[str, str] = {}
    for source in list_sources(root_path, glob):
        rel = source.member if source.member is not None else str(Path(source.path).relative_to(root_path)) \
            if root_path.is_dir() else Path(source.path).name
        labels = dict(base)
        if table is not None:
            row = table.get(source.stem, table.get(rel))
            if row is None:
                failures.append((source.name, f"{source.name}: not listed in {labels_csv}"))
                continue
            labels.update(row)
        elif regex is not None:
            match = regex.fullmatch(source.stem)
            if match is None:
                failures.append((source.name, f"{source.name}: file name does not match pattern {pattern!r}"))
                continue
            labels.update({k: v for k, v in match.groupdict().items() if v is not None})
        labels.setdefault("take", source.stem)
        name = str(Path(rel).with_suffix(""))
        if name in names:
            failures.append((source.name, f"{source.name}: same take name as {names[name]}"))
            continue
        names[name] = source.name
        specs.append(TakeSpec(name, source, labels))
    return build_takeset("bvh_folder", specs, settings or ConversionSettings(), failures, skip_broken,
                         cache_dir, use_cache, workers)
