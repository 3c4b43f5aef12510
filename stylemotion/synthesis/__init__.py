"""Controlled synthesis: motion graph of primitive models, path following, stitching (thesis §4.5, §5.4.4)."""

from stylemotion.synthesis.controller import FollowSettings, SharpTurnWarning, SynthesizedMotion, follow_path
from stylemotion.synthesis.graph import MotionGraph, UnknownStyleError, load_graph
from stylemotion.synthesis.path import GroundPath, PathError, s_curve

__all__ = ["FollowSettings", "GroundPath", "MotionGraph", "PathError", "SharpTurnWarning", "SynthesizedMotion",
           "UnknownStyleError", "follow_path", "load_graph", "s_curve"]
