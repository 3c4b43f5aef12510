"""Converting many motion files to canonical takes, in parallel, with an on-disk cache.

Bad input never sinks or corrupts a build: any failure of one file (a malformed BVH, a limit, a
``RecursionError``, …) is recorded for that file, and the build either stops listing every broken
file or, with ``skip_broken``, goes on without them and reports them. Two files that would give the
same take name are both refused, naming both paths.

The cache is keyed by a hash of the dataset name, the conversion settings and every input's
name, content fingerprint (see :meth:`FileSource.fingerprint`) and labels, so a changed file,
label or setting builds anew. Entries are written atomically (a temporary folder renamed into
place) with a CRC of their positions; a corrupt entry is rebuilt with a warning naming it.
"""

from __future__ import annotations

import hashlib
import json
import logging
import numbers
import os
import shutil
import tempfile
import warnings
import zlib
from collections.abc import Iterable, Mapping
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.config import ConfigError
from stylemotion.datasets.base import Take, TakeSet
from stylemotion.datasets.canonical import DEFAULT_MAX_FRAMES, to_canonical_positions
from stylemotion.io.bvh import DEFAULT_MAX_JOINT_FRAMES, parse_bvh
from stylemotion.io.errors import MotionDataError, MotionDataWarning
from stylemotion.io.outputs import safe_name
from stylemotion.io.sources import FileSource
from stylemotion.motion import Motion

log = logging.getLogger(__name__)

#: Bump when the conversion code or the entry layout changes, to invalidate old caches.
CACHE_FORMAT = 2
#: Default cap on the size of one input file (uncompressed), MB.
DEFAULT_MAX_FILE_MB = 256.0
#: What a broken build tells the user to do.
SKIP_HINT = "Set data.skip_broken=true to build without them; the skipped files are then reported."


class CacheWarning(UserWarning):
    """A cache entry could not be used or written; the dataset is rebuilt (the message names it)."""


def check_positive(value: Any, key: str, integer: bool, allow_none: bool = True) -> None:
    """Raise :class:`~stylemotion.config.ConfigError` naming ``key`` unless ``value`` is a positive finite number
    (or None)."""
    if value is None and allow_none:
        return
    kind = numbers.Integral if integer else numbers.Real
    if isinstance(value, bool) or not isinstance(value, kind) or not np.isfinite(value) or value <= 0:
        what = "a whole number ≥ 1" if integer else "a positive finite number"
        raise ConfigError(f"{key} must be {what}{' or null' if allow_none else ''}, got {value!r}")


def check_workers(workers: Any) -> int | None:
    """``workers`` as an int ≥ 1 or None (all cores); ValueError naming ``data.workers`` otherwise."""
    check_positive(workers, "data.workers (processes; null = all cores)", integer=True)
    return None if workers is None else int(workers)


def check_flag(value: Any, key: str) -> bool:
    """``value`` if it is a bool; ValueError naming ``key`` otherwise (``'abc'`` is not true)."""
    if not isinstance(value, (bool, np.bool_)):
        raise ConfigError(f"{key} must be true or false, got {value!r}")
    return bool(value)


@dataclass(frozen=True)
class ConversionSettings:
    """How files become canonical positions (see :func:`stylemotion.datasets.canonical.to_canonical_positions`).

    Attributes:
        fps: target frame rate.
        joint_map: built-in map name, YAML path, inline mapping, or None to auto-detect.
        unit_scale: metres per file unit, a unit name, or None to detect from the skeleton.
        up_axis: ``"y"`` or ``"z"``.
        max_file_mb: largest input file, MB uncompressed (checked before reading or inflating).
        max_frames: most frames of one take after resampling to ``fps`` (checked before resampling).
        max_joint_frames: most frames × skeleton joints of one motion, at the file's rate and
            after resampling (bounds the memory of one conversion).
    """

    fps: float = 30.0
    joint_map: str | Mapping[str, str] | None = None
    unit_scale: float | str | None = None
    up_axis: str = "y"
    max_file_mb: float | None = DEFAULT_MAX_FILE_MB
    max_frames: int | None = DEFAULT_MAX_FRAMES
    max_joint_frames: int | None = DEFAULT_MAX_JOINT_FRAMES

    def __post_init__(self) -> None:
        """ValueError naming the ``data.`` key of a bad frame rate or limit."""
        check_positive(self.fps, "data.fps", integer=False, allow_none=False)
        check_positive(self.max_file_mb, "data.max_file_mb", integer=False)
        check_positive(self.max_frames, "data.max_frames", integer=True)
        check_positive(self.max_joint_frames, "data.max_joint_frames", integer=True)
        # unit_scale and up_axis are checked per file by to_canonical_positions (MotionDataError).

    def as_key(self) -> dict[str, Any]:
        data = asdict(self)
        if isinstance(self.joint_map, Mapping):
            data["joint_map"] = dict(sorted(self.joint_map.items()))
        elif isinstance(self.joint_map, str) and Path(self.joint_map).is_file():
            data["joint_map_text"] = Path(self.joint_map).read_text()
        return data


def load_canonical_positions(source: FileSource, settings: ConversionSettings) -> np.ndarray:
    """``(frames, 21, 3)`` float32 canonical positions (metres, Y up) of one BVH source.

    Raises:
        MotionDataError: naming the file (LimitError for a file over the settings' limits).
    """
    motion = parse_bvh(source.read_bytes(settings.max_file_mb), source.name, settings.max_joint_frames)
    return convert_motion(motion, settings)


def convert_motion(motion: Motion, settings: ConversionSettings) -> np.ndarray:
    """``(frames, 21, 3)`` float32 canonical positions of a parsed motion, converted as every dataset
    converts its files (joint map, units, up axis, resampling to ``settings.fps``, limits).

    Raises:
        MotionDataError: naming the motion's source.
    """
    return to_canonical_positions(
        motion, joint_map=settings.joint_map, fps=settings.fps, unit_scale=settings.unit_scale,
        up_axis=settings.up_axis, max_frames=settings.max_frames, max_joint_frames=settings.max_joint_frames,
    )


@dataclass(frozen=True)
class TakeSpec:
    """A take to build: its source and the labels its dataset assigned.

    ``name`` must be a safe file-name component (:func:`stylemotion.io.outputs.safe_name`);
    the source keeps the original path for messages.
    """

    name: str
    source: FileSource
    labels: dict[str, str] = field(default_factory=dict)


class DatasetBuildError(MotionDataError):
    """Some inputs of a dataset could not be converted; lists every one of them, in one line (a command's
    error is one line), separated by ``;``."""

    def __init__(self, dataset: str, failures: list[tuple[str, str]]):
        self.failures = failures
        listed = "; ".join(" ".join(msg.split()) for _, msg in failures)
        super().__init__(dataset, f"{len(failures)} broken input file(s): {listed}. {SKIP_HINT}")


def describe_failure(source: str, exc: BaseException) -> str:
    """One line naming the file, the exception type (unless a MotionDataError naming it) and the message."""
    if isinstance(exc, MotionDataError) and str(exc).startswith(source):
        return str(exc)
    message = str(exc) or repr(exc)
    return f"{source}: {type(exc).__name__}: {message}"


#: What one conversion returns: (take name, positions or None, failure or None, warning messages).
ConvertResult = tuple[str, "np.ndarray | None", "str | None", list[str]]


def _convert(args: tuple[TakeSpec, ConversionSettings]) -> ConvertResult:
    """Convert one take; any exception becomes a failure line naming the file (never raised)."""
    spec, settings = args
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            positions = load_canonical_positions(spec.source, settings)
            if positions.shape[0] < 2:
                raise MotionDataError(spec.source.name, f"only {positions.shape[0]} frame(s) at "
                                      f"{settings.fps} fps; a take needs at least 2")
            result: tuple[np.ndarray | None, str | None] = (positions, None)
        except Exception as exc:  # noqa: BLE001 - one file's failure of any kind must not sink the build
            result = (None, describe_failure(spec.source.name, exc))
    messages = [str(w.message) for w in caught if issubclass(w.category, MotionDataWarning)]
    for w in caught:
        if not issubclass(w.category, MotionDataWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return spec.name, result[0], result[1], messages


def default_cache_dir() -> Path:
    """``$STYLEMOTION_CACHE`` or ``~/.cache/stylemotion``."""
    return Path(os.environ.get("STYLEMOTION_CACHE", Path.home() / ".cache" / "stylemotion"))


def cache_key(dataset: str, specs: list[TakeSpec], settings: ConversionSettings,
              label_failures: list[tuple[str, str]], skip_broken: bool,
              fingerprints: list[str] | None = None) -> str:
    """Hex digest identifying this exact build (``fingerprints``: one per spec, computed if None)."""
    if fingerprints is None:
        fingerprints = [spec.source.fingerprint(settings.max_file_mb) for spec in specs]
    h = hashlib.sha256()
    h.update(json.dumps({"format": CACHE_FORMAT, "dataset": dataset, "settings": settings.as_key(),
                         "skip_broken": skip_broken, "label_failures": label_failures},
                        sort_keys=True, default=str).encode())
    for spec, fingerprint in zip(specs, fingerprints):
        h.update(json.dumps([spec.name, spec.source.name, fingerprint, sorted(spec.labels.items())]).encode())
    return h.hexdigest()[:32]


def _is_safe(name: str) -> bool:
    try:
        return safe_name(name) == name
    except ValueError:
        return False


def find_duplicates(specs: list[TakeSpec]) -> tuple[list[TakeSpec], list[tuple[str, str]]]:
    """Specs whose take name is unique (ignoring case), and a failure for every one that is not.

    Two sources that would give the same take (or, on a case-insensitive file system, the same
    file) are both refused, each failure naming every path involved.
    """
    groups: dict[str, list[TakeSpec]] = {}
    for spec in specs:
        groups.setdefault(spec.name.lower(), []).append(spec)
    unique, failures = [], []
    for spec in specs:
        group = groups[spec.name.lower()]
        if len(group) == 1:
            unique.append(spec)
            continue
        others = ", ".join(s.source.name for s in group if s is not spec)
        failures.append((spec.source.name, f"{spec.source.name}: take name {spec.name!r} is also the take name "
                         f"of {others}; rename one of them (take names must be unique, ignoring case)"))
    return unique, failures


def _fingerprints(specs: list[TakeSpec], settings: ConversionSettings
                  ) -> tuple[list[TakeSpec], list[str], list[tuple[str, str]]]:
    """Specs whose source could be fingerprinted, their fingerprints, and failures for the rest."""
    kept, prints, failures = [], [], []
    for spec in specs:
        try:
            prints.append(spec.source.fingerprint(settings.max_file_mb))
            kept.append(spec)
        except Exception as exc:  # noqa: BLE001 - reported per file
            failures.append((spec.source.name, describe_failure(spec.source.name, exc)))
    return kept, prints, failures


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
            every broken file (all are tried first); if True they are skipped and reported in
            ``TakeSet.skipped``.
        cache_dir: cache folder (default :func:`default_cache_dir`).
        use_cache: read and write the cache.
        workers: processes for conversion (default: all cores, at most len(specs)).

    Warns:
        MotionDataWarning: for files that convert but look wrong (each names its file), also when
            the takes come from the cache; CacheWarning for a corrupt cache entry (rebuilt).
    """
    workers = check_workers(workers)
    skip_broken = check_flag(skip_broken, "data.skip_broken")
    use_cache = check_flag(use_cache, "data.use_cache")
    unsafe = [s.name for s in specs if not _is_safe(s.name)]
    if unsafe:
        raise ValueError(f"{dataset}: take names must be safe file names (stylemotion.io.outputs.safe_name), "
                         f"got {unsafe[:5]}")
    specs, duplicates = find_duplicates(list(specs))
    specs, prints, unreadable = _fingerprints(specs, settings)
    failures = list(label_failures or []) + duplicates + unreadable
    cache_root = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    entry = cache_root / f"{dataset}-{cache_key(dataset, specs, settings, failures, skip_broken, prints)}"
    if use_cache and entry.exists():
        cached = _read_cache_or_discard(entry, dataset)
        if cached is not None:
            return cached

    converted, conversion_failures, notes = _convert_all(specs, settings, workers)
    failures += conversion_failures
    if failures and not skip_broken:
        raise DatasetBuildError(dataset, failures)
    if failures:
        log.warning("%s: skipped %d broken input file(s): %s", dataset, len(failures),
                    "; ".join(m for _, m in failures))
    takes = [Take(s.name, converted[s.name], settings.fps, dict(s.labels), s.source.name)
             for s in sorted(specs, key=lambda s: s.name) if s.name in converted]
    takeset = TakeSet(dataset, takes, settings.fps, skipped=failures, warnings=notes)
    if use_cache:
        _write_cache(entry, takeset)
    return takeset


def _convert_all(specs: list[TakeSpec], settings: ConversionSettings, workers: int | None
                 ) -> tuple[dict[str, np.ndarray], list[tuple[str, str]], list[str]]:
    """Positions by take name, failures and warning messages (each warning also issued here)."""
    jobs = [(spec, settings) for spec in specs]
    n_workers = max(1, min(workers or os.cpu_count() or 1, len(jobs)))
    converted: dict[str, np.ndarray] = {}
    failures: list[tuple[str, str]] = []
    notes: list[str] = []
    pool = ProcessPoolExecutor(max_workers=n_workers) if n_workers > 1 else None
    try:
        results: Iterable[ConvertResult] = map(_convert, jobs) if pool is None else \
            pool.map(_convert, jobs, chunksize=max(1, len(jobs) // (n_workers * 16)))
        for (spec, _), (name, positions, error, messages) in zip(jobs, results):
            notes.extend(messages)
            if error is not None:
                failures.append((spec.source.name, error))
            else:
                converted[name] = positions
    finally:
        if pool is not None:
            pool.shutdown()
    _issue(notes)
    return converted, failures, notes


def _issue(notes: list[str]) -> None:
    for note in notes:
        warnings.warn(note, MotionDataWarning, stacklevel=3)


def _write_cache(entry: Path, takeset: TakeSet) -> None:
    """Write ``takeset`` to ``entry`` atomically; a cache that cannot be written only warns."""
    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{entry.name}.", dir=entry.parent))
    except OSError as exc:
        warnings.warn(f"{entry}: cannot write the dataset cache ({exc}); the dataset is built but not cached",
                      CacheWarning, stacklevel=3)
        return
    try:
        stops = np.cumsum([t.num_frames for t in takeset.takes])
        positions = (np.concatenate([t.positions for t in takeset.takes]) if takeset.takes
                     else np.zeros((0, 21, 3), np.float32)).astype(np.float32)
        np.save(tmp / "positions.npy", positions)
        index = {
            "format": CACHE_FORMAT, "dataset": takeset.name, "fps": takeset.fps,
            "positions_crc32": zlib.crc32(np.ascontiguousarray(positions)), "frames": int(positions.shape[0]),
            "takes": [{"name": t.name, "labels": t.labels, "source": t.source,
                       "start": int(stop - t.num_frames), "stop": int(stop)}
                      for t, stop in zip(takeset.takes, stops)],
            "skipped": takeset.skipped,
            "warnings": takeset.warnings,
        }
        (tmp / "index.json").write_text(json.dumps(index))
        try:
            os.replace(tmp, entry)
        except OSError:  # another process wrote the same entry first: keep theirs
            shutil.rmtree(tmp, ignore_errors=True)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        warnings.warn(f"{entry}: cannot write the dataset cache ({exc}); the dataset is built but not cached",
                      CacheWarning, stacklevel=3)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def _read_cache_or_discard(entry: Path, dataset: str) -> TakeSet | None:
    """The cached TakeSet, or None after removing a corrupt entry with a :class:`CacheWarning`."""
    try:
        return _read_cache(entry, dataset)
    except Exception as exc:  # noqa: BLE001 - any damage to the entry means: rebuild it
        warnings.warn(f"{entry}: corrupt dataset cache entry ({type(exc).__name__}: {exc}); rebuilding it",
                      CacheWarning, stacklevel=3)
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry, ignore_errors=True)
        else:
            entry.unlink(missing_ok=True)
        return None


def _read_cache(entry: Path, dataset: str) -> TakeSet:
    """Load a cache entry, checking its layout and the CRC of its positions (ValueError if damaged)."""
    index = json.loads((entry / "index.json").read_text())
    if not isinstance(index, dict) or index.get("format") != CACHE_FORMAT:
        raise ValueError(f"index.json has format {index.get('format') if isinstance(index, dict) else None!r}, "
                         f"expected {CACHE_FORMAT}")
    positions = np.load(entry / "positions.npy", allow_pickle=False)
    if positions.dtype != np.float32 or positions.ndim != 3 or positions.shape[1:] != (21, 3):
        raise ValueError(f"positions.npy holds {positions.dtype} {positions.shape}, expected float32 (frames, 21, 3)")
    if positions.shape[0] != index["frames"] or zlib.crc32(positions) != index["positions_crc32"]:
        raise ValueError("positions.npy does not match the CRC and frame count in index.json")
    takes = []
    for t in index["takes"]:
        start, stop = int(t["start"]), int(t["stop"])
        if not 0 <= start < stop <= positions.shape[0]:
            raise ValueError(f"take {t['name']!r} spans frames {start}:{stop} of {positions.shape[0]}")
        takes.append(Take(str(t["name"]), positions[start:stop], index["fps"], dict(t["labels"]), str(t["source"])))
    skipped = [(str(s[0]), str(s[1])) for s in index["skipped"]]
    notes = [str(n) for n in index["warnings"]]
    if skipped:
        log.warning("%s (cached): %d broken input file(s) were skipped", dataset, len(skipped))
    _issue(notes)
    return TakeSet(dataset, takes, index["fps"], skipped=skipped, warnings=notes)
