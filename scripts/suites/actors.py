"""Suite ``actors``: how many actors (actor groups) each data set holds, i.e. which cross-actor splits exist.

A cross-actor split needs to know which take is whose; Bandai's labels name content and style only, so
:func:`stylemotion.datasets.actors.actor_groups` groups takes by their skeletons: bone lengths within 1 mm and
one rest pose in their BVH files. This suite measures how far the bone lengths differ between takes, how many
groups the bones alone give and how many the rest poses add, and which styles each group holds.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, md_table, provenance_line

DESCRIPTION = "actor groups by bone length and rest pose in Bandai (which cross-actor splits the data set allows)"
DEFAULT_SEEDS = (0,)  # deterministic: no training or sampling


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.bones import median_bone_lengths
    from stylemotion.datasets.actors import ACTOR_TOLERANCE_M, actor_groups
    from stylemotion.datasets.registry import load_dataset

    bandai = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"))
    lengths = np.stack([median_bone_lengths(t.positions) for t in bandai.takes])  # (takes, 20) m
    rows = []
    for content in ["all", *bandai.label_values("content")]:
        takes = bandai.takes if content == "all" else [t for t in bandai.takes if t.content == content]
        bones, groups = actor_groups(takes, rest_poses=False), actor_groups(takes)
        ids = sorted(groups.styles)
        rows.append({"content": content, "takes": len(takes), "groups_by_bones": len(bones.styles),
                     "groups": len(ids), "styles_by_group": [groups.styles[g] for g in ids],
                     "takes_per_group": [list(groups.takes.values()).count(g) for g in ids]})
    return {"splits": {"kind": "none: every take of the data set is measured"},
            "tolerance_m": ACTOR_TOLERANCE_M, "takes": len(bandai.takes),
            "bone_length_sd_max_m": float(lengths.std(axis=0).max()),
            "height_sum_of_bones_m": {"min": float(lengths.sum(1).min()), "max": float(lengths.sum(1).max())},
            "by_content": rows}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    rows = [[row["content"], f"{row['takes']:,}", str(row["groups_by_bones"]), str(row["groups"]),
             "; ".join(f"{'/'.join(s)} ({n:,})" for s, n in zip(row["styles_by_group"], row["takes_per_group"]))]
            for row in r["by_content"]]
    table = md_table(["content", "takes", "groups by bones (within 1 mm)", "groups by bones and rest pose",
                      "styles of each group (takes)"], rows)
    text = (f"{table}\n\nLargest standard deviation of any bone's median length across the {r['takes']:,} takes: "
            f"{fmt(r['bone_length_sd_max_m'] * 1000, 3)} mm (sum of the 20 bones "
            f"{fmt(r['height_sum_of_bones_m']['min'], 3)}–{fmt(r['height_sum_of_bones_m']['max'], 3)} m). "
            f"{provenance_line(record)}")
    return {"headline": text}
