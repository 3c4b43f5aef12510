"""Benchmark of the viewer page: load time and frame rate in headless Chromium, and the folder's size.

    python scripts/bench_viewer.py                    # 16 motions of 300 frames, prints JSON
    python scripts/bench_viewer.py --screenshot docs/images/viewer.png --motions 6 --frames 240

The motions are synthetic walks, runs and turns of several styles (stylemotion.datasets.synthetic), written by
:func:`stylemotion.viewer.page.write_viewer`; the page is opened from disk in Debian's chromium (headless,
software WebGL, Playwright) at 1280×720. Load time: ``page.goto`` until the first frame is drawn
(``document.body.dataset.ready``), median of ``--loads`` fresh pages. Frame rate: frames drawn per second
while playing, over ``--seconds``, with ``?quality=auto`` (on software WebGL: no shadows, no antialiasing) and
``?quality=high`` (shadows and antialiasing); the screenshot is taken at high quality.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from stylemotion.datasets.synthetic import CONTENTS, STYLES, generate_take
from stylemotion.viewer.browser import CHROMIUM_ARGS, chromium_path
from stylemotion.viewer.motions import samples_to_motions
from stylemotion.viewer.page import folder_size, write_viewer


def motions(count: int, frames: int):
    out = []
    for i in range(count):
        style, content = STYLES[i % len(STYLES)], CONTENTS[(i // len(STYLES)) % len(CONTENTS)]
        take = generate_take(content, style, i, duration_s=frames / 30.0)
        out += samples_to_motions(take.positions[None], [frames], take.fps, style, 1)
        out[-1].name = f"{content} {style} #{i}"
    return out


def measure(count: int = 16, frames: int = 300, loads: int = 3, seconds: float = 5.0,
            chromium: str | None = None, screenshot: str | None = None) -> dict:
    """Folder size, page load times and frames per second of ``count`` synthetic motions of ``frames`` frames
    in headless chromium (see the module docstring)."""
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as tmp:
        started = time.perf_counter()
        index = write_viewer(motions(count, frames), Path(tmp) / "view", title=(
            f"stylemotion-view: {count} synthetic motions of {min(count, len(STYLES))} styles"))
        write_s = time.perf_counter() - started
        size = folder_size(index.parent)
        data_size = (index.parent / "data.js").stat().st_size
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=chromium or chromium_path(), args=list(CHROMIUM_ARGS))
            load_times, errors = [], []
            for _ in range(loads):
                page = browser.new_page(viewport={"width": 1280, "height": 720})
                page.on("pageerror", lambda e: errors.append(str(e)))
                page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
                t0 = time.perf_counter()
                page.goto(index.as_uri())
                page.wait_for_function("document.body.dataset.ready === '1'", timeout=60_000)
                load_times.append(time.perf_counter() - t0)
                page.close()
            fps, quality = {}, {}
            for asked in ("auto", "high"):
                page = browser.new_page(viewport={"width": 1280, "height": 720})
                page.goto(index.as_uri() + f"?quality={asked}")
                page.wait_for_function("document.body.dataset.ready === '1'", timeout=60_000)
                page.wait_for_timeout(1000)
                r0, t0 = page.evaluate("window.stylemotionViewer.rendered"), time.perf_counter()
                page.wait_for_timeout(seconds * 1000)
                r1, t1 = page.evaluate("window.stylemotionViewer.rendered"), time.perf_counter()
                fps[asked] = round((r1 - r0) / (t1 - t0), 1)
                quality[asked] = page.evaluate("document.body.dataset.quality")
                skeletons = int(page.evaluate("document.body.dataset.skeletons"))
                if screenshot and asked == "high":
                    page.evaluate("window.stylemotionViewer.pause(); window.stylemotionViewer.setFrame(45)")
                    page.wait_for_timeout(1500)
                    page.screenshot(path=screenshot)
                page.close()
            version = browser.version
            browser.close()
    return {"motions": count, "frames": frames, "skeletons_drawn": skeletons,
            "load_s_median": round(statistics.median(load_times), 3), "load_s": [round(x, 3) for x in load_times],
            "fps_playing": fps, "quality_used": quality, "write_s": round(write_s, 2),
            "folder_mb": round(size / 1e6, 2), "data_js_mb": round(data_size / 1e6, 2),
            "viewport": "1280x720", "browser": f"Debian chromium {version}, headless, --disable-gpu (software WebGL)",
            "console_errors": errors, "load_average": [round(x, 2) for x in os.getloadavg()],
            "numpy": np.__version__}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--motions", type=int, default=16)
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--loads", type=int, default=3)
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--chromium", default=chromium_path())
    parser.add_argument("--screenshot", default=None, help="also save a screenshot of the page (PNG)")
    args = parser.parse_args()
    record = measure(args.motions, args.frames, args.loads, args.seconds, args.chromium, args.screenshot)
    print(json.dumps(record, indent=1))
    return 0 if not record["console_errors"] else 1


if __name__ == "__main__":
    sys.exit(main())
