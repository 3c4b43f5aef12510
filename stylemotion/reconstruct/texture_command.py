"""What ``stylemotion-texture`` runs: motion completion or texturing with a motion database (Krüger §4.2).

    stylemotion-texture motion=legs.npz mode=complete data=bandai out=runs/texture/mine
    stylemotion-texture motion=synthetic_walk_normal_000 mode=complete 'data.styles=[elderly]'

``motion`` is a BVH (``file.bvh[:start-end]``), an NPZ as ``stylemotion-convert`` writes it (in complete mode the
untrusted joints may be NaN) or a take of the dataset (left out of the database unless
``exclude_motion_take=false``). The folder ``out`` (refused when it exists unless ``force``; built beside it and
renamed into place) holds ``motion.npz`` (``positions`` (frames, 21, 3) float32 metres in the input's world frame,
``joint_names``, ``fps``), ``motion.bvh``, ``motion.gif`` (unless ``gif=false``) and ``summary.json``: settings,
database, timings, foot skating before and after, provenance and, for a complete input motion, the error per
joint in cm (complete mode: on the untrusted joints, with the nearest-neighbour baseline).
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig

from stylemotion.config import ConfigError, settings_from_config
from stylemotion.datasets import TakeSet
from stylemotion.datasets.user_motion import conversion_keys, parse_example
from stylemotion.io.outputs import check_new_output
from stylemotion.provenance import provenance
from stylemotion.reconstruct.inputs import command_takeset, database_without
from stylemotion.reconstruct.markers import read_markers
from stylemotion.reconstruct.output import write_motion_folder
from stylemotion.reconstruct.settings import TextureSettings
from stylemotion.reconstruct.texture import LEG_JOINTS, MODES, MotionTexturer, TextureInputError, check_joints
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX, NUM_JOINTS

log = logging.getLogger(__name__)
_D = TextureSettings


def load_motion(text: str, takeset: TakeSet, joints: Sequence[str],
                conversion: Mapping[str, Any] | None = None) -> tuple[np.ndarray, np.ndarray | None, str | None]:
    """The motion ``motion=`` names as ``(frames, 21, 3)`` metres (NaN where only untrusted joints are missing),
    the complete motion for error figures (or None) and the take it is (None for a file)."""
    names = {t.name: t for t in takeset.takes}
    if text in names and not Path(text).expanduser().is_file():
        positions = np.asarray(names[text].positions, dtype=np.float64)
        return positions, positions, text
    if not text:
        raise TextureInputError("motion= is empty: give a BVH or NPZ file or a take of the dataset")
    name, _, frames = text.rpartition(":")
    if name in names and not Path(text).expanduser().is_file():  # <take>:start-end, frames of the take
        spec = parse_example(text, "motion")
        if spec.start is None or spec.end is None:
            raise TextureInputError(f"motion={text}: after a take's name give a frame range START-END "
                                    f"(e.g. motion={name}:0-120)")
        if spec.end > len(names[name].positions):
            raise TextureInputError(f"motion={text}: the frame range {frames} runs past the take's "
                                    f"{len(names[name].positions)} frames (END exclusive)")
        positions = np.asarray(names[name].positions[spec.start:spec.end], dtype=np.float64)
        return positions, positions, name
    tracks = read_markers(text, joints, takeset.fps, dict(conversion or {}))
    if tracks.full is not None:
        return np.asarray(tracks.full, dtype=np.float64), np.asarray(tracks.full, dtype=np.float64), None
    motion = np.full((tracks.num_frames, NUM_JOINTS, 3), np.nan)
    motion[:, [JOINT_INDEX[j] for j in tracks.joints]] = tracks.positions
    return motion, None, None


def _errors_cm(positions: np.ndarray, truth: np.ndarray, joints: Sequence[str]) -> dict[str, Any]:
    idx = [JOINT_INDEX[j] for j in joints]
    err = np.linalg.norm(positions[:, idx] - truth[:, idx], axis=-1) * 100.0
    return {"joints": list(joints), "mean_cm": round(float(err.mean()), 4), "max_cm": round(float(err.max()), 4),
            "per_joint_mean_cm": {j: round(float(err[:, i].mean()), 3) for i, j in enumerate(joints)}}


def texture_command(data: Mapping[str, Any], motion: str, out: str | os.PathLike, *, mode: str = _D.mode,
                    joints: Sequence[str] | None = _D.joints, k: int = _D.k,
                    exclude_motion_take: bool = _D.exclude_motion_take, model: Mapping[str, Any] | None = None,
                    conversion: Mapping[str, Any] | None = None,
                    force: bool = _D.force, gif: bool = _D.gif, command: str = "") -> dict[str, Any]:
    """Complete or texture ``motion`` on the database ``data`` (a ``data`` config) and write ``out`` (module
    docstring). ``model``: further :class:`MotionTexturer` settings. The defaults are
    :class:`~stylemotion.reconstruct.settings.TextureSettings`'s. Returns what ``summary.json`` holds.

    Raises:
        OutputExistsError: ``out`` exists and ``force`` is off (before any work).
        TextureInputError, MarkerInputError, ConfigError: a bad value (naming it); nothing is written then.
    """
    from stylemotion.synthesis.quality import skating

    started = time.perf_counter()
    out = check_new_output(out, force)
    if mode not in MODES:
        raise TextureInputError(f"mode={mode} is not one of {list(MODES)}")
    trusted = check_joints((LEG_JOINTS if mode == "complete" else CANONICAL_JOINTS) if joints is None else joints)
    takeset = command_takeset(data)
    positions, truth, take = load_motion(str(motion or "").strip(), takeset, trusted, conversion)
    database = database_without(takeset, {take} if exclude_motion_take and take else set(), f"motion={motion}")
    log.info(f"database {database.name}: {database.num_takes} takes, {database.num_frames} frames; motion {motion}: "
             f"{len(positions)} frames, mode {mode}")
    try:
        texturer = MotionTexturer(database, mode, trusted, k, **dict(model or {}))
    except TypeError as exc:
        raise ConfigError(f"model: {exc}") from None
    result = texturer.apply(positions)
    skate_in = skating(positions, database.fps) if np.all(np.isfinite(positions)) else None
    skate_raw, skate_out = skating(result.raw, database.fps), skating(result.positions, database.fps)
    summary: dict[str, Any] = {
        "motion": {"value": str(motion), "frames": len(positions), "fps": database.fps,
                   "excluded_take": take if exclude_motion_take else None},
        "settings": result.settings,
        "database": {**result.settings["database"], "digest": database.digest},
        "foot_skating_ratio": {"input": None if skate_in is None else round(skate_in[0], 4),
                               "before_cleanup": round(skate_raw[0], 4), "after_cleanup": round(skate_out[0], 4)},
        "timing_s": {key: round(v, 4) for key, v in result.timings.items()},
    }
    if truth is not None:
        scored = [j for j in CANONICAL_JOINTS if j not in trusted] if mode == "complete" else list(CANONICAL_JOINTS)
        summary["error"] = _errors_cm(result.positions, truth, scored)
        if mode == "complete":
            summary["error_nearest_neighbour"] = _errors_cm(result.nearest_neighbour, truth, scored)
    summary["provenance"] = provenance(command or None)
    write_motion_folder(out, force, result.positions, database.fps, summary, started, gif=gif)
    error = summary.get("error")
    log.info(f"{len(positions)} frames ({mode}) into {out}"
             + (f"; error {error['mean_cm']:.2f} cm mean per joint" if error else ""))
    return summary


def texture_from_config(cfg: DictConfig, command: str = "") -> dict[str, Any]:
    """:func:`texture_command` with the keys of ``stylemotion/configs/texture.yaml`` (:class:`TextureSettings`)."""
    data, s = settings_from_config(cfg, TextureSettings, "texture")
    return texture_command(
        data, s.motion, s.out, mode=s.mode, joints=s.joints, k=s.k, exclude_motion_take=s.exclude_motion_take,
        model=asdict(s.model), conversion=conversion_keys(vars(s)), force=s.force, gif=s.gif,
        command=command)
