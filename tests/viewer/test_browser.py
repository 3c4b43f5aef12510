"""The viewer page in headless Chromium, as a user sees it (marker ``browser``)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from stylemotion.viewer.motions import read_inputs
from stylemotion.viewer.page import write_viewer

pytestmark = pytest.mark.browser


def _pixels(page) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(page.locator("#view canvas").screenshot())).convert("L"), dtype=float)


def test_page_plays_scrubs_and_shows_every_motion(browser, motion_files, tmp_path):
    index = write_viewer(read_inputs(motion_files), tmp_path / "view", title="browser test")
    page = browser.new_page(viewport={"width": 1000, "height": 640})
    problems = []
    page.on("console", lambda m: problems.append(f"console {m.type}: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
    page.goto(index.as_uri())  # from disk: file://
    page.wait_for_function("document.body.dataset.ready === '1'", timeout=30_000)

    # the number of skeletons drawn equals the number of motions given
    assert page.evaluate("document.body.dataset.skeletons") == str(len(motion_files))
    assert page.evaluate("window.stylemotionViewer.skeletons") == len(motion_files)

    # the frame counter advances while playing
    counter = page.locator("#frame")
    first = int(counter.get_attribute("data-frame"))
    page.wait_for_function(f"Number(document.getElementById('frame').dataset.frame) > {first}", timeout=10_000)
    assert int(counter.get_attribute("data-frame")) > first

    # paused, the scrubber moves the skeletons: two screenshots differ
    page.click("#play")
    assert page.locator("#play").inner_text() == "Play"
    scrub = page.locator("#scrub")
    scrub.fill("0")
    page.wait_for_function("window.stylemotionViewer.frame() === 0")
    a = _pixels(page)
    last = int(scrub.get_attribute("max"))
    scrub.fill(str(last // 2))
    page.wait_for_function(f"window.stylemotionViewer.frame() === {last // 2}")
    assert counter.inner_text() == f"frame {last // 2} / {last}"
    b = _pixels(page)

    # the canvas is not blank, and the scrubbed frame looks different
    assert a.std() > 5.0 and b.std() > 5.0, (a.std(), b.std())
    changed = np.mean(np.abs(a - b) > 10)
    assert changed > 0.002, changed
    assert problems == []
    page.close()
