"""The reconstruction benchmarks' data (scripts/bench_reconstruct.py, bench_texture.py, bench_keyframes.py):
Bandai or the synthetic default, split by take into the database (train) and the queries (test)."""

from __future__ import annotations

import os
from collections.abc import Sequence

from stylemotion.datasets import Take, TakeSet, load_dataset, spread_over_styles


def benchmark_split(data: str, root: str | None = None, seed: int = 0, workers: int = 1,
                    synthetic_takes: int = 1) -> tuple[TakeSet, list[Take], list[Take]]:
    """``(dataset, train takes, test takes)``: ``data="bandai"`` (``root`` or ``$STYLEMOTION_DATA``/
    ``../shared/data``, 10 % test per content and style) or ``"synthetic"`` (``synthetic_takes`` takes per content
    and style, 15 % test per content)."""
    if data == "synthetic":
        takeset = load_dataset("synthetic", takes_per_pair=synthetic_takes)
        parts = takeset.split(seed, 0.0, 0.15, group_by=("content",))
    elif data == "bandai":
        root = root or os.path.join(os.environ.get("STYLEMOTION_DATA", "../shared/data"), "bandai-namco-motion-2",
                                    "data.zip")
        takeset = load_dataset("bandai", root=root, workers=workers)
        parts = takeset.split(seed, 0.0, 0.1, group_by=("content", "style"))
    else:
        raise ValueError(f"data={data!r}: the benchmarks run on 'bandai' or 'synthetic'")
    return takeset, parts["train"], parts["test"]


def benchmark_queries(test: Sequence[Take], contents: str, per_content: int) -> list[Take]:
    """``per_content`` test takes of each comma-separated content, in turn from each style; ValueError naming a
    content without test takes."""
    wanted = [c for c in contents.split(",") if c]
    missing = sorted(set(wanted) - {t.content for t in test})
    if missing:
        raise ValueError(f"--contents: no test take of {missing}; the data's contents: "
                         f"{sorted({t.content for t in test})}")
    return spread_over_styles(test, wanted, per_content)
