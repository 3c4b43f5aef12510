"""The segmentation report (what ``stylemotion-segment`` writes): primitives of walks and runs, in a folder.

    stylemotion-segment                                  # the embedded synthetic dataset
    stylemotion-segment data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right,run]' \\
        out=reports/segmentation/bandai
    stylemotion-segment data=bandai out=reports/seg force=true segment.max_step_s=1.2

The folder (``out``; an existing one is refused unless ``force=true``) holds:

* ``report.json``: everything below, machine-readable, including every rejected take and step;
* ``report.md``: clip counts per action × primitive × style, length statistics and canonical
  timelines, step coverage and planted/swing foot speeds per action × style, rejections by reason;
* ``takes/<take>.png``: foot heights, detected contacts, keyframes and clips of chosen takes
  (``plot_takes`` per action × style, plus up to ``plot_rejected`` takes with rejected steps);
* ``clips_<action>.png``: stick-figure contact sheets, ``sheet_clips`` clips per primitive.

The whole folder is written next to ``out`` and renamed into place, so a report is never half
written.
"""

from __future__ import annotations

import dataclasses
import logging
from collections import Counter, defaultdict
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from stylemotion.config import ConfigError
from stylemotion.datasets import Take, TakeSet, build_dataset
from stylemotion.io.atomic import atomic_folder
from stylemotion.io.jsonfile import write_json
from stylemotion.io.outputs import check_new_output, inside, safe_name
from stylemotion.primitives.segmentation import (
    PRIMITIVES,
    Clip,
    Segmentation,
    SegmentSettings,
    canonical_timelines,
    segment_takes,
    stance_speeds,
)
from stylemotion.provenance import provenance

log = logging.getLogger(__name__)

#: Planted-foot speed (m/s) over the middle half of a stance clip below which it counts as still.
STILL_SPEED = 0.15


# ---------------------------------------------------------------------------------------------
# Numbers


def coverage_table(seg: Segmentation) -> list[dict[str, Any]]:
    """Per (action, style): complete steps, clips, rejected steps, border steps, coverage.

    A *complete* step has both support transfers inside its take; coverage is clips / complete
    steps. Border steps (cut by the take's start or end) are counted apart.
    """
    rows: dict[tuple[str, str], Counter] = defaultdict(Counter)
    for take_seg in seg.takes:
        for c in take_seg.clips:
            rows[(c.action, c.style)]["clips"] += 1
        for r in take_seg.rejections:
            rows[(r.action, r.style)]["rejected_" + r.kind] += 1
    out = []
    for (action, style), n in sorted(rows.items()):
        complete = n["clips"] + n["rejected_step"]
        out.append({"action": action, "style": style, "complete_steps": complete, "clips": n["clips"],
                    "rejected_steps": n["rejected_step"], "border_steps": n["rejected_border"],
                    "rejected_takes": n["rejected_take"],
                    "coverage": round(n["clips"] / complete, 4) if complete else None,
                    "share_of_all_stances": round(n["clips"] / (complete + n["rejected_border"]), 4)
                    if complete + n["rejected_border"] else None})
    return out


def _totals(rows: list[dict[str, Any]], key: str | None) -> list[dict[str, Any]]:
    groups: dict[str, Counter] = defaultdict(Counter)
    for r in rows:
        g = groups[r[key] if key else "all"]
        for k in ("complete_steps", "clips", "rejected_steps", "border_steps", "rejected_takes"):
            g[k] += r[k]
    return [{(key or "scope"): name, **dict(n), "coverage": round(n["clips"] / n["complete_steps"], 4)
             if n["complete_steps"] else None} for name, n in sorted(groups.items())]


def speed_table(clips: list[Clip]) -> list[dict[str, Any]]:
    """Per (action, style), over left/right stance clips: mean planted and swing foot speeds."""
    values: dict[tuple[str, str], list[dict[str, float]]] = defaultdict(list)
    for c in clips:
        if c.primitive in ("leftStance", "rightStance"):
            values[(c.action, c.style)].append(stance_speeds(c.positions, c.fps, c.stance_foot, c.contacts))
    out = []
    for (action, style), vals in sorted(values.items()):
        planted = np.array([v["planted_mid"] for v in vals])
        out.append({
            "action": action, "style": style, "clips": len(vals),
            "planted_mid_mps": round(float(planted.mean()), 4),
            "swing_mid_mps": round(float(np.mean([v["swing_mid"] for v in vals])), 4),
            "planted_contact_mps": round(float(np.nanmean([v["planted_contact"] for v in vals])), 4),
            "share_planted_mid_still": round(float((planted <= STILL_SPEED).mean()), 4),
        })
    return out


def length_table(clips: list[Clip], statistic: str) -> list[dict[str, Any]]:
    """Per (action, primitive): clip count, frames min/median/max, duration mean ± sd, canonical length."""
    canon = canonical_timelines(clips, statistic)
    groups: dict[tuple[str, str], list[Clip]] = defaultdict(list)
    for c in clips:
        groups[(c.action, c.primitive)].append(c)
    out = []
    for (action, primitive), cs in sorted(groups.items(), key=lambda kv: (kv[0][0], PRIMITIVES.index(kv[0][1]))):
        frames = np.array([c.num_frames for c in cs])
        dur = np.array([c.duration_s for c in cs])
        out.append({"action": action, "primitive": primitive, "clips": len(cs), "frames_min": int(frames.min()),
                    "frames_median": float(np.median(frames)), "frames_max": int(frames.max()),
                    "duration_mean_s": round(float(dur.mean()), 4), "duration_sd_s": round(float(dur.std()), 4),
                    "canonical_frames": canon[(action, primitive)]})
    return out


def count_table(seg: Segmentation, actions: list[str], styles: list[str]) -> list[dict[str, Any]]:
    """Clip counts for every action × primitive × style (zeros included)."""
    counts = seg.counts()
    return [{"action": a, "primitive": p, "style": s, "clips": counts.get((a, p, s), 0)}
            for a in actions for p in PRIMITIVES for s in styles]


def build_report(takeset: TakeSet, seg: Segmentation, settings: SegmentSettings,
                 timeline: str = "median") -> dict[str, Any]:
    """All numbers of the segmentation report (JSON-ready)."""
    styles = sorted({t.style for t in takeset.takes if t.name not in {n for n, _ in seg.ignored}})
    coverage = coverage_table(seg)
    reasons = Counter((r.kind, _reason_key(r.reason)) for r in seg.rejections)
    return {
        "dataset": {"name": takeset.name, "fps": takeset.fps, "takes": len(takeset),
                    "segmented_takes": len(seg.takes), "ignored_takes": len(seg.ignored),
                    "ignored_contents": sorted({c for _, c in seg.ignored}),
                    "skipped_inputs": [{"source": s, "reason": r} for s, r in takeset.skipped]},
        "settings": dataclasses.asdict(settings),
        "timeline_statistic": timeline,
        "still_speed_mps": STILL_SPEED,
        "counts": count_table(seg, list(settings.actions), styles),
        "lengths": length_table(seg.clips, timeline) if seg.clips else [],
        "coverage": coverage,
        "coverage_by_action": _totals(coverage, "action"),
        "coverage_total": _totals(coverage, None),
        "stance_speeds": speed_table(seg.clips),
        "rejection_reasons": [{"kind": k, "reason": r, "count": n} for (k, r), n in reasons.most_common()],
        "rejections": [dataclasses.asdict(r) for r in seg.rejections],
        "ignored": [{"take": n, "content": c} for n, c in seg.ignored],
    }


def _reason_key(reason: str) -> str:
    """A rejection reason without its numbers, for grouping (``too short (0.07 s …)`` → ``too short``)."""
    return reason.split(" (")[0].split(": ", 1)[-1] if ": " in reason.split(" (")[0] else reason.split(" (")[0]


# ---------------------------------------------------------------------------------------------
# Markdown


def _table(rows: list[dict[str, Any]], columns: list[str]) -> list[str]:
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for r in rows:
        cells = []
        for c in columns:
            v = r.get(c)
            cells.append(f"{v:.1%}" if c in ("coverage", "share_planted_mid_still", "share_of_all_stances")
                         and v is not None else "–" if v is None else str(v))
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def format_report(report: dict[str, Any], command: str, plots: list[str], sheets: list[str]) -> str:
    """``report.md`` text."""
    d = report["dataset"]
    s = report["settings"]
    out = [f"# Segmentation report: {d['name']}", "",
           f"Command: `{command}`", "",
           f"{d['segmented_takes']} locomotion takes segmented of {d['takes']} ({d['fps']:g} fps); "
           f"{d['ignored_takes']} takes of other contents ignored {d['ignored_contents'] or ''}.",
           f"Actions {s['actions']}; steps of {s['min_step_s']}–{s['max_step_s']} s; contact thresholds "
           f"{s['contacts']} (heights in leg lengths, speeds in leg lengths/s).", "",
           "Definitions: a *step* is one foot's single-support phase; it is *complete* when both its support "
           "transfers (double support of a walk, flight of a run) lie in the take, and a *border* step "
           "otherwise. Coverage = clips / complete steps. Keyframes are the middle frames of the support "
           "transfers (see stylemotion/primitives/segmentation.py).", ""]
    out += ["## Step coverage", ""]
    out += _table(report["coverage_total"] + report["coverage_by_action"],
                  ["scope", "action", "complete_steps", "clips", "rejected_steps", "border_steps",
                   "rejected_takes", "coverage"])
    out += ["", "Per action × style:", ""]
    out += _table(report["coverage"], ["action", "style", "complete_steps", "clips", "rejected_steps",
                                       "border_steps", "rejected_takes", "coverage", "share_of_all_stances"])
    out += ["", "## Planted vs swing foot (left/right stance clips)", "",
            "Mean horizontal speed (m/s) of each foot's slower point (heel or ball) over the middle half of "
            f"the clip; `planted_contact`: the planted foot over its own contact frames; `still`: share of "
            f"clips whose planted foot is at most {report['still_speed_mps']} m/s over the middle half.", ""]
    out += _table(report["stance_speeds"], ["action", "style", "clips", "planted_mid_mps", "swing_mid_mps",
                                            "planted_contact_mps", "share_planted_mid_still"])
    out += ["", "## Clip lengths and canonical timelines", ""]
    out += _table(report["lengths"], ["action", "primitive", "clips", "frames_min", "frames_median", "frames_max",
                                      "duration_mean_s", "duration_sd_s", "canonical_frames"])
    out += ["", "## Clips per action × primitive × style", ""]
    styles = sorted({r["style"] for r in report["counts"]})
    grid: dict[tuple[str, str], dict[str, int]] = defaultdict(dict)
    for r in report["counts"]:
        grid[(r["action"], r["primitive"])][r["style"]] = r["clips"]
    out += ["| action | primitive | " + " | ".join(styles) + " | total |", "|" + "---|" * (len(styles) + 3)]
    for (action, primitive), per in grid.items():
        out.append(f"| {action} | {primitive} | " + " | ".join(str(per.get(s, 0)) for s in styles)
                   + f" | {sum(per.values())} |")
    out += ["", "## Rejections by reason", ""]
    out += _table(report["rejection_reasons"], ["kind", "reason", "count"]) if report["rejection_reasons"] \
        else ["none"]
    steps = [r for r in report["rejections"] if r["kind"] != "border"]
    if steps:
        out += ["", f"Rejected takes and steps ({len(steps)}; border steps are listed in report.json):", ""]
        out += [f"- {r['take']} [{r['start']}:{r['stop']}] ({r['content']}, {r['style']}): {r['reason']}"
                if r["start"] is not None else f"- {r['take']} ({r['content']}, {r['style']}): {r['reason']}"
                for r in steps[:200]]
        if len(steps) > 200:
            out.append(f"- … {len(steps) - 200} more in report.json")
    out += ["", "## Figures", ""]
    out += [f"![{Path(p).stem}]({p})" for p in sheets]
    out += [f"- [{Path(p).stem}]({p})" for p in plots]
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------------------------------------
# Writing


def _chosen_takes(takeset: TakeSet, seg: Segmentation, per_group: int, rejected: int) -> list[str]:
    by_group: dict[tuple[str, str], list[tuple[bool, str]]] = defaultdict(list)
    actions = {s.take: s.action for s in seg.takes}
    for take in takeset.takes:
        if take.name in actions:  # straight takes (content == action) first
            by_group[(actions[take.name], take.style)].append((take.content != actions[take.name], take.name))
    chosen = [n for group in sorted(by_group) for _, n in sorted(by_group[group])[:per_group]]
    bad = sorted({r.take for r in seg.rejections if r.kind != "border"} - set(chosen))
    return chosen + bad[:rejected]


def _sheet_rows(clips: list[Clip], action: str, per_primitive: int) -> dict[str, list]:
    rows: dict[str, list] = {}
    for primitive in PRIMITIVES:
        cs = [c for c in clips if c.action == action and c.primitive == primitive]
        if not cs:
            continue
        styles = sorted({c.style for c in cs})
        picked: list[Clip] = []
        for i in range(min(per_primitive, len(cs))):  # round-robin over styles
            pool = [c for c in cs if c.style == styles[i % len(styles)]]
            picked.append(pool[(i // len(styles)) % len(pool)])
        rows[primitive] = [(f"{c.style} {c.take.split('_')[-1]}[{c.start}:{c.stop}]", c.positions, c.contacts)
                           for c in picked]
    return rows


#: Statistics a canonical timeline can take (``timeline=``).
TIMELINE_STATISTICS = ("median", "mean", "min", "max")


def check_report_values(cfg: DictConfig | dict) -> None:
    """Refuse a bad ``timeline`` or a count that is not a whole number ≥ 0 (``plot_takes=-3`` would be read as
    a slice), naming the key, before any work.

    Raises:
        ConfigError: naming the key and the value.
    """
    timeline = cfg.get("timeline", "median")
    if timeline not in TIMELINE_STATISTICS:
        raise ConfigError(f"timeline={timeline!r} is not a statistic of clip lengths; one of "
                          f"{list(TIMELINE_STATISTICS)}")
    for key in ("plot_takes", "plot_rejected", "sheet_clips"):
        value = cfg.get(key, 0)
        if isinstance(value, bool) or not isinstance(value, int) or value < 0:
            raise ConfigError(f"{key} must be a whole number ≥ 0, got {value!r}")


def write_report(cfg: DictConfig | dict, out: Path, force: bool = False, command: str = "") -> dict[str, Any]:
    """Segment ``cfg.data`` and write the report folder ``out`` (see the module docstring).

    Raises:
        OutputExistsError: ``out`` exists and ``force`` is false.
    """
    from stylemotion.viz.segmentation import plot_take_segmentation
    from stylemotion.viz.stick import render_contact_sheet

    out = check_new_output(out, force)
    cfg = OmegaConf.create(cfg) if isinstance(cfg, dict) else cfg
    check_report_values(cfg)
    settings = SegmentSettings.from_dict(OmegaConf.to_container(cfg.segment, resolve=True) if cfg.get("segment")
                                         else {})
    takeset = build_dataset(cfg.data)
    seg = segment_takes(takeset.takes, settings)
    report = build_report(takeset, seg, settings, str(cfg.get("timeline", "median")))
    with atomic_folder(out) as tmp:
        by_name: dict[str, Take] = {t.name: t for t in takeset.takes}
        seg_by_name = {s.take: s for s in seg.takes}
        plots = []
        for name in _chosen_takes(takeset, seg, int(cfg.get("plot_takes", 1)), int(cfg.get("plot_rejected", 6))):
            file_name = f"{safe_name(name, 'take name')}.png"  # take names come from file and zip member paths
            while f"takes/{file_name}" in plots:  # two names that sanitize alike keep both plots
                file_name = file_name[:-4] + "_.png"
            plot_take_segmentation(by_name[name], seg_by_name[name], inside(tmp, "takes", file_name),
                                   settings.contacts)
            plots.append(f"takes/{file_name}")
        sheets = []
        for action in settings.actions:
            rows = _sheet_rows(seg.clips, action, int(cfg.get("sheet_clips", 4)))
            if rows:
                sheet = f"clips_{safe_name(action, 'action')}.png"
                render_contact_sheet(rows, inside(tmp, sheet),
                                     title=f"{takeset.name} {action}: clips per primitive (each starts at the "
                                           "origin facing +Z)")
                sheets.append(sheet)
        report["figures"] = {"takes": plots, "sheets": sheets}
        report["command"] = command
        report["provenance"] = provenance(command or None)
        write_json(tmp / "report.json", report)
        (tmp / "report.md").write_text(format_report(report, command, plots, sheets))
    return report


def summary_lines(report: dict[str, Any], out: Path) -> list[str]:
    """A few lines for the terminal and the command's log: coverage per action, where the report is."""
    lines = []
    if not report["coverage_by_action"]:
        d = report["dataset"]
        lines.append(f"no take of {d['name']} was segmented: {d['ignored_takes']} takes of contents "
                     f"{d['ignored_contents']} are none of the actions {list(report['settings']['actions'])}")
    for row in report["coverage_by_action"]:
        cov = "–" if row["coverage"] is None else f"{row['coverage']:.1%}"
        lines.append(f"{row['action']}: {row['clips']} clips of {row['complete_steps']} complete steps ({cov}); "
                     f"{row['border_steps']} border steps, {row['rejected_takes']} rejected takes")
    lines.append(f"report written to {out}")
    return lines
