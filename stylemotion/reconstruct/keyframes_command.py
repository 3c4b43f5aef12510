"""What ``stylemotion-keyframes`` runs: a motion through a few keyframes with dynamic motion graphs (Krüger §4.3).

    stylemotion-keyframes keys=keys.json data=bandai out=runs/keyframes/mine

``keys`` is a JSON file (docs/reconstruct.md, "Keyframe files")::

    {"keys": [
      {"time": 0.0, "take": "dataset-2_walk_normal_001", "frame": 40},
      {"time": 2.0, "motion": "walk.bvh", "frame": 100, "turn_deg": 30, "shift_m": [0.5, 0.0, 0.0]},
      {"time": 4.0, "positions": [[x, y, z], ... 21 canonical joints, metres]}
    ]}

or, for keys every ``every_s`` seconds of one motion (a take of the dataset or a BVH/NPZ file),
``{"motion": "walk.bvh", "every_s": 2.0, "start_s": 0.0, "end_s": 8.0}``. Times are seconds; ``turn_deg`` turns
the pose about the vertical through its Hips, ``shift_m`` then moves it (metres, Y up). File paths are relative to
the JSON file's folder. Takes that give keys are left out of the database unless ``exclude_key_takes=false``
(the thesis removed the motion its keys came from).

The folder ``out`` (refused when it exists unless ``force``; built beside it and renamed into place) holds
``motion.npz`` (``positions`` (frames, 21, 3) float32 metres in the keys' world frame, ``joint_names``, ``fps``),
``motion.bvh``, ``motion.gif`` (unless ``gif=false``) and ``summary.json``: the keys and their frames, per key
pair the search figures (iterations, nodes, connections, duration error, cost, the intermediate result's key
error), foot skating before and after cleaning, settings, timings and provenance.
"""

from __future__ import annotations

import json
import logging
import os
import time
import warnings
from collections.abc import Mapping
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig

from stylemotion.config import ConfigError, settings_from_config
from stylemotion.datasets import TakeSet
from stylemotion.datasets.user_motion import conversion_keys
from stylemotion.io.outputs import check_new_output
from stylemotion.provenance import provenance
from stylemotion.reconstruct.inputs import command_takeset, database_without
from stylemotion.reconstruct.keyframes import (
    DynamicMotionGraph,
    FarKeyframeWarning,
    Keyframe,
    KeyframeError,
    check_keyframes,
    keys_from_motion,
    placements,
    turn_key,
)
from stylemotion.reconstruct.markers import read_markers
from stylemotion.reconstruct.output import write_motion_folder
from stylemotion.reconstruct.settings import KeyframesSettings
from stylemotion.skeleton import CANONICAL_JOINTS, NUM_JOINTS

log = logging.getLogger(__name__)
_D = KeyframesSettings
_KEY_FIELDS = {"time", "take", "motion", "frame", "positions", "turn_deg", "shift_m"}


def _motion_positions(value: str, where: str, takes: Mapping[str, Any], folder: Path, fps: float,
                      conversion: Mapping[str, Any]) -> tuple[np.ndarray, str | None]:
    """``(frames, 21, 3)`` metres of a take name or a BVH/NPZ file (relative to ``folder``), and the take."""
    if value in takes and not (folder / value).is_file():
        return np.asarray(takes[value].positions, dtype=np.float64), value
    path = value if Path(value.split(":")[0]).is_absolute() else str(folder / value)
    try:
        tracks = read_markers(path, CANONICAL_JOINTS, fps, dict(conversion))
    except ValueError as exc:
        raise KeyframeError(f"{where}: {exc}") from None
    if tracks.full is None:
        raise KeyframeError(f"{where}: {value} holds marker tracks, not a whole motion")
    return np.asarray(tracks.full, dtype=np.float64), None


def _number(entry: Mapping[str, Any], key: str, where: str, default: float | None = None) -> float:
    value = entry.get(key, default)
    if value is None or isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
        raise KeyframeError(f"{where}: {key}={value!r} must be a finite number")
    return float(value)


#: Farthest a key's joint may lie from the origin (m): far beyond any capture volume, well within float range.
MAX_KEY_DISTANCE_M = 1e5


def _turned(pose: np.ndarray, entry: Mapping[str, Any], where: str) -> np.ndarray:
    """The pose turned by ``turn_deg`` about its Hips' vertical and moved by ``shift_m``."""
    turn = np.deg2rad(_number(entry, "turn_deg", where, 0.0))
    shift = np.asarray(entry.get("shift_m", [0.0, 0.0, 0.0]), dtype=np.float64)
    if shift.shape != (3,) or not np.isfinite(shift).all():
        raise KeyframeError(f"{where}: shift_m={entry.get('shift_m')!r} must be [x, y, z] metres")
    with np.errstate(over="ignore", invalid="ignore"):
        moved = turn_key(pose, turn, shift)
    if not np.isfinite(moved).all() or np.abs(moved).max() > MAX_KEY_DISTANCE_M:
        raise KeyframeError(f"{where}: turn_deg={entry.get('turn_deg', 0.0)!r}, shift_m={entry.get('shift_m')!r} "
                            f"put the pose more than {MAX_KEY_DISTANCE_M:g} m from the origin; give a shift of "
                            "metres in the motion's space")
    return moved


def read_keys(path: str | os.PathLike, takeset: TakeSet,
              conversion: Mapping[str, Any] | None = None) -> tuple[list[Keyframe], list[dict], set[str]]:
    """The keyframes of a JSON file (module docstring), a JSON-ready description of each, and the dataset takes
    they came from. KeyframeError naming the file, the key and the value otherwise."""
    path = Path(path)
    if not path.is_file():
        raise KeyframeError(f"keys={path}: no such file")
    try:
        spec = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise KeyframeError(f"keys={path}: line {exc.lineno}: not valid JSON ({exc.msg})") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise KeyframeError(f"keys={path}: cannot read this keys file ({exc})") from None
    takes = {t.name: t for t in takeset.takes}
    conversion = dict(conversion or {})
    if not isinstance(spec, dict) or ("keys" in spec) == ("every_s" in spec):
        raise KeyframeError(f"keys={path}: give an object with a 'keys' list, or 'motion' and 'every_s'")
    if "every_s" in spec:
        where = f"keys={path}"
        positions, take = _motion_positions(str(spec.get("motion", "")), where, takes, path.parent, takeset.fps,
                                            conversion)
        end = spec.get("end_s")
        try:
            keys = keys_from_motion(positions, takeset.fps, _number(spec, "every_s", where),
                                    _number(spec, "start_s", where, 0.0), None if end is None else float(end))
        except KeyframeError as exc:  # named after the file the value came from
            raise KeyframeError(f"{where}: {exc}") from None
        described = [{"time_s": k.time_s, "motion": spec["motion"],
                      "frame": int(round((_number(spec, "start_s", where, 0.0) + k.time_s) * takeset.fps))}
                     for k in keys]
        return keys, described, {take} if take else set()
    entries = spec["keys"]
    if not isinstance(entries, list):
        raise KeyframeError(f"keys={path}: 'keys' must be a list")
    keys, described, used = [], [], set()
    for i, entry in enumerate(entries):
        where = f"keys={path}: keys[{i}]"
        if not isinstance(entry, dict):
            raise KeyframeError(f"{where}: must be an object, got {entry!r}")
        unknown = sorted(set(entry) - _KEY_FIELDS)
        if unknown:
            raise KeyframeError(f"{where}: unknown field(s) {unknown}; valid: {sorted(_KEY_FIELDS)}")
        time_s = _number(entry, "time", where)
        if "positions" in entry:
            try:
                pose = np.asarray(entry["positions"], dtype=np.float64)
            except (TypeError, ValueError, OverflowError):
                pose = np.zeros(0)  # refused below: not a grid of numbers
            if pose.shape != (NUM_JOINTS, 3):
                raise KeyframeError(f"{where}: positions must be {NUM_JOINTS} [x, y, z] rows (canonical joints, "
                                    f"metres), got shape {pose.shape}")
            source = {"positions": True}
        elif "take" in entry or "motion" in entry:
            value = str(entry.get("take", entry.get("motion")))
            if "take" in entry and value not in takes:
                raise KeyframeError(f"{where}: take={value!r} is not a take of dataset {takeset.name!r}")
            positions, take = _motion_positions(value, where, takes, path.parent, takeset.fps, conversion)
            frame = entry.get("frame", 0)
            if isinstance(frame, bool) or not isinstance(frame, int) or not 0 <= frame < len(positions):
                raise KeyframeError(f"{where}: frame={frame!r} must be a frame of {value} (0 to {len(positions) - 1})")
            pose = positions[frame]
            source = {"take" if take else "motion": value, "frame": frame}
            if take:
                used.add(take)
        else:
            raise KeyframeError(f"{where}: give 'positions', or 'take' or 'motion' with 'frame'")
        pose = _turned(pose, entry, where)
        keys.append(Keyframe(time_s, pose))
        described.append({"time_s": time_s, **source, "turn_deg": entry.get("turn_deg", 0.0),
                          "shift_m": entry.get("shift_m", [0.0, 0.0, 0.0])})
    try:
        check_keyframes(keys)
    except KeyframeError as exc:
        raise KeyframeError(f"keys={path}: {exc}") from None
    return keys, described, used


def keyframes_command(data: Mapping[str, Any], keys: str | os.PathLike, out: str | os.PathLike, *,
                      exclude_key_takes: bool = _D.exclude_key_takes, model: Mapping[str, Any] | None = None,
                      conversion: Mapping[str, Any] | None = None,
                      force: bool = _D.force, gif: bool = _D.gif, command: str = "") -> dict[str, Any]:
    """A motion through the keys of the JSON file ``keys`` on the database ``data`` (a ``data`` config), written
    to ``out`` (module docstring). ``model``: :class:`DynamicMotionGraph` settings. The defaults are
    :class:`~stylemotion.reconstruct.settings.KeyframesSettings`'s. Returns what ``summary.json`` holds.

    Raises:
        OutputExistsError: ``out`` exists and ``force`` is off (before any work).
        KeyframeError, ConfigError: a bad value (naming it); NoConnectionError: two keys the search could not
        join (naming them). Nothing is written then.
    """
    from stylemotion.synthesis.quality import skating

    started = time.perf_counter()
    out = check_new_output(out, force)
    takeset = command_takeset(data)
    key_list, described, used = read_keys(keys, takeset, conversion)
    database = database_without(takeset, used if exclude_key_takes else set(), "the keys' takes")
    log.info(f"database {database.name}: {database.num_takes} takes, {database.num_frames} frames; "
             f"{len(key_list)} keys over {key_list[-1].time_s - key_list[0].time_s:g} s")
    try:
        graph = DynamicMotionGraph(database, **dict(model or {}))
    except TypeError as exc:
        raise ConfigError(f"model: {exc}") from None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", FarKeyframeWarning)
        result = graph.synthesize(key_list)
    for warning in caught:
        log.warning(f"warning: {warning.message}")
    skate_mid, skate_out = skating(result.intermediate, database.fps), skating(result.positions, database.fps)
    summary: dict[str, Any] = {
        "keys": [{**d, "frame_in_motion": f} for d, f in zip(described, result.key_frames)],
        "excluded_takes": sorted(used) if exclude_key_takes else [],
        "pairs": result.pairs,
        "frames": len(result.positions), "fps": database.fps,
        "foot_skating_ratio": {"intermediate": round(skate_mid[0], 4), "result": round(skate_out[0], 4)},
        "warnings": [str(w.message) for w in caught],
        "settings": result.settings,
        "database": {**result.settings["database"], "digest": database.digest},
        "timing_s": dict(result.timings),
    }
    summary["provenance"] = provenance(command or None)
    ground = np.stack([placements(np.asarray(k.pose)[None], database.fps)[0][0] for k in key_list])
    write_motion_folder(out, force, result.positions, database.fps, summary, started, gif=gif,
                        gif_path_xz=ground[:, [0, 2]], gif_keys=result.key_frames,
                        gif_title=f"{len(key_list)} keyframes, database {database.name}")
    log.info(f"{len(result.positions)} frames through {len(key_list)} keys into {out}")
    return summary


def keyframes_from_config(cfg: DictConfig, command: str = "") -> dict[str, Any]:
    """:func:`keyframes_command` with the keys of ``stylemotion/configs/keyframes.yaml``
    (:class:`KeyframesSettings`)."""
    data, s = settings_from_config(cfg, KeyframesSettings, "keyframes")
    if not s.keys:
        raise ConfigError("keys= is empty: give a keyframe JSON file (stylemotion-keyframes --help)")
    return keyframes_command(
        data, s.keys, s.out, exclude_key_takes=s.exclude_key_takes, model=asdict(s.model),
        conversion=conversion_keys(vars(s)), force=s.force, gif=s.gif, command=command)
