"""A walk along a ground path, neutral or stylized, written to a folder (what ``stylemotion-generate`` runs; §5.4.4).

    stylemotion-generate                                          # neutral, 10 m S-curve, synthetic run
    stylemotion-generate run=runs/reproduce/bandai style=elderly seed=3
    stylemotion-generate style=active path.file=path.csv out=runs/generate/active_path
    stylemotion-generate run=runs/style/mine style=mine           # a style made by stylemotion-style

The models come from a ``stylemotion-reproduce`` folder (``run``), a ``stylemotion-style`` folder (``run``:
its new style, and through the reproduce run it extends ``neutral`` and the run's styles) or an
explicit ``models`` mapping;
the path from ``path.file`` (.json/.csv), ``path.points`` or the default S-curve
(:mod:`stylemotion.synthesis.path`). The walk is synthesized by
:func:`stylemotion.synthesis.controller.follow_path` and written to the folder ``out`` (refused if
it exists, unless ``force=true``; the folder appears complete or not at all):

* ``motion.npz``: ``positions`` (frames, 21, 3) float32 metres Y up (after the foot clean-up of
  :mod:`stylemotion.synthesis.cleanup` unless ``clean_feet=false``), ``frames`` (frames, 66: the
  stitched frames as synthesized, before the clean-up),
  ``fps``, ``path`` (n, 2) x/z metres, ``junctions`` (keyframe index of each transition),
  ``joint_names``;
* ``motion.bvh``: the canonical skeleton with rotations fitted to the positions
  (:mod:`stylemotion.io.export`);
* ``motion.gif`` (and ``motion.mp4`` with ``outputs.mp4=true``, by imageio-ffmpeg's ffmpeg): the stick figure
  on the path;
* ``summary.json``: :func:`stylemotion.synthesis.quality.walk_figures`, the BVH round trip error,
  the real data's foot-skating ratio for the style, the steps, the settings and provenance.
"""

from __future__ import annotations

import io
import logging
import math
import time
from collections.abc import Mapping
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from stylemotion.config import ConfigError
from stylemotion.datasets.loading import ConversionSettings, load_canonical_positions
from stylemotion.io.atomic import atomic_folder
from stylemotion.io.export import write_motion_bvh
from stylemotion.io.jsonfile import read_json, write_json
from stylemotion.io.outputs import check_new_output
from stylemotion.io.sources import FileSource
from stylemotion.models.loading import NEUTRAL
from stylemotion.provenance import provenance
from stylemotion.skeleton import CANONICAL_JOINTS
from stylemotion.synthesis.cleanup import clean_foot_skating
from stylemotion.synthesis.controller import FollowSettings, SynthesizedMotion, follow_path
from stylemotion.synthesis.graph import extended_run, load_graph, style_folder_meta
from stylemotion.synthesis.path import GroundPath, s_curve
from stylemotion.synthesis.quality import skating, walk_figures
from stylemotion.viz.walk import save_walk_animation

log = logging.getLogger(__name__)


def path_from_config(node: Mapping[str, Any]) -> GroundPath:
    """The path of a ``path`` config node: ``file``, else ``points``, else ``s_curve``."""
    if node.get("file"):
        return GroundPath.from_file(node["file"], spline=bool(node.get("spline", True)))
    if node.get("points") is not None:
        return GroundPath.from_points(node["points"], spline=bool(node.get("spline", True)), source="path.points")
    curve = node.get("s_curve") or {}
    return s_curve(float(curve.get("length_m", 10.0)), float(curve.get("amplitude_m", 1.0)),
                   float(curve.get("waves", 1.0)))


def bvh_round_trip_error(bvh: Path, positions: np.ndarray, fps: float) -> tuple[float, float]:
    """Mean and largest joint distance (m) between ``positions`` and the BVH file read back by the project's own
    loader."""
    back = load_canonical_positions(FileSource(str(bvh)), ConversionSettings(fps=fps))
    if back.shape != positions.shape:
        raise RuntimeError(f"{bvh} reads back as {back.shape}, expected {positions.shape}")
    distance = np.linalg.norm(back - positions, axis=-1)
    return float(distance.mean()), float(distance.max())


def rigid_bones(positions: np.ndarray) -> tuple[np.ndarray, dict[str, float]]:
    """``positions`` ``(frames, 21, 3)`` with every bone at its median length (directions kept, placed from the
    root outwards: :func:`stylemotion.bones.retarget_positions`), and what that changed: the largest relative
    spread of a bone's length before (``(max − min) / median``) and the mean and largest joint shift (m). The
    decoder's positions stretch bones from frame to frame, which no skeleton of a BVH file can follow."""
    from stylemotion.bones import BONE_JOINTS, median_bone_lengths, retarget_positions
    from stylemotion.skeleton import bone_lengths

    lengths = bone_lengths(np.asarray(positions, dtype=np.float64))[:, list(BONE_JOINTS)]
    median = median_bone_lengths(positions)
    spread = float(((lengths.max(0) - lengths.min(0)) / np.maximum(median, 1e-9)).max())
    fixed = retarget_positions(positions, median)
    shift = np.linalg.norm(fixed - positions, axis=-1)
    return fixed, {"bone_length_spread_before": spread, "mean_shift_m": float(shift.mean()),
                   "max_shift_m": float(shift.max())}


def real_foot_skating(run: str | Path | None, style: str) -> float | None:
    """The foot-skating ratio of real clips of ``style`` in a reproduce run's report, if recorded; for the
    new style of a ``stylemotion-style`` folder, that of its example's clips (the run's styles: the run's)."""
    meta = style_folder_meta(run) if run else None
    if meta is not None:
        if style != meta.get("name"):
            return real_foot_skating(extended_run(run, meta), style)
        value = read_json(Path(run).expanduser() / "report.json", "style report").get("foot_skating_pooled", {})
        return None if value.get("example") is None else float(value["example"])
    report = Path(run) / "report" / "report.json" if run else None
    if report is None or not report.is_file():
        return None
    value = read_json(report, "run report").get("foot_skating_real", {}).get(style)
    return None if value is None else float(value)


def write_outputs(motion: SynthesizedMotion, folder: Path, outputs: Mapping[str, Any], title: str) -> dict[str, Any]:
    """Write the motion's files into ``folder``; returns what the BVH round trip measured."""
    buffer = io.BytesIO()
    np.savez(buffer, positions=motion.positions, frames=motion.frames, fps=np.float64(motion.fps),
             path=motion.path.points, junctions=np.asarray(motion.junctions, dtype=np.int64),
             joint_names=np.asarray(CANONICAL_JOINTS))
    (folder / "motion.npz").write_bytes(buffer.getvalue())
    figures: dict[str, Any] = {}
    if outputs.get("bvh", True):
        write_motion_bvh(motion.positions, folder / "motion.bvh", motion.fps)
        mean, largest = bvh_round_trip_error(folder / "motion.bvh", motion.positions, motion.fps)
        figures["bvh_reimport_mpjpe_m"], figures["bvh_reimport_max_m"] = mean, largest
    keys = [s.start_frame for s in motion.steps[1:]]
    if outputs.get("gif", True):
        save_walk_animation(motion.positions, motion.fps, motion.path.points, folder / "motion.gif", keys, title)
    if outputs.get("mp4", False):
        save_walk_animation(motion.positions, motion.fps, motion.path.points, folder / "motion.mp4", keys, title)
    return figures


def model_kind(cfg: Mapping[str, Any]) -> str:
    """``vae`` (no ``model=``: the VAEs of ``run``/``models``) or the chosen model config's ``family``."""
    return "vae" if not cfg.get("model") else str((cfg.get("model") or {}).get("family", "?"))


def walk_graph(cfg: Mapping[str, Any]) -> Any:
    """The graph of stance models a walk of ``cfg`` (a resolved generate config) takes its steps from: the VAEs of
    ``run``/``models`` in ``style``, or the Morphable Graph with ``model=morphable``."""
    kind = model_kind(cfg)
    if kind == "morphable":
        from stylemotion.synthesis.morphable_graph import MapSettings, load_morphable_graph

        try:
            map_settings = MapSettings(**(cfg.get("morphable") or {}))
        except (TypeError, ValueError) as err:  # an unknown or out-of-range morphable.* key
            raise ConfigError(f"morphable.*: {err}") from err
        return load_morphable_graph(cfg.get("models") or {}, action=str(cfg.get("action", "walk")),
                                    settings=map_settings)
    if kind == "vae":
        return load_graph(str(cfg["style"]), run=cfg.get("run"), models=cfg.get("models"),
                          action=str(cfg.get("action", "walk")), neutral_style=str(cfg.get("neutral_style", "normal")))
    raise ConfigError("stylemotion-generate takes model=morphable (the Morphable Graph) or no model= (the VAEs); "
                      f"the chosen model config has family {kind!r}")


def generate(cfg: DictConfig | Mapping[str, Any], command: str = "", graph: Any = None) -> dict[str, Any]:
    """Synthesize and write one walk (see the module doc); returns the summary. ``graph``: the models of
    :func:`walk_graph` for this ``cfg``, loaded once for many walks (default: loaded here)."""
    cfg = OmegaConf.to_container(cfg, resolve=True) if isinstance(cfg, DictConfig) else dict(cfg)
    force = bool(cfg.get("force", False))
    out = check_new_output(cfg["out"], force)
    started = time.perf_counter()
    path = path_from_config(cfg.get("path") or {})
    settings = FollowSettings(**(cfg.get("follow") or {}))  # bad follow.* values are refused before loading
    kind = model_kind(cfg)
    graph = graph if graph is not None else walk_graph(cfg)
    motion = follow_path(graph, path, seed=int(cfg.get("seed", 0)), settings=settings)
    joint = None
    if kind == "morphable":  # Algorithm 1's line 9 where morphable.joint_evaluations asks for it
        from stylemotion.synthesis.morphable_graph import finish_walk

        motion, joint = finish_walk(graph, motion, settings)
    rigid = None
    if cfg.get("rigid_bones", True):
        positions, rigid = rigid_bones(motion.positions)
        motion = replace(motion, positions=positions.astype(np.float32))
    raw_skating, _ = skating(motion.positions, motion.fps)
    if cfg.get("clean_feet", True):
        motion = replace(motion, positions=clean_foot_skating(motion.positions, motion.fps).astype(np.float32))
    summary = walk_figures(motion)
    summary["foot_skating_ratio_before_cleanup"] = raw_skating
    summary["rigid_bones"] = rigid
    if joint is not None:
        summary["joint_optimization"] = joint
    style = graph.style if graph.style != NEUTRAL else str(cfg.get("neutral_style", "normal"))
    summary["real_foot_skating_ratio"] = real_foot_skating(cfg.get("run") if kind == "vae" else None, graph.style)
    title = (f"{graph.action} · {graph.style} · seed {cfg.get('seed', 0)} · {path.length:.1f} m path · "
             f"{summary['duration_s']:.1f} s")
    with atomic_folder(out, on_exists=lambda: check_new_output(out, force)) as tmp:
        summary.update(write_outputs(motion, tmp, cfg.get("outputs") or {}, title))
        summary["meta"] = {
            "style": graph.style, "data_style": style, "seed": int(cfg.get("seed", 0)), "models": graph.sources,
            "model": kind,
            "profiles": {k: asdict(v) for k, v in graph.profiles.items()}, "follow": asdict(settings),
            "path": cfg.get("path"), **provenance(command or None), "seconds": time.perf_counter() - started,
        }
        summary["steps_detail"] = [asdict(s) for s in motion.steps]
        write_json(tmp / "summary.json", summary)
    return summary


def _share(value: float | None) -> str:
    """A ratio as a percentage; "n/a (no planted foot)" when it has no value (NaN, or null when read back)."""
    return "n/a (no planted foot)" if value is None or not math.isfinite(value) else f"{value:.1%}"


def summary_lines(summary: Mapping[str, Any]) -> list[str]:
    """A few lines for the terminal."""
    dev, tr = summary["deviation"], summary["transitions"]
    real = summary.get("real_foot_skating_ratio")
    real = "" if real is None else f"; real clips of the style: {real:.1%}"
    lines = [f"{summary['style']}: {summary['steps']} steps, {summary['duration_s']:.2f} s, "
             f"{summary['walked_m']:.2f} m walked at {summary['mean_speed_mps']:.2f} m/s",
             f"path deviation: mean {dev['mean_m']:.3f} m, max {dev['max_m']:.3f} m, final {dev['final_m']:.3f} m",
             f"transitions: peak joint speed {tr['ratio']:.2f}×, peak acceleration {tr['accel_ratio']:.2f}× the 99th "
             "percentile inside clips",
             f"foot skating {_share(summary['foot_skating_ratio'])} (before clean-up "
             f"{_share(summary['foot_skating_ratio_before_cleanup'])})" + real,
             f"synthesis {summary['synthesis_seconds']:.2f} s"]
    joint = summary.get("joint_optimization")
    if joint:
        lines.append(f"all steps optimized together (Algorithm 1, line 9): objective {joint['objective_before']:.2f} → "
                     f"{joint['objective_after']:.2f}, step-target error {joint['target_error_before']:.2f} → "
                     f"{joint['target_error_after']:.2f}, {joint['evaluations']} evaluations, {joint['seconds']:.1f} s")
    if "bvh_reimport_mpjpe_m" in summary:
        lines.append(f"BVH re-import MPJPE {summary['bvh_reimport_mpjpe_m'] * 100:.2f} cm")
    lines += [f"warning: {w}" for w in summary.get("warnings", [])]
    return lines
