"""Human- and machine-readable summaries of a dataset and its split."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from stylemotion.datasets.base import Take, TakeSet
from stylemotion.io.jsonfile import write_json


def dataset_summary(takeset: TakeSet, split: dict[str, list[Take]] | None = None) -> dict[str, Any]:
    """Counts of takes and frames per content × style, split sizes, skipped inputs, warnings and the
    skeleton the takes were retargeted to (``retarget``: None when each keeps its own bones)."""
    takes = Counter((t.content, t.style) for t in takeset.takes)
    frames: Counter[tuple[str, str]] = Counter()
    for t in takeset.takes:
        frames[(t.content, t.style)] += t.num_frames
    summary: dict[str, Any] = {
        "dataset": takeset.name,
        "fps": takeset.fps,
        "takes": len(takeset),
        "frames": takeset.num_frames,
        "seconds": round(takeset.num_frames / takeset.fps, 2),
        "per_content_style": [
            {"content": c, "style": s, "takes": takes[(c, s)], "frames": frames[(c, s)]}
            for c, s in sorted(takes)
        ],
        "skipped": [{"source": src, "reason": why} for src, why in takeset.skipped],
        "warnings": list(takeset.warnings),
        "retarget": takeset.retarget,
    }
    if split is not None:
        summary["split"] = {part: {"takes": len(ts), "frames": sum(t.num_frames for t in ts)}
                            for part, ts in split.items()}
    return summary


def format_summary(summary: dict[str, Any]) -> str:
    """A plain-text table of :func:`dataset_summary`."""
    lines = [f"dataset {summary['dataset']}: {summary['takes']} takes, {summary['frames']} frames "
             f"({summary['seconds']} s at {summary['fps']:g} fps)"]
    lines.append(f"  {'content':<20} {'style':<12} {'takes':>6} {'frames':>8}")
    for row in summary["per_content_style"]:
        lines.append(f"  {row['content']:<20} {row['style']:<12} {row['takes']:>6} {row['frames']:>8}")
    target = summary.get("retarget")
    if target:
        bones = target["bone_lengths_m"]
        lines.append(f"  retargeted: every take on the median bones of the {target['takes']} {target['style']!r} "
                     f"takes (left thigh {bones['LowerLeg_L']:.3f} m, shin {bones['Foot_L']:.3f} m)")
    for part, info in summary.get("split", {}).items():
        lines.append(f"  split {part:<5}: {info['takes']} takes, {info['frames']} frames")
    if summary["skipped"]:
        lines.append(f"  skipped {len(summary['skipped'])} broken input(s):")
        lines.extend(f"    {s['reason']}" for s in summary["skipped"])
    if summary.get("warnings"):
        lines.append(f"  {len(summary['warnings'])} input(s) loaded but look wrong:")
        lines.extend(f"    {w}" for w in summary["warnings"])
    return "\n".join(lines)


def write_dataset_summary(data_cfg: Mapping[str, Any], out_dir: str | Path) -> dict[str, Any]:
    """Build the dataset of ``data_cfg``, split it as ``data_cfg.split`` says and write
    ``summary.json`` into ``out_dir``; returns the summary."""
    from stylemotion.datasets import build_dataset
    from stylemotion.provenance import provenance

    takeset = build_dataset(data_cfg)
    split = takeset.split(**(data_cfg.get("split") or {}))
    summary = dataset_summary(takeset, split)
    summary["provenance"] = provenance()
    write_json(Path(out_dir) / "summary.json", summary, indent=2)
    return summary
