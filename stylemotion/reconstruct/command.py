"""What ``stylemotion-reconstruct`` runs: full poses from a few marker tracks (Krüger §2.5.2).

    stylemotion-reconstruct markers=tracks.csv data=bandai out=runs/reconstruct/mine
    stylemotion-reconstruct markers=synthetic_walk_normal_000 features=E15x3 k=128 'joints=[Hand_L,Hand_R,Hips]'

    stylemotion-reconstruct markers=capture.c3d marker_set=skin data=bandai subject=calibration.bvh

``markers`` is a BVH (``file.bvh[:start-end]``, any skeleton a joint map names; its canonical joints become the
markers), an NPZ as ``stylemotion-convert`` writes it, a CSV of marker tracks at any rate (resampled to the
dataset's; :mod:`stylemotion.reconstruct.markers`), a C3D (with a skin-marker set,
:mod:`stylemotion.reconstruct.capture`), or the name of a take of the dataset (then left out of the database
unless ``exclude_markers_take=false``). ``joints`` picks the markers at joint centres (default: hands, feet,
head, hips; a CSV's own columns); ``marker_set`` names skin markers instead (``skin`` or a CSV of a set,
:mod:`stylemotion.reconstruct.marker_set`), put virtually on a BVH, NPZ or take. ``subject`` gives the bones
the database is put on and the output holds (``database``, ``markers``: scaled from the markers, or a BVH of the
subject's skeleton). ``noise_mm`` adds uniform noise of ± that many millimetres to the markers (the thesis' ±1 mm).

The folder ``out`` (refused when it exists unless ``force``; built beside it and renamed into place):

* ``motion.npz``: ``positions`` ``(frames, 21, 3)`` float32 metres in the markers' world frame, ``joint_names``,
  ``fps`` — as ``stylemotion-convert`` writes;
* ``motion.bvh``: the same through :func:`stylemotion.io.export.write_motion_bvh`;
* ``motion.gif``: the stick figure along its ground track (unless ``gif=false``);
* ``summary.json``: the settings, the markers' source and filled gaps, frames/s, the database, provenance and,
  when the input was a complete motion, the mean/max per-joint error in cm (also of the nearest-neighbour
  baseline for marker-only feature sets).
"""

from __future__ import annotations

import logging
import os
import time
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig

from stylemotion.config import ConfigError, positive_int, settings_from_config
from stylemotion.datasets import TakeSet
from stylemotion.datasets.user_motion import conversion_keys, parse_example
from stylemotion.io.outputs import check_new_output
from stylemotion.provenance import provenance
from stylemotion.reconstruct.benchmark import bone_length_spread_cm
from stylemotion.reconstruct.capture import read_capture, resample_tracks, tracks_on_motion
from stylemotion.reconstruct.inputs import command_takeset, database_without
from stylemotion.reconstruct.marker_set import MarkerSet, marker_set_named
from stylemotion.reconstruct.markers import (
    DEFAULT_MARKERS,
    MarkerGapWarning,
    MarkerInputError,
    MarkerTracks,
    read_markers,
    tracks_from_positions,
)
from stylemotion.reconstruct.output import write_motion_folder
from stylemotion.reconstruct.settings import ReconstructSettings
from stylemotion.reconstruct.sparse import (
    RECONSTRUCT_FEATURE_SETS,
    SparseReconstructor,
    joint_errors_cm,
    subject_scale,
)
from stylemotion.reconstruct.subject import Subject, subject_from_motion
from stylemotion.skeleton import CANONICAL_JOINTS

log = logging.getLogger(__name__)
_D = ReconstructSettings


def _number(value: Any, key: str, low: float = 0.0) -> float:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value) and value >= low
    if not ok:
        raise ConfigError(f"{key}={value} must be a finite number ≥ {low:g}")
    return float(value)


def take_positions(text: str, takeset: TakeSet) -> tuple[np.ndarray, str] | None:
    """The positions ``(frames, 21, 3)`` of ``markers=<take>`` or ``<take>:start-end`` (END exclusive) and the take's
    name; None when ``text`` names no take of ``takeset`` (or is a file)."""
    names = {t.name: t for t in takeset.takes}
    if text in names and not Path(text).expanduser().is_file():
        return names[text].positions, text
    name, _, frames = text.rpartition(":")
    if name in names and not Path(text).expanduser().is_file():  # <take>:start-end, frames of the take
        spec = parse_example(text, "markers")
        take = names[name]
        if spec.start is None or spec.end is None:
            raise MarkerInputError(f"markers={text}: after a take's name give a frame range START-END "
                                   f"(e.g. markers={name}:0-120)")
        if spec.end > len(take.positions):
            raise MarkerInputError(f"markers={text}: the frame range {frames} runs past the take's "
                                   f"{len(take.positions)} frames (END exclusive)")
        return take.positions[spec.start:spec.end], name
    return None


def load_tracks(text: str, takeset: TakeSet, joints: Sequence[str] | None,
                conversion: Mapping[str, Any] | None = None, marker_set: MarkerSet | None = None,
                marker_names: Mapping[str, str] | None = None, markers_fps: float | None = None,
                markers_up_axis: str = "z") -> tuple[MarkerTracks, str | None]:
    """The marker tracks ``markers=`` names (a file, a take, or ``<take>:start-end``: frames of a take, END exclusive)
    at the dataset's rate, and the take they were cut from (None for a file). ``marker_set``: skin markers (read
    from a C3D or CSV, or put virtually on a motion); None: joint centres ``joints``."""
    if not text:
        raise MarkerInputError("markers= is empty: give a BVH, NPZ, CSV or C3D file or a take of the dataset")
    taken = take_positions(text, takeset)
    if taken is not None:
        positions, take = taken
        if marker_set is not None:
            return tracks_on_motion(positions, marker_set, takeset.fps, text), take
        return tracks_from_positions(positions, DEFAULT_MARKERS if joints is None else joints, takeset.fps,
                                     text), take
    if marker_set is not None:
        return read_capture(text, marker_set, takeset.fps, names=marker_names, up_axis=markers_up_axis,
                            capture_fps=markers_fps, conversion=conversion), None
    if Path(text).suffix.lower() == ".c3d":
        raise MarkerInputError(f"markers={text}: a C3D holds skin markers; name their set with marker_set=skin "
                               f"or marker_set=<set.csv> (docs/reconstruct.md)")
    csv_file = Path(text).suffix.lower() == ".csv"
    tracks = read_markers(text, joints, (markers_fps or takeset.fps) if csv_file else takeset.fps,
                          dict(conversion or {}))
    return resample_tracks(tracks, takeset.fps), None


def subject_bones(subject: str, positions: np.ndarray, marker_set: MarkerSet, database,
                  conversion: Mapping[str, Any] | None, fps: float
                  ) -> tuple[np.ndarray | Subject | None, dict[str, Any]]:
    """``subject=``: the bone lengths ``(20,)`` m or the :class:`Subject` (lengths, rigid bones and feet measured on
    a BVH of the subject) the database is put on (None: its own), and what to record."""
    from stylemotion.bones import median_bone_lengths

    if subject in ("", "database"):
        return None, {"value": "database"}
    if subject == "markers":
        scale = subject_scale(positions, marker_set, database)
        step = max(1, database.num_frames // 50_000)
        own = median_bone_lengths(np.asarray(database.positions[::step], np.float64))
        return own * scale, {"value": "markers", "scale": round(scale, 4)}
    if not subject.lower().split(":")[0].endswith(".bvh"):
        raise ConfigError(f"subject={subject}: give database, markers or a BVH of the subject's skeleton")
    full = read_markers(subject, CANONICAL_JOINTS, fps, dict(conversion or {})).full
    return subject_from_motion(full), {"value": subject, "source": "the BVH's skeleton: median bone lengths, the "
                                                                   "directions of the bones rigid in the pelvis and "
                                                                   "chest, the feet's convention"}


def reconstruct_command(data: Mapping[str, Any], markers: str, out: str | os.PathLike, *,
                        features: str = _D.features, k: int = _D.k, joints: Sequence[str] | None = _D.joints,
                        noise_mm: float = _D.noise_mm, seed: int = _D.seed,
                        exclude_markers_take: bool = _D.exclude_markers_take, model: Mapping[str, Any] | None = None,
                        conversion: Mapping[str, Any] | None = None, marker_set: str | None = _D.marker_set,
                        marker_names: Mapping[str, str] | None = _D.marker_names,
                        markers_fps: float | None = _D.markers_fps, markers_up_axis: str = _D.markers_up_axis,
                        subject: str = _D.subject,
                        force: bool = _D.force, gif: bool = _D.gif, command: str = "") -> dict[str, Any]:
    """Reconstruct ``markers`` on the database ``data`` (a ``data`` config) and write ``out`` (module docstring).

    ``model``: further :class:`SparseReconstructor` settings (variance, marker_sd, smooth_sd, prior_weight,
    iterations, weighted, hold_bones). ``marker_set``, ``marker_names``, ``markers_fps``, ``markers_up_axis``,
    ``subject``: :class:`~stylemotion.reconstruct.settings.ReconstructSettings`, which holds the defaults.
    Returns what ``summary.json`` holds.

    Raises:
        OutputExistsError: ``out`` exists and ``force`` is off (before any work).
        MarkerInputError, ConfigError: a bad value (naming it); nothing is written then.
    """
    started = time.perf_counter()
    out = check_new_output(out, force)
    if features not in RECONSTRUCT_FEATURE_SETS:
        raise ConfigError(f"features={features} cannot be used; valid: {list(RECONSTRUCT_FEATURE_SETS)}")
    k = positive_int(k, "k")
    noise_mm = _number(noise_mm, "noise_mm")
    if markers_fps is not None:
        markers_fps = _number(markers_fps, "markers_fps")
        if markers_fps <= 0:
            raise ConfigError(f"markers_fps={markers_fps} must be positive")
    if markers_up_axis not in ("y", "z"):
        raise ConfigError(f"markers_up_axis={markers_up_axis} must be y or z")
    skin = None
    if marker_set not in (None, "", "joints"):
        if joints is not None:
            raise ConfigError(f"joints={list(joints)} picks markers at joint centres; with marker_set={marker_set} "
                              f"the set names the markers: give one of them")
        skin = marker_set_named(str(marker_set))
    takeset = command_takeset(data)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MarkerGapWarning)
        tracks, take = load_tracks(str(markers or "").strip(), takeset, joints, conversion, skin,
                                   dict(marker_names or {}), markers_fps, markers_up_axis)
    for warning in caught:
        log.warning(f"warning: {warning.message}")
    database = database_without(takeset, {take} if exclude_markers_take and take else set(), f"markers={markers}")
    if not 2 <= k <= database.num_frames:
        raise ConfigError(f"k={k} must be from 2 to the database's {database.num_frames} frames")
    log.info(f"database {database.name}: {database.num_takes} takes, {database.num_frames} frames; markers "
             f"{list(tracks.joints)}: {tracks.num_frames} frames")
    chosen_set = skin if skin is not None else marker_set_named(None, tracks.joints)
    bones, subject_record = subject_bones(str(subject), tracks.positions, chosen_set, database, conversion,
                                          takeset.fps)
    try:
        reconstructor = SparseReconstructor(database, chosen_set if skin is not None else tracks.joints, features, k,
                                            bones=bones, **dict(model or {}))
    except TypeError as exc:
        raise ConfigError(f"model: {exc}") from None
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    positions = tracks.positions
    if noise_mm > 0:
        positions = positions + np.random.default_rng(seed).uniform(-noise_mm, noise_mm, positions.shape) / 1000.0
    result = reconstructor.reconstruct(positions)
    summary: dict[str, Any] = {
        "markers": {"value": str(markers), "source": tracks.source, "joints": list(tracks.joints),
                    "frames": tracks.num_frames, "fps": tracks.fps, "filled_frames": tracks.filled or {},
                    "noise_mm": noise_mm, "seed": seed, "excluded_take": take if exclude_markers_take else None,
                    "marker_set": chosen_set.name, "subject": subject_record},
        "settings": result.settings,
        "database": {**result.settings["database"], "digest": database.digest},
        "frames_per_s": round(result.frames_per_second, 2),
        "timing_s": {key: round(v, 4) for key, v in result.timings.items()},
        "bone_length_sd_cm": bone_length_spread_cm(result.positions),
    }
    if tracks.full is not None:
        summary["error"] = joint_errors_cm(result.positions, tracks.full)
        if not reconstructor.guided:
            baseline = joint_errors_cm(reconstructor.nearest_neighbour(positions), tracks.full)
            summary["error_nearest_neighbour"] = {key: baseline[key] for key in ("mean_cm", "max_cm")}
    summary["provenance"] = provenance(command or None)
    write_motion_folder(out, force, result.positions, database.fps, summary, started, gif=gif)
    error = summary.get("error")
    log.info(f"{tracks.num_frames} frames reconstructed at {summary['frames_per_s']:g} frames/s into {out}"
             + (f"; error {error['mean_cm']:.2f} cm mean, {error['max_cm']:.2f} cm max per joint" if error else ""))
    return summary


def reconstruct_from_config(cfg: DictConfig, command: str = "") -> dict[str, Any]:
    """:func:`reconstruct_command` with the keys of ``stylemotion/configs/reconstruct.yaml``
    (:class:`ReconstructSettings`)."""
    data, s = settings_from_config(cfg, ReconstructSettings, "reconstruct")
    return reconstruct_command(
        data, s.markers, s.out, features=s.features, k=s.k, joints=s.joints, noise_mm=s.noise_mm, seed=s.seed,
        exclude_markers_take=s.exclude_markers_take, model=asdict(s.model), conversion=conversion_keys(vars(s)),
        marker_set=s.marker_set, marker_names=dict(s.marker_names) if s.marker_names else None,
        markers_fps=s.markers_fps, markers_up_axis=s.markers_up_axis, subject=s.subject,
        force=s.force, gif=s.gif, command=command)
