"""Converting many motion files to canonical takes, in parallel, with an on-disk cache.

The cache is keyed by a hash of the dataset name, the conversion settings and every input's
name, fingerprint and labels, so a changed file, label or setting builds anew. Entries are
written atomically (a temporary folder renamed into place).
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import shutil
import tempfile
from collections.abc import Mapping
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.canonical import to_canonical_positions
from stylemotion.datasets.base import Take, TakeSet
from stylemotion.io.bvh import parse_bvh
from stylemotion.io.errors import MotionDataError
from stylemotion.io.sources import FileSource

log = logging.getLogger(__name__)

#: Bump when the conversion code changes what it produces, to invalidate old caches.
CACHE_FORMAT = 1


@dataclass(frozen=True)
class ConversionSettings:
    """How files become canonical positions (see :func:`stylemotion.canonical.to_canonical_positions`).

    Attributes:
        fps: target frame rate.
        joint_map: built-in map name, YAML path, inline mapping, or None to auto-detect.
        unit_scale: metres per file unit, a unit name, or None to detect from the skeleton.
        up_axis: ``"y"`` or ``"z"``.
    """

    fps: float = 30.0
    joint_map: str | Mapping[str, str] | None = None
    unit_scale: float | str | None = None
    up_axis: str = "y"

    def as_key(self) -> dict[str, Any]:
        data = asdict(self)
        if isinstance(self.joint_map, Mapping):
            data["joint_map"] = dict(sorted(self.joint_map.items()))
        elif isinstance(self.joint_map, str) and Path(self.joint_map).is_file():
            data["joint_map_text"] = Path(self.joint_map).read_text()
        return data


def load_canonical_positions(source: FileSource, settings: ConversionSettings) -> np.ndarray:
    """``(frames, 21, 3)`` float32 canonical positions (metres, Y up) of one BVH source."""
    motion = parse_bvh(source.read_bytes(), source.name)
    return to_canonical_positions(
        motion, joint_map=settings.joint_map, fps=settings.fps,
        unit_scale=settings.unit_scale, up_axis=settings.up_axis,
    )


@dataclass(frozen=True)
class TakeSpec:
    """A take to build: its source and the labels its dataset assigned."""

    name: str
    source: FileSource
    labels: dict[str, str] = field(default_factory=dict)


class DatasetBuildError(MotionDataError):
    """Some inputs of a dataset could not be converted; lists every one of them."""

    def __init__(self, dataset: str, failures: list[tuple[str, str]]):
        self.failures = failures
        lines = "\n".join(f"  {msg}" for _, msg in failures)
        super().__init__(
            dataset,
            f"{len(failures)} broken input file(s):\n{lines}\n"
            "(set skip_broken=true to build without them; the skipped files are then reported)",
        )


def _convert(args: tuple[TakeSpec, ConversionSettings]) -> tuple[str, np.ndarray | None, str | None]:
    spec, settings = args
    try:
        positions = load_canonical_positions(spec.source, settings)
        if positions.shape[0] < 2:
            raise MotionDataError(spec.source.name, f"only {positions.shape[0]} frame(s) at "
                                  f"{settings.fps} fps; a take needs at least 2")
        return spec.name, positions, None
    except MotionDataError as exc:
        return spec.name, None, str(exc)


def default_cache_dir() -> Path:
    """``$STYLEMOTION_CACHE`` or ``~/.cache/stylemotion``."""
    return Path(os.environ.get("STYLEMOTION_CACHE", Path.home() / ".cache" / "stylemotion"))


def cache_key(dataset: str, specs: list[TakeSpec], settings: ConversionSettings,
              label_failures: list[tuple[str, str]], skip_broken: bool) -> str:
    """Hex digest identifying this exact build."""
    h = hashlib.sha256()
    h.update(json.dumps({"format": CACHE_FORMAT, "dataset": dataset, "settings": settings.as_key(),
                         "skip_broken": skip_broken, "label_failures": label_failures},
                        sort_keys=True, default=str).encode())
    for spec in specs:
        h.update(json.dumps([spec.name, spec.source.name, spec.source.fingerprint(),
                             sorted(spec.labels.items())]).encode())
    return h.hexdigest()[:32]


def build_takeset(
    dataset: str,
    specs: list[TakeSpec],
    settings: ConversionSettings,
    label_failures: list[tuple[str, str]] | None = None,
    skip_broken: bool = False,
    cache_dir: str | os.PathLike | None = None,
    use_cache: bool = True,
    workers: int | None = None,
) -> TakeSet:
    """Convert ``specs`` into a :class:`TakeSet`, or load it from the cache.

    Args:
        dataset: dataset name, part of the cache key and of messages.
        specs: takes to convert.
        settings: conversion settings.
        label_failures: ``(source, message)`` pairs the dataset already found broken (labels).
        skip_broken: if False (default) any broken input raises :class:`DatasetBuildError` listing
            every broken file; if True they are skipped and reported in ``TakeSet.skipped``.
        cache_dir: cache folder (default :func:`default_cache_dir`).
        use_cache: read and write the cache.
        workers: processes for conversion (default: all cores, at most len(specs)).
    """
    label_failures = list(label_failures or [])
    if not skip_broken and label_failures:
        raise DatasetBuildError(dataset, label_failures)
    cache_root = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    key = cache_key(dataset, specs, settings, label_failures, skip_broken)
    entry = cache_root / f"{dataset}-{key}"
    if use_cache and (entry / "index.json").is_file():
        return _read_cache(entry, dataset)

    failures = list(label_failures)
    converted: dict[str, np.ndarray] = {}
    jobs = [(spec, settings) for spec in specs]
    n_workers = max(1, min(workers or os.cpu_count() or 1, len(jobs)))
    if n_workers == 1:
        results = map(_convert, jobs)
    else:
        pool = ProcessPoolExecutor(max_workers=n_workers)
        results = pool.map(_convert, jobs, chunksize=max(1, len(jobs) // (n_workers * 16)))
    try:
        for (spec, _), (name, positions, error) in zip(jobs, results):
            if error is not None:
                failures.append((spec.source.name, error))
            else:
                converted[name] = positions
    finally:
        if n_workers > 1:
            pool.shutdown()
    failures = [f for f in failures if f[1]]
    if failures and not skip_broken:
        raise DatasetBuildError(dataset, failures)
    if failures:
        log.warning("%s: skipped %d broken input file(s): %s", dataset, len(failures),
                    "; ".join(m for _, m in failures))
    takes = [Take(s.name, converted[s.name], settings.fps, dict(s.labels), s.source.name)
             for s in sorted(specs, key=lambda s: s.name) if s.name in converted]
    takeset = TakeSet(dataset, takes, settings.fps, skipped=failures)
    if use_cache:
        _write_cache(entry, takeset)
    return takeset


def _write_cache(entry: Path, takeset: TakeSet) -> None:
    entry.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{entry.name}.", dir=entry.parent))
    try:
        stops = np.cumsum([t.num_frames for t in takeset.takes])
        positions = (np.concatenate([t.positions for t in takeset.takes]) if takeset.takes
                     else np.zeros((0, 21, 3), np.float32))
        np.save(tmp / "positions.npy", positions.astype(np.float32))
        index = {
            "format": CACHE_FORMAT, "dataset": takeset.name, "fps": takeset.fps,
            "takes": [{"name": t.name, "labels": t.labels, "source": t.source,
                       "start": int(stop - t.num_frames), "stop": int(stop)}
                      for t, stop in zip(takeset.takes, stops)],
            "skipped": takeset.skipped,
        }
        (tmp / "index.json").write_text(json.dumps(index))
        try:
            os.replace(tmp, entry)
        except OSError:  # another process wrote the same entry first: keep theirs
            shutil.rmtree(tmp, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def _read_cache(entry: Path, dataset: str) -> TakeSet:
    index = json.loads((entry / "index.json").read_text())
    positions = np.load(entry / "positions.npy")
    takes = [Take(t["name"], positions[t["start"]:t["stop"]], index["fps"], t["labels"], t["source"])
             for t in index["takes"]]
    skipped = [tuple(s) for s in index["skipped"]]
    if skipped:
        log.warning("%s (cached): %d broken input file(s) were skipped", dataset, len(skipped))
    return TakeSet(dataset, takes, index["fps"], skipped=skipped)
