"""Browser viewer of motions (a static three.js page) and the HTML evaluation report; see docs/viewer.md."""

from stylemotion.viewer.motions import ViewerMotion, read_inputs
from stylemotion.viewer.page import build_viewer, write_viewer

__all__ = ["ViewerMotion", "build_viewer", "read_inputs", "write_viewer"]
