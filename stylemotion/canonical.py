"""From any BVH skeleton to canonical 21-joint global positions in metres, Y up, at a fixed fps.

This is the single code path used by the datasets and by ``stylemotion-convert``:

    Motion (file units, file fps) ──resample (slerp)──▶ FK ──pick canonical joints──▶
    ──scale to metres──▶ Y up ──▶ positions (frames, 21, 3) float32
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np
import yaml

from stylemotion.io.errors import MotionDataError
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


_UP_TO_Y = {
    "y": np.eye(3),
    "z": np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]]),  # (x, y, z) → (x, z, -y)
}


def to_canonical_positions(
    motion: Motion,
    joint_map: str | Mapping[str, str] | JointMap | None = None,
    fps: float | None = 30.0,
    unit_scale: float | str | None = None,
    up_axis: str = "y",
) -> np.ndarray:
    """Canonical global joint positions of ``motion``.

    Args:
        motion: a loaded motion, any skeleton.
        joint_map: built-in map name, YAML path, mapping, or None to auto-detect.
        fps: target frame rate (slerp resampling), or None to keep the file's.
        unit_scale: metres per file unit, a unit name from :data:`UNIT_SCALES`, or None to detect.
        up_axis: the file's up axis, ``"y"`` or ``"z"``.

    Returns:
        ``(frames, 21, 3)`` float32 global positions in metres, Y up, canonical joint order.
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
    if up_axis not in _UP_TO_Y:
        raise MotionDataError(motion.source, f"up_axis must be one of {sorted(_UP_TO_Y)}, got {up_axis!r}")
    if fps is not None:
        motion = motion.resample(fps)
    positions = motion.global_positions()[:, idx] * scale
    if up_axis != "y":
        positions = positions @ _UP_TO_Y[up_axis].T
    return positions.astype(np.float32)
