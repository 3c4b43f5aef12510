"""stylemotion: generative models of human motion variation and style from motion capture."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("stylemotion")
except PackageNotFoundError:  # run from a source tree that was never installed
    __version__ = "0+unknown"
