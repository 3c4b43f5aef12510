"""The viewer tests' fixtures (defined in tests/viewer_fixtures.py)."""

from viewer_fixtures import browser, motion_files  # noqa: F401 (fixtures)
