"""From any BVH skeleton to canonical 21-joint global positions in metres, Y up, at a fixed fps.

This is the single code path used by the datasets and by ``stylemotion-convert``:

    Motion (file units, file fps) ──resample (slerp)──▶ FK ──pick canonical joints──▶
    ──scale to metres──▶ Y up ──▶ positions (frames, 21, 3) float32
"""

from __future__ import annotations

import numbers
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np
import yaml

from stylemotion.io.bvh import DEFAULT_MAX_JOINT_FRAMES, check_joint_frames
from stylemotion.io.errors import LimitError, MotionDataError, MotionDataWarning
from stylemotion.motion import Motion
from stylemotion.skeleton import CANONICAL_JOINTS

#: Candidate length units (metres per file unit) for unit detection.
UNIT_SCALES: dict[str, float] = {
    "m": 1.0,
    "cm": 0.01,
    "mm": 0.001,
    "inch": 0.0254,
    "cmu": 0.0254 / 0.45,  # CMU ASF/AMC length unit: inches / 0.45
}
#: Head-to-hips plus hips-to-ankle chain length of a typical adult, metres (pose independent).
TYPICAL_CHAIN_HEIGHT_M = 1.45


@dataclass(frozen=True)
class JointMap:
    """Which source joint plays each canonical joint. ``joints[canonical] = source name``."""

    name: str
    joints: Mapping[str, str]
    num_joints: int | None = None  # joint count of the source convention, for auto-detection

    def __post_init__(self) -> None:
        missing = [c for c in CANONICAL_JOINTS if c not in self.joints]
        unknown = [c for c in self.joints if c not in CANONICAL_JOINTS]
        if missing or unknown:
            raise MotionDataError(
                f"joint map {self.name!r}",
                (f"missing canonical joints {missing}" if missing else "")
                + ("; " if missing and unknown else "")
                + (f"unknown canonical joints {unknown} (canonical: {list(CANONICAL_JOINTS)})"
                   if unknown else ""),
            )

    @classmethod
    def from_yaml(cls, path: str | Path) -> JointMap:
        """Load a map from a YAML file with keys ``name`` and ``joints: {canonical: source}``."""
        path = Path(path)
        try:
            data = yaml.safe_load(path.read_text())
        except (OSError, yaml.YAMLError) as exc:
            raise MotionDataError(str(path), f"cannot read joint map ({exc})") from None
        if not isinstance(data, dict) or not isinstance(data.get("joints"), dict):
            raise MotionDataError(str(path), "joint map needs a 'joints' mapping {canonical: source}")
        return cls(str(data.get("name", path.stem)), dict(data["joints"]))


def builtin_joint_maps() -> dict[str, JointMap]:
    """The maps shipped with the package (bandai, cmu31, cmu21)."""
    maps = {}
    for entry in sorted(resources.files("stylemotion.joint_maps").iterdir(), key=lambda p: p.name):
        if entry.name.endswith(".yaml"):
            data = yaml.safe_load(entry.read_text())
            maps[data["name"]] = JointMap(data["name"], data["joints"], data.get("num_joints"))
    return maps


def resolve_joint_map(spec: str | Mapping[str, str] | JointMap | None, motion: Motion) -> JointMap:
    """A joint map from a built-in name, a YAML path, a mapping, or ``None`` (auto-detect).

    Auto-detection picks, among the built-in maps whose source joints all exist in the skeleton,
    the one whose convention's joint count is closest to the skeleton's.
    """
    if isinstance(spec, JointMap):
        return spec
    if isinstance(spec, Mapping):
        return JointMap("custom", dict(spec))
    builtin = builtin_joint_maps()
    if spec is None or spec == "auto":
        names = set(motion.skeleton.names)
        fitting = [jm for jm in builtin.values() if all(src in names for src in jm.joints.values())]
        if fitting:
            return min(fitting, key=lambda jm: abs((jm.num_joints or len(names)) - len(names)))
        raise MotionDataError(
            motion.source,
            "no built-in joint map fits this skeleton (built-in: "
            + ", ".join(f"{k}: missing {[s for s in v.joints.values() if s not in names][:4]}"
                        for k, v in builtin.items())
            + "); pass a joint map YAML with joints: {canonical: source}",
        )
    if spec in builtin:
        return builtin[spec]
    if Path(spec).suffix in (".yaml", ".yml"):
        return JointMap.from_yaml(spec)
    raise MotionDataError(str(spec), f"unknown joint map; built-in maps are {sorted(builtin)} "
                          "or give a YAML path")


def source_indices(motion: Motion, joint_map: JointMap) -> list[int]:
    """Index in ``motion.skeleton`` of each canonical joint; error names the missing joints."""
    names = motion.skeleton.names
    missing = [f"{c} (as {s!r})" for c, s in joint_map.joints.items() if s not in names]
    if missing:
        raise MotionDataError(
            motion.source,
            f"skeleton lacks required canonical joints {missing} for joint map {joint_map.name!r}",
        )
    return [names.index(joint_map.joints[c]) for c in CANONICAL_JOINTS]


def chain_height(motion: Motion, joint_map: JointMap) -> float:
    """Head→hips plus the longer hips→foot chain, summed bone lengths in file units.

    Uses the first frame's local translations, so it does not depend on the pose and honours
    position channels that replace OFFSETs.
    """
    sk = motion.skeleton
    trans = np.linalg.norm(motion.translations[0], axis=-1)
    hips = sk.index(joint_map.joints["Hips"])

    def up_to_hips(joint_name: str) -> float:
        j, total = sk.index(joint_map.joints[joint_name]), 0.0
        while j != hips:
            if j < 0:
                raise MotionDataError(motion.source, f"joint {joint_name!r} is not below the hips")
            total += trans[j]
            j = int(sk.parents[j])
        return total

    return up_to_hips("Head") + max(up_to_hips("Foot_L"), up_to_hips("Foot_R"))


def detect_unit_scale(motion: Motion, joint_map: JointMap) -> float:
    """Metres per file unit: the candidate unit that makes the skeleton closest to adult size."""
    height = chain_height(motion, joint_map)
    if not np.isfinite(height) or height <= 0:
        raise MotionDataError(motion.source, f"cannot detect units: skeleton chain height is {height}")
    return min(UNIT_SCALES.values(), key=lambda s: abs(np.log(height * s / TYPICAL_CHAIN_HEIGHT_M)))


#: Rotation taking a file's up axis (``y`` or ``z``) to Y up: ``positions @ UP_TO_Y[axis].T``.
UP_TO_Y = {
    "y": np.eye(3),
    "z": np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]]),  # (x, y, z) → (x, z, -y)
}


#: Default cap on the frames of one take after resampling (3 hours at 30 fps).
DEFAULT_MAX_FRAMES = 324_000
#: The body's height axis is "evidently" another axis when it is this many times longer there.
_UP_AXIS_RATIO = 2.0
#: ... and at least this long (metres): a head this far from the feet is a body's height, not noise.
_MIN_BODY_HEIGHT_M = 0.3
_AXES = "xyz"


def check_resampled_length(motion: Motion, fps: float, max_frames: int | None,
                           max_joint_frames: int | None) -> None:
    """Refuse, before resampling, a motion that would become longer than the limits.

    Raises:
        LimitError: naming ``data.max_frames`` or ``data.max_joint_frames`` and the file.
    """
    finite = bool(np.isfinite(motion.duration * fps))
    n_new = motion.resampled_length(fps) if finite else None
    if max_frames is not None and (n_new is None or n_new > max_frames):
        raise LimitError(
            motion.source,
            f"{motion.num_frames} frames at {motion.fps:g} fps ({motion.duration:g} s) resampled to {fps:g} fps "
            f"would be {n_new if finite else 'infinitely many'} frames, more than the limit "
            f"data.max_frames={max_frames} (raise it for longer takes; a Frame Time in milliseconds instead of "
            "seconds also does this)",
        )
    if n_new is not None:
        check_joint_frames(n_new, motion.skeleton.num_joints, max_joint_frames, motion.source,
                           f"after resampling to {fps:g} fps")


def check_up_axis(positions: np.ndarray, up_axis: str, source: str) -> None:
    """Warn if the body's height (head above feet) evidently runs along another axis than ``up_axis``.

    Args:
        positions: ``(frames, 21, 3)`` canonical positions in the file's axes.
        up_axis: the declared up axis, ``"y"`` or ``"z"``.
        source: the file, for the message.
    """
    head = positions[:, CANONICAL_JOINTS.index("Head")]
    feet = positions[:, [CANONICAL_JOINTS.index("Foot_L"), CANONICAL_JOINTS.index("Foot_R")]].mean(axis=1)
    height = np.median(head - feet, axis=0)  # (3,) typical head-over-feet vector
    if not np.all(np.isfinite(height)):
        return
    declared = _AXES.index(up_axis)
    axis = int(np.argmax(np.abs(height)))
    if axis != declared and abs(height[axis]) > max(_UP_AXIS_RATIO * abs(height[declared]), _MIN_BODY_HEIGHT_M):
        sign = "+" if height[axis] > 0 else "-"
        hint = f"set data.up_axis={_AXES[axis]}" if _AXES[axis] in UP_TO_Y and sign == "+" else \
            "check the file's axes"
        warnings.warn(
            f"{source}: read as {up_axis.upper()}-up but the body's height (head above feet) runs along "
            f"{sign}{_AXES[axis].upper()} ({abs(height[axis]):.2f} m against {abs(height[declared]):.2f} m "
            f"along {up_axis.upper()}); the file looks {_AXES[axis].upper()}-up: {hint} "
            "(or ignore this for a take where the body lies down)",
            MotionDataWarning, stacklevel=3,
        )


def to_canonical_positions(
    motion: Motion,
    joint_map: str | Mapping[str, str] | JointMap | None = None,
    fps: float | None = 30.0,
    unit_scale: float | str | None = None,
    up_axis: str = "y",
    max_frames: int | None = DEFAULT_MAX_FRAMES,
    max_joint_frames: int | None = DEFAULT_MAX_JOINT_FRAMES,
) -> np.ndarray:
    """Canonical global joint positions of ``motion``.

    Args:
        motion: a loaded motion, any skeleton.
        joint_map: built-in map name, YAML path, mapping, or None to auto-detect.
        fps: target frame rate (slerp resampling), or None to keep the file's.
        unit_scale: metres per file unit, a unit name from :data:`UNIT_SCALES`, or None to detect.
        up_axis: the file's up axis, ``"y"`` or ``"z"``.
        max_frames: refuse (before resampling) a take longer than this many frames at ``fps``.
        max_joint_frames: refuse (before resampling) more frames × skeleton joints than this.

    Returns:
        ``(frames, 21, 3)`` float32 global positions in metres, Y up, canonical joint order.

    Raises:
        MotionDataError: naming the file, for unusable skeletons, units, axes or positions that
            overflow to inf/NaN; :class:`LimitError` for a motion over the limits.

    Warns:
        MotionDataWarning: the body's height runs along another axis than ``up_axis``.
    """
    jm = resolve_joint_map(joint_map, motion)
    idx = source_indices(motion, jm)
    if isinstance(unit_scale, str):
        if unit_scale not in UNIT_SCALES:
            raise MotionDataError(motion.source, f"unknown unit {unit_scale!r}; known: {sorted(UNIT_SCALES)}")
        scale = UNIT_SCALES[unit_scale]
    else:
        scale = detect_unit_scale(motion, jm) if unit_scale is None else float(unit_scale)
        if not np.isfinite(scale) or scale <= 0:
            raise MotionDataError(motion.source, f"unit_scale must be a positive number of metres per file "
                                  f"unit or a unit name ({sorted(UNIT_SCALES)}), got {unit_scale!r}")
    if up_axis not in UP_TO_Y:
        raise MotionDataError(motion.source, f"up_axis must be one of {sorted(UP_TO_Y)}, got {up_axis!r}")
    if fps is not None:
        if isinstance(fps, bool) or not isinstance(fps, numbers.Real) or not np.isfinite(fps) or fps <= 0:
            raise ValueError(f"{motion.source}: fps must be a positive finite number of frames per second, "
                             f"got {fps!r}")
        check_resampled_length(motion, fps, max_frames, max_joint_frames)
        motion = motion.resample(fps)
    with np.errstate(over="ignore", invalid="ignore"):  # overflow is reported below, naming the file
        in_file_axes = motion.global_positions()[:, idx] * scale
        _check_finite(in_file_axes, motion, scale)
        positions = in_file_axes @ UP_TO_Y[up_axis].T if up_axis != "y" else in_file_axes
        positions = positions.astype(np.float32)
    _check_finite(positions, motion, scale)
    check_up_axis(in_file_axes, up_axis, motion.source)
    return positions


def _check_finite(positions: np.ndarray, motion: Motion, scale: float) -> None:
    """Raise naming the file, frame and joint if ``positions`` hold inf/NaN (values too large)."""
    bad = ~np.isfinite(positions)
    if not bad.any():
        return
    frame, joint = (int(i) for i in np.argwhere(bad.any(axis=-1))[0])
    largest = float(np.abs(motion.translations).max())
    raise MotionDataError(
        motion.source,
        f"joint positions overflow to inf/NaN (frame {frame}, canonical joint {CANONICAL_JOINTS[joint]!r} "
        f"in {positions.dtype}): the file's values are too large (largest translation {largest:.3g} file "
        f"units × {scale:g} m per unit)",
    )
