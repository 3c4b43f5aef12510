"""How the viewer's tests and benchmark start a headless browser: Debian's ``chromium`` through Playwright.

Playwright's own browser download is never used; ``STYLEMOTION_CHROMIUM`` names another Chromium binary.
"""

from __future__ import annotations

import os

#: Command-line switches of the headless browser (no sandbox in containers, software WebGL, no network noise).
CHROMIUM_ARGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync")


def chromium_path() -> str:
    """The Chromium binary: ``$STYLEMOTION_CHROMIUM``, else Debian's ``/usr/bin/chromium``."""
    return os.environ.get("STYLEMOTION_CHROMIUM", "/usr/bin/chromium")
