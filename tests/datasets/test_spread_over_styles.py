"""``spread_over_styles``: benchmark queries taken in turn from each style of each content."""

from __future__ import annotations

from stylemotion.datasets import spread_over_styles
from stylemotion.datasets.registry import load_dataset


def test_queries_cover_every_style_before_repeating_one():
    takes = load_dataset("synthetic", takes_per_pair=2).takes
    picked = spread_over_styles(takes, ["walk", "run"], 8)
    styles = sorted({t.style for t in takes})
    assert [t.content for t in picked] == ["walk"] * 8 + ["run"] * 8
    assert [t.style for t in picked[:7]] == styles and picked[7].style == styles[0]
    assert picked[0].name < picked[7].name  # within a style, in name order
    assert len(spread_over_styles(takes, ["walk"], 100)) == sum(t.content == "walk" for t in takes)
