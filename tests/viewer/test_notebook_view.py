"""``stylemotion.view``: the viewer page as one self-contained HTML output of a notebook
(stylemotion/viewer/notebook.py)."""

from __future__ import annotations

import html
import re
from importlib import resources

import numpy as np
import pytest
from viewer_fixtures import synthetic_samples, write_take_npz

import stylemotion
from stylemotion.io.errors import UserInputError
from stylemotion.viewer.notebook import ViewerPage, view


def srcdoc(page: ViewerPage) -> str:
    """The document inside the page's ``<iframe srcdoc=…>`` (what the notebook front end renders)."""
    match = re.fullmatch(r'<iframe srcdoc="([^"]*)" style="[^"]*" sandbox="allow-scripts"></iframe>',
                         page._repr_html_())
    assert match, page._repr_html_()[:300]
    return html.unescape(match[1])


def test_samples_display_as_an_iframe_holding_the_vendored_three_js_and_no_url(tmp_path):
    page = stylemotion.view(synthetic_samples(("normal", "elderly", "active")), title="three styles")
    assert isinstance(page, ViewerPage) and len(page.motions) == 3
    document = srcdoc(page)
    assert document == page.document
    bundle = resources.files("stylemotion.viewer").joinpath("vendor", "three.bundle.min.js").read_text()
    assert bundle in document  # the vendored three.js, inlined
    viewer_js = resources.files("stylemotion.viewer").joinpath("static", "viewer.js").read_text()
    assert viewer_js in document and "window.STYLEMOTION_DATA = " in document
    assert not re.search(r"""(src|href)\s*=\s*["']?(https?:)?//""", document)  # nothing fetched from a CDN
    assert "cdn" not in document.lower().replace(bundle.lower(), "")
    assert "<h1>three styles</h1>" in document and 'data-motions="3"' in document
    assert 'src="' not in document.replace('data-src="', "")  # every script inlined


def test_arrays_files_and_named_groups_are_shown(tmp_path):
    walk = write_take_npz(tmp_path / "walk.npz", "normal", walk=True)
    one = np.zeros((10, 21, 3), np.float32) + np.linspace(0, 1, 21)[None, :, None]
    page = view({"mine": one, "file": walk, "batch": synthetic_samples(("normal", "youthful"))}, max_samples=1)
    assert [m.group for m in page.motions] == ["mine", "walk", "batch"]
    assert page.motions[1].path is not None  # a walk's ground path is drawn
    assert len(view([one, one]).motions) == 2


def test_what_is_no_motion_is_one_clear_error(tmp_path):
    with pytest.raises(UserInputError, match=r"\(frames, 21, 3\)"):
        view(np.zeros((10, 3)))
    with pytest.raises(UserInputError, match="no such file"):
        view(tmp_path / "missing.npz")
    with pytest.raises(UserInputError, match="no motion"):
        view([])


@pytest.mark.browser
def test_the_inline_page_plays_offline_in_a_browser(browser):
    page = view(synthetic_samples(("normal", "elderly")))
    tab = browser.new_page(viewport={"width": 900, "height": 500})
    requests, problems = [], []
    tab.route("**/*", lambda route: (requests.append(route.request.url), route.abort()))
    tab.on("pageerror", lambda e: problems.append(str(e)))
    tab.set_content(page.document)
    tab.wait_for_function("document.body.dataset.ready === '1'", timeout=30_000)
    assert tab.evaluate("window.stylemotionViewer.skeletons") == 2
    assert requests == [] and problems == []
    tab.close()
