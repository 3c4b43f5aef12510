"""Controlled synthesis: motion graph of primitive models, path following, stitching (thesis §4.5, §5.4.4).

The names below are loaded on first use (PEP 562), so importing a light submodule such as
:mod:`stylemotion.synthesis.stitching` does not load the models (and torch) behind the controller.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from stylemotion.synthesis.controller import FollowSettings, SharpTurnWarning, SynthesizedMotion, follow_path
    from stylemotion.synthesis.graph import MotionGraph, UnknownStyleError, load_graph
    from stylemotion.synthesis.path import GroundPath, PathError, s_curve

_WHERE = {
    "FollowSettings": "controller", "SharpTurnWarning": "controller", "SynthesizedMotion": "controller",
    "follow_path": "controller",
    "MotionGraph": "graph", "UnknownStyleError": "graph", "load_graph": "graph",
    "GroundPath": "path", "PathError": "path", "s_curve": "path",
}

__all__ = ["FollowSettings", "GroundPath", "MotionGraph", "PathError", "SharpTurnWarning", "SynthesizedMotion",
           "UnknownStyleError", "follow_path", "load_graph", "s_curve"]


def __getattr__(name: str) -> Any:
    """Load an exported name from its submodule on first use."""
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f"{__name__}.{_WHERE[name]}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
