"""Plots and stick-figure renderings (matplotlib, Agg backend friendly)."""

from stylemotion.viz.stick import BONES, StickFigure, draw_clip, draw_pose, render_contact_sheet

__all__ = ["BONES", "StickFigure", "draw_clip", "draw_pose", "render_contact_sheet"]
