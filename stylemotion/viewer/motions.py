"""The motions a viewer page shows, read from BVH files, motion NPZ files and run folders.

Every input becomes :class:`ViewerMotion`\\ s on the canonical skeleton (metres, Y up):

* a ``.bvh`` file: converted by the one loader (:func:`stylemotion.datasets.loading.load_canonical_positions`);
* a motion ``.npz``: ``positions`` ``(frames, 21, 3)`` and ``fps`` (what ``stylemotion-convert``,
  ``stylemotion-generate``, ``stylemotion-reconstruct`` and ``stylemotion-texture`` write; a walk's
  ``path`` ``(n, 2)`` and ``junctions`` are drawn on the ground), or a batch of samples:
  ``positions`` ``(n, frames, 21, 3)`` with ``num_frames`` ``(n,)`` (what the sample callback writes);
* a run folder: its ``motion.npz`` (a generated walk or a reconstruction; ``summary.json`` beside it
  names the style), else every ``samples/*.npz`` and ``example/example.npz`` below it.

Foot contacts come from :func:`stylemotion.primitives.contacts.foot_contacts`, the detector the rest of the
project uses. Bad input raises :class:`~stylemotion.io.errors.MotionDataError` naming the file and key.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from stylemotion.io.errors import MotionDataError
from stylemotion.io.npzfile import NpzFileError, load_npz
from stylemotion.primitives.contacts import foot_contacts
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX, NUM_JOINTS, checked_positions

#: Files inside a run folder that hold motions, in the order they are looked for.
RUN_MOTION = "motion.npz"
RUN_SAMPLE_GLOBS = ("**/samples/*.npz", "**/example/example.npz")


@dataclass
class ViewerMotion:
    """One motion of a viewer page.

    Attributes:
        name: label in the legend (file or folder name, sample index).
        group: colour group (the style where known, else the name).
        positions: ``(frames, 21, 3)`` float32 canonical positions, metres, Y up.
        fps: frames per second.
        contacts: ``(frames, 2)`` bool foot contacts ``[left, right]``.
        path: ``(n, 2)`` ground path (x, z) metres of a generated walk, or None.
        targets: ``(k, 2)`` ground points (x, z) metres the walk had to reach (the root at each step
            transition and the path's end), or None.
        source: the file it came from.
    """

    name: str
    group: str
    positions: np.ndarray
    fps: float
    contacts: np.ndarray
    path: np.ndarray | None
    targets: np.ndarray | None
    source: str

    @property
    def frames(self) -> int:
        return int(self.positions.shape[0])


def _check_positions(positions: np.ndarray, source: str, key: str = "positions") -> np.ndarray:
    """Canonical positions of at least 2 frames as float32; MotionDataError naming the file and key."""
    try:
        return checked_positions(positions, min_frames=2, what=f"key {key!r}").astype(np.float32)
    except ValueError as exc:
        raise MotionDataError(source, f"{exc} (canonical positions in metres; a motion needs at least 2 frames)"
                              ) from None


def _fps(data: Mapping[str, np.ndarray], source: str) -> float:
    if "fps" not in data:
        raise MotionDataError(source, "no key 'fps' (frames per second); a motion NPZ holds 'positions' and 'fps'")
    fps = np.asarray(data["fps"])
    if fps.size != 1 or not np.issubdtype(fps.dtype, np.number) or not np.isfinite(fps).all() or float(fps) <= 0:
        raise MotionDataError(source, f"key 'fps' is {fps!r}; expected one positive number")
    return float(fps)


def _ground_points(data: Mapping[str, np.ndarray], key: str, source: str) -> np.ndarray | None:
    if key not in data:
        return None
    points = np.asarray(data[key], dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 2 or not np.isfinite(points).all():
        raise MotionDataError(source, f"key {key!r} has shape {points.shape}; expected (n, 2) finite x/z metres")
    return points.astype(np.float32)


def _walk_targets(positions: np.ndarray, path: np.ndarray | None, data: Mapping[str, np.ndarray],
                  source: str) -> np.ndarray | None:
    """The root's ground point at each step transition (``junctions``) and the path's last point."""
    points = []
    if "junctions" in data:
        junctions = np.asarray(data["junctions"]).reshape(-1)
        if not np.issubdtype(junctions.dtype, np.integer) or (junctions < 0).any() or \
                (junctions >= positions.shape[0]).any():
            raise MotionDataError(source, f"key 'junctions' must hold frame indices in [0, {positions.shape[0]}); "
                                          f"got {junctions[:8]!r}")
        root = positions[junctions, JOINT_INDEX["Hips"]]
        points += list(root[:, [0, 2]])
    if path is not None and len(path):
        points.append(path[-1])
    return np.asarray(points, dtype=np.float32).reshape(-1, 2) if points else None


def _check_joint_names(data: Mapping[str, np.ndarray], source: str) -> None:
    if "joint_names" in data:
        names = [str(n) for n in np.asarray(data["joint_names"]).reshape(-1)]
        if names != list(CANONICAL_JOINTS):
            raise MotionDataError(source, f"key 'joint_names' is {names[:4]}…; expected the canonical joints "
                                          f"{list(CANONICAL_JOINTS[:4])}… (convert other skeletons with "
                                          f"stylemotion-convert)")


def _motion(name: str, group: str, positions: np.ndarray, fps: float, source: str,
            path: np.ndarray | None = None, targets: np.ndarray | None = None) -> ViewerMotion:
    return ViewerMotion(name, group, positions, fps, foot_contacts(positions, fps), path, targets, source)


def read_npz(path: Path, group: str | None = None, max_samples: int = 16) -> list[ViewerMotion]:
    """The motions of one motion or samples NPZ (see the module doc); at most ``max_samples`` of a batch."""
    source = str(path)
    try:
        data = load_npz(path, "motion NPZ")  # every array, never with pickle
    except NpzFileError as exc:
        raise MotionDataError(source, exc.detail) from None
    if "positions" not in data:
        raise MotionDataError(source, f"no key 'positions' (keys: {', '.join(data) or 'none'}); a motion "
                                      f"NPZ holds 'positions' (frames, {NUM_JOINTS}, 3) and 'fps'")
    positions = np.asarray(data["positions"])
    if not np.issubdtype(positions.dtype, np.floating):
        raise MotionDataError(source, f"key 'positions' has dtype {positions.dtype}; expected floats (metres)")
    _check_joint_names(data, source)
    fps = _fps(data, source)
    group = group or path.stem
    if positions.ndim == 4:
        if "num_frames" not in data:
            raise MotionDataError(source, f"key 'positions' has shape {positions.shape} (a batch) but there is no "
                                          f"key 'num_frames' (n,) giving each sample's length")
        lengths = np.asarray(data["num_frames"]).reshape(-1)
        if lengths.shape != (positions.shape[0],) or not np.issubdtype(lengths.dtype, np.integer) or \
                (lengths < 2).any() or (lengths > positions.shape[1]).any():
            raise MotionDataError(source, f"key 'num_frames' must hold {positions.shape[0]} lengths in "
                                          f"[2, {positions.shape[1]}]; got {lengths[:8]!r}")
        return [_motion(f"{group} #{i}", group, _check_positions(positions[i, :n], source, f"positions[{i}]"),
                        fps, source) for i, n in enumerate(lengths[:max_samples])]
    positions = _check_positions(positions, source)
    walk_path = _ground_points(data, "path", source)
    targets = _walk_targets(positions, walk_path, data, source) if walk_path is not None else None
    return [_motion(path.stem, group, positions, fps, source, walk_path, targets)]


def read_bvh(path: Path, fps: float = 30.0) -> list[ViewerMotion]:
    """One BVH file on the canonical skeleton at ``fps`` (the project's loader and joint maps)."""
    from stylemotion.datasets.loading import ConversionSettings, load_canonical_positions
    from stylemotion.io.sources import FileSource

    positions = load_canonical_positions(FileSource(str(path)), ConversionSettings(fps=fps))
    return [_motion(path.stem, path.stem, positions, fps, str(path))]


def _run_style(folder: Path) -> str | None:
    """The style a run folder's ``summary.json`` names (``meta.style``), if any."""
    summary = folder / "summary.json"
    if not summary.is_file():
        return None
    try:
        meta = json.loads(summary.read_text()).get("meta") or {}
    except (json.JSONDecodeError, AttributeError):
        return None
    style = meta.get("style") if isinstance(meta, dict) else None
    return str(style) if style else None


def read_run_folder(folder: Path, max_samples: int = 16) -> list[ViewerMotion]:
    """The motions of a run folder (see the module doc)."""
    if (folder / RUN_MOTION).is_file():
        style = _run_style(folder)
        motions = read_npz(folder / RUN_MOTION, group=style or folder.name, max_samples=max_samples)
        for m in motions:
            m.name = folder.name + (f" ({style})" if style else "")
        return motions
    files = sorted({p for pattern in RUN_SAMPLE_GLOBS for p in folder.glob(pattern) if p.is_file()})
    if not files:
        raise MotionDataError(str(folder), f"a run folder without samples: no {RUN_MOTION}, samples/*.npz or "
                                           f"example/example.npz below it")
    out = []
    for f in files:
        rel = f.relative_to(folder)
        owner = rel.parts[-3] if len(rel.parts) >= 3 else folder.name  # e.g. cvae/walk_left_active/samples/x.npz
        out += read_npz(f, group=owner, max_samples=max_samples)
    return out


def read_inputs(paths: Iterable[str | Path], fps: float = 30.0, max_samples: int = 16) -> list[ViewerMotion]:
    """Every motion of ``paths`` (BVH files, motion NPZ files, run folders), in the order given.

    Raises:
        MotionDataError: a path that is missing, of another kind, or malformed (naming it).
    """
    motions: list[ViewerMotion] = []
    for p in paths:
        path = Path(p).expanduser()
        if path.is_dir():
            motions += read_run_folder(path, max_samples)
        elif not path.exists():
            raise MotionDataError(str(path), "no such file or folder")
        elif path.suffix.lower() == ".bvh":
            motions += read_bvh(path, fps)
        elif path.suffix.lower() == ".npz":
            motions += read_npz(path, max_samples=max_samples)
        else:
            raise MotionDataError(str(path), f"neither a BVH file (.bvh) nor a motion NPZ (.npz) nor a run folder "
                                             f"(suffix {path.suffix or '(none)'!r})")
    if not motions:
        raise MotionDataError("stylemotion-view", "no motions given")
    return motions


def samples_to_motions(positions: np.ndarray, num_frames: Sequence[int], fps: float, group: str,
                       count: int) -> list[ViewerMotion]:
    """The first ``count`` of a batch of samples ``(n, frames, 21, 3)`` (lengths ``num_frames``) as motions."""
    return [_motion(f"{group} #{i}", group, _check_positions(np.asarray(positions[i, :int(n)]), group), fps, group)
            for i, n in enumerate(list(num_frames)[:count])]
