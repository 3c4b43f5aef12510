"""Controlled synthesis: motion graph of primitive models, path following, stitching (thesis §4.5, §5.4.4).

The names below load from their submodules on first use (PEP 562, :func:`stylemotion.lazy_exports`), so a light
submodule of the package loads without the heavy ones.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from stylemotion import lazy_exports

if TYPE_CHECKING:
    from stylemotion.synthesis.controller import SharpTurnWarning, SynthesizedMotion, follow_path
    from stylemotion.synthesis.graph import MotionGraph, UnknownStyleError, load_graph
    from stylemotion.synthesis.path import GroundPath, PathError, s_curve
    from stylemotion.synthesis.settings import FollowSettings


__all__ = ["FollowSettings", "GroundPath", "MotionGraph", "PathError", "SharpTurnWarning", "SynthesizedMotion",
           "UnknownStyleError", "follow_path", "load_graph", "s_curve"]

__getattr__, __dir__ = lazy_exports(__name__, {
    "FollowSettings": "settings",
    "SharpTurnWarning": "controller",
    "SynthesizedMotion": "controller",
    "follow_path": "controller",
    "MotionGraph": "graph",
    "UnknownStyleError": "graph",
    "load_graph": "graph",
    "GroundPath": "path",
    "PathError": "path",
    "s_curve": "path",
})
