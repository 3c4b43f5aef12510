"""Helpers every benchmark suite shares: spreads over seeds, number formatting, tables, the split record.

Suites import this as ``from suites.common import ...`` (``scripts/benchmarks.py`` puts ``scripts/`` on the
path). Protocol: docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import sys
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from stylemotion.io.markdown import md_table as _md_table

__all__ = ["spread", "fmt", "fmt_spread", "fmt_range", "md_table", "provenance_line", "take_split_record",
           "quantiles", "DATA_ROOT"]

#: Where the benchmark data lies (``$STYLEMOTION_DATA`` or ``../shared/data`` beside the repository).
DATA_ROOT = Path(os.environ.get("STYLEMOTION_DATA") or Path(__file__).resolve().parents[3] / "shared" / "data")


@contextmanager
def progress_printed(prefix: str, logger: str = "stylemotion") -> Iterator[None]:
    """Print what ``logger`` (the library) logs at INFO while the block runs, one line each after ``prefix``
    (e.g. ``[seed 0]``); the library reports progress only through :mod:`logging`."""
    handler = logging.StreamHandler(sys.stdout)
    handler.setFormatter(logging.Formatter(f"{prefix} %(message)s"))
    target = logging.getLogger(logger)
    before = target.level
    target.addHandler(handler)
    target.setLevel(logging.INFO)
    try:
        yield
    finally:
        target.removeHandler(handler)
        target.setLevel(before)


def number_above(bound: float, kind: type = int, inclusive: bool = True) -> Callable[[str], Any]:
    """An argparse ``type``: a ``kind`` number ≥ ``bound`` (> ``bound`` when not ``inclusive``); anything else is
    refused by argparse in one line naming the option and the value."""
    def parse(text: str) -> Any:
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {'an integer' if kind is int else 'a number'}") from None
        if not (value >= bound if inclusive else value > bound) or not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{text} is not {'≥' if inclusive else '>'} {bound:g}")
        return value
    return parse


def md_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A Markdown table whose cells may hold ``|`` (escaped, so a cell never splits in two)."""
    def cells(row: Sequence[str]) -> list[str]:
        return [str(c).replace("|", "\\|") for c in row]

    return _md_table(cells(header), [cells(r) for r in rows])


def spread(values: Iterable[float | None]) -> dict[str, Any]:
    """Mean, sample SD, min, max and count of ``values``; ``missing`` counts None/non-finite values, which are
    left out of the statistics but never silently (a suite shows ``missing`` beside the figure)."""
    raw = list(values)
    finite = [float(v) for v in raw if v is not None and math.isfinite(float(v))]
    out: dict[str, Any] = {"n": len(finite), "missing": len(raw) - len(finite)}
    if finite:
        arr = np.asarray(finite)
        out.update(mean=float(arr.mean()), sd=float(arr.std(ddof=1)) if len(arr) > 1 else 0.0,
                   min=float(arr.min()), max=float(arr.max()))
    return out


def capped_log(shares: Iterable[float | None]) -> float:
    """Mean of ``log(min(1, share))`` over ``shares`` (variation as shares of real clips: more than the real clips'
    counts as no more); −inf when one is missing or not positive."""
    values = list(shares)
    if not values or any(v is None or not v > 0 for v in values):
        return -math.inf
    return sum(math.log(min(1.0, v)) for v in values) / len(values)


def mean_capped_log(cases: Sequence[Mapping[str, float | None]], keys: Sequence[str]) -> float:
    """Mean over ``cases`` of :func:`capped_log` of each case's ``keys``; −inf without cases."""
    return sum(capped_log([c[k] for k in keys]) for c in cases) / len(cases) if cases else -math.inf


def quantiles(values: Sequence[float], qs: Sequence[float] = (50, 95, 100)) -> dict[str, float | None]:
    """Percentiles of ``values`` as ``{"p50": …, "p95": …, "p100": …}`` (None for no values)."""
    arr = np.asarray([v for v in values if v is not None], dtype=float)
    return {f"p{q:g}": (float(np.percentile(arr, q)) if arr.size else None) for q in qs}


def fmt(value: float | None, digits: int = 2, unit: str = "") -> str:
    """``value`` with ``digits`` decimals (thousands separated) and ``unit``; an em dash for None."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "—"
    return f"{value:,.{digits}f}{unit}"


def fmt_spread(s: Mapping[str, Any], digits: int = 2, unit: str = "") -> str:
    """``mean ± sd`` over seeds (``(n = k)`` appended when fewer than 3; ``, m missing`` when any was missing)."""
    if not s.get("n"):
        return f"— ({s.get('missing', 0)} missing)"
    text = f"{fmt(s['mean'], digits)} ± {fmt(s['sd'], digits)}{unit}"
    if s["n"] < 3:
        text += f" (n = {s['n']})"
    if s.get("missing"):
        text += f", {s['missing']} missing"
    return text


def fmt_range(s: Mapping[str, Any], digits: int = 2, unit: str = "") -> str:
    """``min–max`` of a :func:`spread`."""
    if not s.get("n"):
        return "—"
    return f"{fmt(s['min'], digits)}–{fmt(s['max'], digits)}{unit}"


def provenance_line(record: Mapping[str, Any]) -> str:
    """One sentence naming the command, commit, date, machine, load and seeds of a results record."""
    m = record.get("machine", {})
    load = record.get("load_average_start") or ["?"]
    load_end = record.get("load_average_end") or ["?"]
    commit = str(record["commit"])
    dirty = len(record.get("uncommitted") or []) if commit.endswith("+dirty") else 0
    commit = commit[:12] + (f" with {dirty} uncommitted file{'s' if dirty != 1 else ''}, listed in the results file"
                            if dirty else "+dirty" if commit.endswith("+dirty") else "")
    return (f"Command: `{record['command']}` (commit {commit}, {record['started'][:10]}, "
            f"{m.get('cpu', '?')}, {m.get('cores', '?')} cores, load {load[0]} → {load_end[0]}, seeds "
            f"{', '.join(map(str, record.get('seeds', [])))}, {record.get('seconds', '?')} s).")


def bandai_split_settings() -> dict[str, Any]:
    """``seed``, ``val_fraction`` and ``test_fraction`` of Bandai's take split (``configs/data/bandai.yaml``), as
    :meth:`~stylemotion.datasets.base.TakeSet.split` takes them."""
    from omegaconf import OmegaConf

    import stylemotion

    cfg = OmegaConf.load(Path(stylemotion.__file__).parent / "configs" / "data" / "bandai.yaml")
    return {"seed": int(cfg.split.seed), "val_fraction": float(cfg.split.val_fraction),
            "test_fraction": float(cfg.split.test_fraction)}


def take_split_record(split: Mapping[str, Sequence[Any]], seed: int, val_fraction: float, test_fraction: float,
                      group_by: Sequence[str] = ("content", "style")) -> dict[str, Any]:
    """What a suite records about a :meth:`~stylemotion.datasets.base.TakeSet.split`: the seed, fractions and
    the number of takes in each part (take names of ``val``/``test`` so a reader can check no test take was
    used to choose anything)."""
    return {"kind": "by take", "seed": int(seed), "val_fraction": float(val_fraction),
            "test_fraction": float(test_fraction), "group_by": list(group_by),
            "takes": {part: len(takes) for part, takes in split.items()},
            "val_takes": sorted(getattr(t, "name", str(t)) for t in split.get("val", [])),
            "test_takes": sorted(getattr(t, "name", str(t)) for t in split.get("test", []))}


def bandai_arguments(base: Any) -> Callable[[argparse.ArgumentParser], None]:
    """``add_arguments`` of the suite module ``base`` with ``--data`` defaulting to ``bandai``: the Bandai twin of a
    suite whose default is the synthetic smoke run, so that its results get a file of their own."""

    def add_arguments(parser: argparse.ArgumentParser) -> None:
        base.add_arguments(parser)
        parser.set_defaults(data="bandai")

    return add_arguments


def train_job(container: dict[str, Any], folder: str) -> dict[str, Any]:
    """Train one model (a resolved ``train`` config) into ``folder``, or reuse a finished one; returns its
    ``metrics.json`` ``val`` figures (best epoch), epochs, training seconds and whether it was reused. Runs in a
    worker process."""
    import time

    from omegaconf import OmegaConf

    from stylemotion.io.jsonfile import read_json_object
    from stylemotion.training.fit import run as train_run

    path = Path(folder)
    t0 = time.perf_counter()
    reused = (path / "metrics.json").is_file()
    if not reused:
        train_run(OmegaConf.create(container))
    metrics = read_json_object(path / "metrics.json", "a suite training's metrics", f"delete {path}")
    return {"val": dict(metrics.get("val") or {}), "epochs": metrics.get("epoch"),
            "seconds": round(time.perf_counter() - t0, 1), "reused": reused}


def run_jobs(jobs: dict[Any, tuple[dict[str, Any], str]], workers: int, shown: Sequence[str] = ("val/mpjpe",)
             ) -> dict[Any, dict[str, Any]]:
    """:func:`train_job` of every ``{key: (container, folder)}``, ``workers`` at once in spawned processes; prints
    each job's ``shown`` validation figures as it finishes."""
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    out = {}
    with ProcessPoolExecutor(max_workers=max(1, workers), mp_context=get_context("spawn")) as pool:
        futures = {key: pool.submit(train_job, *job) for key, job in jobs.items()}
        for key, future in futures.items():
            out[key] = future.result()
            figures = ", ".join(f"{k} {out[key]['val'].get(k)}" for k in shown)
            print(f"[{key}] trained: {figures}, {out[key]['seconds']} s", flush=True)
    return out
