"""Suite ``speed``: the data layer (cold conversion and cached load of all Bandai), command start-up (imports),
and the viewer page (load time, frames per second in headless chromium) — measured ALONE.

Speed depends on the machine and on what else runs: run this suite with nothing beside it; the results file
records the load average before and after, and the render prints it. Each "seed" is one repetition of every
measurement; the tables give min–max over repetitions.
"""

from __future__ import annotations

import argparse
from typing import Any

from suites.common import DATA_ROOT, fmt_range, md_table, provenance_line, spread

DESCRIPTION = "data-layer load, command start-up and viewer speed (run alone; repetitions as seeds)"
PARTS = ("data", "imports", "viewer")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--parts", nargs="+", choices=PARTS, default=list(PARTS), help="what to measure")


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    results: dict[str, Any] = {"splits": {"kind": "none: speed of every Bandai file / synthetic motions"},
                               "repetitions": len(seeds)}
    if "data" in args.parts:
        import bench

        results["data"] = bench.measure(str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"), repeats=3,
                                        colds=len(seeds))
    if "imports" in args.parts:
        import bench_imports

        results["imports"] = [bench_imports.measure(m, 5 * len(seeds)) for m in bench_imports.DEFAULT_MODULES]
    if "viewer" in args.parts:
        import bench_viewer

        results["viewer"] = [bench_viewer.measure(16, 300, 3, 5.0) for _ in seeds]
    return results


def _data(record: dict[str, Any]) -> str:
    data = record["results"]["data"]
    cold = [r for r in data if r["bench"] == "bandai_cold"]
    cached = [r for r in data if r["bench"] == "bandai_cached"]
    rows = [["cold: parse, resample, FK, canonical, cache write", f"{cold[0]['files']:,}", f"{cold[0]['frames']:,}",
             fmt_range(spread(r["seconds"] for r in cold), 1, " s"),
             fmt_range(spread(r["frames_per_s"] for r in cold), 0),
             f"{max(r['peak_rss_main_mb'] for r in cold):,.0f} / {max(r['peak_rss_worker_mb'] for r in cold):,.0f} MB",
             "≤ 60 s"],
            ["cached: fingerprints, labels, one .npy read (best of 3 per repetition)", f"{cached[0]['files']:,}",
             f"{cached[0]['frames']:,}", fmt_range(spread(r["seconds"] for r in cached), 3, " s"),
             fmt_range(spread(r["frames_per_s"] for r in cached), 0), "", "≤ 3 s"]]
    return md_table(["measurement", "files", "frames", "seconds (min–max)", "frames/s", "peak RSS main / workers",
                     "aim"], rows) + f"\n\n{len(cold)} repetitions, {cold[0]['workers']} worker processes."


def _imports(record: dict[str, Any]) -> str:
    rows = [[f"`{r['module']}`", f"{r['median_s']:.2f} s ({r['min_s']:.2f}–{r['max_s']:.2f})", str(r["repeat"]),
             ", ".join(k for k in ("torch", "lightning", "sklearn", "matplotlib") if r[k]) or "none of them"]
            for r in record["results"]["imports"]]
    return md_table(["import (fresh interpreter)", "median (min–max)", "processes",
                     "loads torch / Lightning / scikit-learn / matplotlib"], rows)


def _viewer(record: dict[str, Any]) -> str:
    runs = record["results"]["viewer"]
    first = runs[0]
    rows = [["folder size (data.js)", f"{first['folder_mb']:.2f} MB ({first['data_js_mb']:.2f} MB)"],
            ["writing the folder", fmt_range(spread(r["write_s"] for r in runs), 2, " s")],
            ["page load, open from disk → first frame (median of 3 pages per repetition)",
             fmt_range(spread(r["load_s_median"] for r in runs), 2, " s")],
            ["frames per second while playing, `quality=auto`",
             fmt_range(spread(r["fps_playing"]["auto"] for r in runs), 1)],
            ["the same, `quality=high` (shadows, antialiasing)",
             fmt_range(spread(r["fps_playing"]["high"] for r in runs), 1)],
            ["skeletons drawn / console errors",
             f"{first['skeletons_drawn']} / {sum(len(r['console_errors']) for r in runs)}"]]
    return (md_table(["figure", f"{first['motions']} motions × {first['frames']} frames, {len(runs)} repetitions "
                      "(min–max)"], rows) + f"\n\n{first['browser']}, {first['viewport']}.")


def render(record: dict[str, Any]) -> dict[str, str]:
    line = provenance_line(record)
    blocks, head = {}, []
    r = record["results"]
    if "data" in r:
        blocks["data"] = f"{_data(record)}\n\n{line}"
        cold = spread(x["seconds"] for x in r["data"] if x["bench"] == "bandai_cold")
        cached = spread(x["seconds"] for x in r["data"] if x["bench"] == "bandai_cached")
        head.append(["all Bandai: cold build / cached load (aims ≤ 60 s / ≤ 3 s)",
                     f"{fmt_range(cold, 1, ' s')} / {fmt_range(cached, 3, ' s')}"])
    if "imports" in r:
        blocks["imports"] = f"{_imports(record)}\n\n{line}"
        search = next(x for x in r["imports"] if x["module"] == "stylemotion.search.command")
        head.append(["`import stylemotion.search.command` (aim ≤ 1.5 s, no Lightning)",
                     f"{search['median_s']:.2f} s, Lightning {'loaded' if search['lightning'] else 'not loaded'}"])
    if "viewer" in r:
        blocks["viewer"] = f"{_viewer(record)}\n\n{line}"
        head.append(["viewer, 16 × 300 frames: page load / frames per second (auto quality)",
                     f"{fmt_range(spread(x['load_s_median'] for x in r['viewer']), 2, ' s')} / "
                     f"{fmt_range(spread(x['fps_playing']['auto'] for x in r['viewer']), 1)}"])
    table = md_table(["figure (measured alone)", "result (min–max over repetitions)"], head)
    blocks["headline"] = f"{table}\n\n{line}"
    return blocks
