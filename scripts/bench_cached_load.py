"""Cached load of a dataset in a fresh process (what every command pays on start), as one JSON line.

    python scripts/bench_cached_load.py ../shared/data/bandai-namco-motion-2/data.zip   # zip: CRCs
    python scripts/bench_cached_load.py /tmp/bandai_folder                              # loose files: content hashes

Run it once to fill the cache (``$STYLEMOTION_CACHE``), then time further runs. Loose files are
keyed by a hash of their bytes (read again in every new process), zip members by the CRC in the
archive's central directory; ``scripts/bench.py`` measures repeated loads inside one process.
"""

from __future__ import annotations

import argparse
import json
import os
import time

from stylemotion.datasets import build_dataset


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", help="Bandai data.zip or an unpacked Bandai folder (with cfg/)")
    args = parser.parse_args()
    started = time.perf_counter()
    takeset = build_dataset({"name": "bandai", "root": args.root})
    print(json.dumps({"bench": "bandai_cached_fresh_process", "root": args.root, "takes": len(takeset),
                      "frames": takeset.num_frames, "seconds": round(time.perf_counter() - started, 3),
                      "load_avg_1m": round(os.getloadavg()[0], 2)}))


if __name__ == "__main__":
    main()
