"""Data-layer benchmark: cold conversion and cached load of a dataset, with peak memory.

Prints one JSON object per measurement (machine-readable), e.g.

    python scripts/bench.py                                  # all of Bandai from ../shared/data
    python scripts/bench.py --contents walk --styles normal  # a subset
    python scripts/bench.py --workers 1

Cold = a fresh, empty cache folder (every file parsed, resampled, FK'd and converted);
cached = the same call again (index + one .npy read). Peak memory is the resident set size
high-water mark of this process plus its worker processes.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import sys
import tempfile
import time

from stylemotion.datasets import load_dataset


def _peak_rss_mb() -> dict[str, float]:
    own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    return {"peak_rss_main_mb": round(own, 1), "peak_rss_worker_mb": round(children, 1)}


def measure(root: str, contents=None, styles=None, workers: int | None = None, repeats: int = 3,
            colds: int = 1) -> list[dict]:
    """``colds`` cold builds (each in a fresh, empty cache folder), then ``repeats`` cached loads of the last
    one (best kept): one record per measurement, with the peak memory so far."""
    records = []
    for _ in range(colds):
        with tempfile.TemporaryDirectory(prefix="stylemotion-bench-") as cache:
            options = dict(root=root, contents=contents, styles=styles, cache_dir=cache, workers=workers)
            start = time.perf_counter()
            takeset = load_dataset("bandai", **options)
            cold = time.perf_counter() - start
            frames = takeset.num_frames
            records.append({"bench": "bandai_cold", "files": len(takeset), "frames": frames,
                            "seconds": round(cold, 3), "frames_per_s": round(frames / cold, 1),
                            "workers": workers or os.cpu_count(), **_peak_rss_mb()})
            best = float("inf")
            for _ in range(repeats):
                start = time.perf_counter()
                cached = load_dataset("bandai", **options)
                best = min(best, time.perf_counter() - start)
            assert cached.num_frames == frames
        records.append({"bench": "bandai_cached", "files": len(cached), "frames": frames,
                        "seconds": round(best, 3), "frames_per_s": round(frames / best, 1),
                        "cold_over_cached": round(cold / best, 1), **_peak_rss_mb()})
    return records


def main(argv: list[str] | None = None) -> int:
    default_root = os.path.join(os.environ.get("STYLEMOTION_DATA", "../shared/data"),
                                "bandai-namco-motion-2", "data.zip")
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default=default_root)
    parser.add_argument("--contents", nargs="*", default=None)
    parser.add_argument("--styles", nargs="*", default=None)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--repeats", type=int, default=3, help="cached-load repetitions (best is kept)")
    args = parser.parse_args(argv)

    machine = {"machine": platform.machine(), "cpus": os.cpu_count(), "python": platform.python_version(),
               "load_avg_1m": round(os.getloadavg()[0], 2)}
    for record in measure(args.root, args.contents, args.styles, args.workers, args.repeats):
        print(json.dumps({**record, **machine}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
