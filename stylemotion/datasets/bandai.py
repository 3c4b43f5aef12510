"""The Bandai-Namco Research Motion dataset (folder or ``data.zip``).

File names are ``dataset-2_{content}_{style}_{take}.bvh`` with a ``.json`` label file beside each
(``{"content": i, "style": j}``), whose indices refer to ``cfg/content_label.txt`` and
``cfg/style_label.txt`` (lines like ``dataset-2_walk``). Both must agree; a disagreement is an
error naming the file and the key. Take names are the file stems (safe file names as they
are); the same stem in two folders of the dataset is refused, naming both paths.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

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

FILE_NAME = re.compile(r"^(?P<prefix>dataset-\d+)_(?P<content>[a-z-]+)_(?P<style>[a-z]+)_(?P<take>\d+)$")


def find_label_tables(root: Path, label_dir: str | os.PathLike | None = None) -> tuple[list[str], list[str]]:
    """Content and style label tables (index → name without the ``dataset-N_`` prefix)."""
    candidates = [Path(label_dir)] if label_dir else [
        root / "cfg", root.parent / "cfg", root.parent.parent / "cfg"]
    for folder in candidates:
        content, style = folder / "content_label.txt", folder / "style_label.txt"
        if content.is_file() and style.is_file():
            return _read_table(content), _read_table(style)
    raise MotionDataError(str(root), "label tables content_label.txt and style_label.txt not found in "
                          + ", ".join(str(c) for c in candidates) + " (set data.label_dir)")


def _read_table(path: Path) -> list[str]:
    try:
        text = path.read_bytes().decode("utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise MotionDataError(str(path), f"cannot read label table ({exc})") from None
    names = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        line = line.strip()
        if not line:
            continue
        match = re.fullmatch(r"dataset-\d+_(\S+)", line)
        if match is None:
            raise MotionDataError(str(path), f"expected a label like 'dataset-2_walk', found {line!r}", lineno)
        names.append(match.group(1))
    return names


def bandai_labels(source: FileSource, contents: list[str], styles: list[str],
                  max_file_mb: float | None = None) -> dict[str, str]:
    """Labels of one file from its name, checked against its JSON label file."""
    match = FILE_NAME.match(source.stem)
    if match is None:
        raise MotionDataError(source.name, "file name does not follow dataset-N_{content}_{style}_{take}.bvh")
    labels = {"content": match["content"], "style": match["style"], "take": match["take"]}
    json_source = source.sibling(".json")
    if not json_source.exists():
        raise MotionDataError(json_source.name, "label file missing")
    try:
        data = json.loads(json_source.read_bytes(max_file_mb))
    except json.JSONDecodeError as exc:
        raise MotionDataError(json_source.name, f"label file is not valid JSON ({exc.msg})", exc.lineno) from None
    except UnicodeDecodeError as exc:
        raise MotionDataError(json_source.name, f"label file is not UTF-8 text ({exc.reason})") from None
    if not isinstance(data, dict):
        raise MotionDataError(json_source.name, f"label file holds a {type(data).__name__}, expected an object "
                              '{"content": i, "style": j}')
    for key, table in (("content", contents), ("style", styles)):
        if key not in data:
            raise MotionDataError(json_source.name, f"key {key!r} missing")
        index = data[key]
        if isinstance(index, bool) or not isinstance(index, int) or not 0 <= index < len(table):
            raise MotionDataError(json_source.name, f"key {key!r} = {index!r} is not an index into the "
                                  f"{len(table)} {key} labels")
        if table[index] != labels[key]:
            raise MotionDataError(json_source.name, f"key {key!r} = {index} means {table[index]!r} but the "
                                  f"file name says {labels[key]!r}")
    return labels


def load_bandai(
    root: str | os.PathLike,
    label_dir: str | os.PathLike | None = None,
    contents: list[str] | None = None,
    styles: list[str] | None = None,
    settings: ConversionSettings | None = None,
    skip_broken: bool = False,
    cache_dir: str | os.PathLike | None = None,
    use_cache: bool = True,
    workers: int | None = None,
) -> TakeSet:
    """All (or the selected contents'/styles') takes of the Bandai dataset.

    Args:
        root: the dataset folder or its ``data.zip``.
        label_dir: folder with the label tables (default: ``cfg`` beside or above ``root``).
        contents, styles: keep only these labels (None keeps all).
        settings: conversion settings (default 30 fps, detected units and joint map).
        skip_broken, cache_dir, use_cache, workers: see :func:`build_takeset`.
    """
    check_workers(workers)
    root = Path(root).expanduser()
    if not root.exists():
        raise MotionDataError(str(root), "no such file or folder: data.root is the Bandai data set's folder or its "
                              "data.zip (docs/data.md)")
    sources = list_sources(root, "*.bvh")  # a damaged zip is named before its label tables are looked for
    try:
        content_table, style_table = find_label_tables(root if root.is_dir() else root.parent, label_dir)
    except MotionDataError as exc:  # named after data.root, the value the user gave
        raise MotionDataError(str(root), "not the Bandai data set as downloaded (its data.zip beside the "
                              f"label tables): {exc.detail}") from None
    for key, wanted, table in (("content", contents, content_table), ("style", styles, style_table)):
        unknown = sorted(set(wanted or []) - set(table))
        if unknown:
            raise MotionDataError(str(root), f"unknown {key} {unknown}; the dataset has {table}")
    settings = settings or ConversionSettings()
    specs: list[TakeSpec] = []
    failures: list[tuple[str, str]] = []
    for source in sources:
        try:
            labels = bandai_labels(source, content_table, style_table, settings.max_file_mb)
            name = safe_name(source.stem, f"take name of {source.name}")
        except Exception as exc:  # noqa: BLE001 - one file's failure of any kind is reported for that file
            failures.append((source.name, describe_failure(source.name, exc)))
            continue
        if (contents and labels["content"] not in contents) or (styles and labels["style"] not in styles):
            continue
        specs.append(TakeSpec(name, source, labels))
    return build_takeset("bandai", specs, settings, failures, skip_broken, cache_dir, use_cache, workers)
