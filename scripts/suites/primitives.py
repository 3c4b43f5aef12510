"""Suite ``primitives``: foot contacts against the synthetic ground truth, and step segmentation of Bandai's
walks and runs (coverage, planted vs swing foot speed).

The contact thresholds (``stylemotion/configs/segment.yaml``) were set by hand when the segmentation was built;
this suite checks them where the truth is known (synthetic takes, three generator seeds, 30 and 60 fps) and
reports what they do on every Bandai walk and run (no setting is tuned on Bandai).
"""

from __future__ import annotations

import argparse
from collections import Counter
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, fmt_range, md_table, provenance_line, spread

DESCRIPTION = "foot contacts vs synthetic ground truth (3 seeds) and step segmentation of all Bandai walks and runs"
LOCOMOTION = ["walk", "walk-turn-left", "walk-turn-right", "run"]


def contact_errors(seed: int, fps: float, takes_per_group: int = 3, duration_s: float = 4.0) -> dict[str, Any]:
    """Onset and offset errors (detected − true, frames) of every interior synthetic contact; a true contact
    that is not detected, or detected split in two, is counted as missed."""
    from stylemotion.datasets.synthetic import CONTENTS, STYLES, generate_take
    from stylemotion.primitives.contacts import contact_intervals, foot_contacts

    onsets, offsets, missed, total = [], [], 0, 0
    for content in CONTENTS:
        for style in STYLES:
            for index in range(takes_per_group):
                take = generate_take(content, style, index, seed=seed, fps=fps, duration_s=duration_s)
                detected = foot_contacts(take.positions, take.fps)
                n = take.contacts.shape[0]
                for foot in (0, 1):
                    found = contact_intervals(detected[:, foot])
                    for a, b in contact_intervals(take.contacts[:, foot]):
                        if a == 0 or b == n:
                            continue  # cut by the take's ends: the true extent is unknown
                        total += 1
                        overlapping = [(c, d) for c, d in found if c < b and d > a]
                        if len(overlapping) != 1:
                            missed += 1
                            continue
                        onsets.append(overlapping[0][0] - a)
                        offsets.append(overlapping[0][1] - b)
    return {"seed": seed, "fps": fps, "contacts": total, "missed_or_split": missed,
            "onset": dict(sorted(Counter(onsets).items())), "offset": dict(sorted(Counter(offsets).items())),
            "mean_abs_onset_frames": float(np.abs(onsets).mean()) if onsets else None,
            "mean_abs_offset_frames": float(np.abs(offsets).mean()) if offsets else None,
            "max_abs_frames": int(max(np.abs(onsets).max(), np.abs(offsets).max())) if onsets else None}


def bandai_segmentation() -> dict[str, Any]:
    """Coverage and stance speeds of every Bandai walk (incl. turns) and run with the default settings."""
    from stylemotion.datasets.registry import load_dataset
    from stylemotion.primitives.report import build_report
    from stylemotion.primitives.segmentation import SegmentSettings, segment_takes

    takeset = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"), contents=LOCOMOTION)
    settings = SegmentSettings()
    report = build_report(takeset, segment_takes(takeset.takes, settings), settings)
    return {key: report[key] for key in ("dataset", "settings", "coverage_by_action", "coverage", "stance_speeds",
                                          "lengths", "rejection_reasons")}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    synthetic = [contact_errors(seed, fps) for seed in seeds for fps in (30.0, 60.0)]
    return {"splits": {"contacts": "synthetic takes (generator seeds as given), ground truth known; nothing tuned",
                       "segmentation": "every Bandai walk, turn and run take; defaults not tuned on Bandai"},
            "contacts": synthetic, "bandai": bandai_segmentation()}


def _contacts_table(record: dict[str, Any]) -> str:
    rows = []
    for fps in (30.0, 60.0):
        runs = [r for r in record["results"]["contacts"] if r["fps"] == fps]
        rows.append([f"{fps:g}", f"{sum(r['contacts'] for r in runs):,} ({len(runs)} seeds)",
                     str(sum(r["missed_or_split"] for r in runs)),
                     fmt_range(spread(r["mean_abs_onset_frames"] for r in runs)),
                     fmt_range(spread(r["mean_abs_offset_frames"] for r in runs)),
                     str(max(r["max_abs_frames"] for r in runs))])
    return md_table(["fps", "true interior contacts", "missed or split", "mean abs onset error, frames (min–max "
                     "over seeds)", "mean abs offset error, frames", "worst error, frames"], rows)


def _coverage_table(record: dict[str, Any]) -> str:
    b = record["results"]["bandai"]
    table = md_table(["action", "complete steps", "clips", "border steps", "coverage (aim ≥ 90 %)"],
                     [[r["action"], f"{r['complete_steps']:,}", f"{r['clips']:,}", f"{r['border_steps']:,}",
                       fmt(100 * r["coverage"], 1, " %")] for r in b["coverage_by_action"]])
    return f"{table}\n\n{b['dataset']['takes']:,} takes (walk, turns and run, every style)."


def _speed_table(record: dict[str, Any]) -> str:
    rows = [[r["action"], r["style"], f"{r['clips']:,}", fmt(r["planted_mid_mps"], 3), fmt(r["planted_contact_mps"], 3),
             fmt(r["swing_mid_mps"], 2), fmt(100 * r["share_planted_mid_still"], 1, " %")]
            for r in record["results"]["bandai"]["stance_speeds"]]
    return md_table(["action", "style", "stance clips", "planted foot, middle half (m/s; aim ≤ 0.15)",
                     "planted foot over its contact frames (m/s)", "swing foot, middle half (m/s)",
                     "clips with planted foot ≤ 0.15 m/s"], rows)


def render(record: dict[str, Any]) -> dict[str, str]:
    line = provenance_line(record)
    speeds = record["results"]["bandai"]["stance_speeds"]
    walk = spread(r["planted_mid_mps"] for r in speeds if r["action"] == "walk")
    run_ = spread(r["planted_mid_mps"] for r in speeds if r["action"] == "run")
    headline = md_table(["figure", "result"], [
        ["synthetic contacts: missed or split / worst onset or offset error (30 fps)",
         f"{sum(r['missed_or_split'] for r in record['results']['contacts'] if r['fps'] == 30.0)} / "
         f"{max(r['max_abs_frames'] for r in record['results']['contacts'] if r['fps'] == 30.0)} frames"],
        *[[f"Bandai {r['action']}: step coverage (aim ≥ 90 %)", fmt(100 * r["coverage"], 1, " %")]
          for r in record["results"]["bandai"]["coverage_by_action"]],
        ["Bandai walk / run: planted foot over the middle half, range over styles (aim ≤ 0.15 m/s)",
         f"{fmt_range(walk, 3)} / {fmt_range(run_, 3)} m/s"]])
    return {"headline": f"{headline}\n\n{line}", "contacts": f"{_contacts_table(record)}\n\n{line}",
            "coverage": f"{_coverage_table(record)}\n\n{line}", "speeds": f"{_speed_table(record)}\n\n{line}"}
