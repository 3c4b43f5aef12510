"""The subject's skeleton, and the motion database put on it, for reconstruction from markers.

Skeletons differ in more than bone lengths: where a skeleton puts the hip joints relative to the pelvis, or the
clavicles and the neck relative to the chest (one puts the shoulders' root on the chest, another 6 cm to the
side), is a convention of the capture system, fixed for a skeleton. A :class:`Subject` holds both:

* ``lengths``: the 20 bone lengths (metres, :data:`stylemotion.bones.BONE_NAMES` order);
* ``rigid``: for the bones that hang rigidly off the pelvis or the chest (:data:`RIGID_BONES`), their direction
  in that body part's frame (:func:`body_frames`), or None to keep the database's;
* ``hinged``: for the feet (:data:`HINGED_BONES`), the median direction of the foot bone (ankle → toe joint) in the
  shank's frame. The foot turns at the ankle, so it is not rigid, but where a skeleton puts its ankle and toe joints
  is a convention: Bandai's ankle sits 12 cm above the floor and its foot bone points 40° down in stance, other
  skeletons' 2–7 cm and 12–19°. The database's feet are turned by the constant rotation that takes the database's
  median direction to the subject's, so their flexing is kept and their convention becomes the subject's.

:func:`subject_from_motion` measures all three on a motion of the subject (a calibration: the medians over its frames);
:func:`database_on_subject` puts every database take on them (each other bone keeps its direction per frame,
:func:`stylemotion.bones.retarget_takes`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from stylemotion.bones import BONE_NAMES, median_bone_lengths, retarget_takes
from stylemotion.search.database import MotionDatabase
from stylemotion.skeleton import CANONICAL_PARENTS, JOINT_INDEX

#: Bones whose direction is fixed in the frame of the body part they hang off: bone (child joint) → part.
RIGID_BONES = {"UpperLeg_L": "pelvis", "UpperLeg_R": "pelvis", "Neck": "chest", "Shoulder_L": "chest",
               "Shoulder_R": "chest", "UpperArm_L": "chest", "UpperArm_R": "chest"}
#: Bones whose direction differs between skeletons by a constant turn in their parent segment's frame: bone → part.
HINGED_BONES = {"Toes_L": "shank_L", "Toes_R": "shank_R"}
_EPS = 1e-9


@dataclass(frozen=True)
class Subject:
    """A subject's bone ``lengths`` ``(20,)`` metres and ``rigid`` bone directions (module docstring)."""

    lengths: np.ndarray
    rigid: dict[str, np.ndarray] | None = None
    hinged: dict[str, np.ndarray] | None = None

    def describe(self) -> dict:
        def rounded(directions: dict[str, np.ndarray] | None) -> dict | None:
            return None if directions is None else {k: [round(float(x), 4) for x in v] for k, v in directions.items()}

        return {"bones_m": [round(float(b), 5) for b in self.lengths], "rigid": rounded(self.rigid),
                "hinged": rounded(self.hinged)}


def _frame(x_ref: np.ndarray, y_ref: np.ndarray) -> np.ndarray:
    """``(frames, 3, 3)`` columns x, y, z: x along ``x_ref``, y along ``y_ref`` made orthogonal to x."""
    x = x_ref / np.maximum(np.linalg.norm(x_ref, axis=-1, keepdims=True), _EPS)
    y = y_ref - np.sum(y_ref * x, axis=-1, keepdims=True) * x
    y = y / np.maximum(np.linalg.norm(y, axis=-1, keepdims=True), _EPS)
    return np.stack([x, y, np.cross(x, y)], axis=-1)


def body_frames(positions: np.ndarray) -> dict[str, np.ndarray]:
    """The pelvis frame (x: right hip joint → left, y: Hips → Spine), the chest frame (x: right upper arm →
    left, y: Spine → Chest) and each shank's frame (x: right hip joint → left, y: knee → ankle) of a motion
    ``(frames, 21, 3)`` → part → ``(frames, 3, 3)``."""
    p = np.asarray(positions, np.float64)
    j = JOINT_INDEX
    left = p[:, j["UpperLeg_L"]] - p[:, j["UpperLeg_R"]]
    return {"pelvis": _frame(left, p[:, j["Spine"]] - p[:, j["Hips"]]),
            "chest": _frame(p[:, j["UpperArm_L"]] - p[:, j["UpperArm_R"]], p[:, j["Chest"]] - p[:, j["Spine"]]),
            **{f"shank_{s}": _frame(left, p[:, j[f"Foot_{s}"]] - p[:, j[f"LowerLeg_{s}"]]) for s in "LR"}}


def _median_directions(positions: np.ndarray, bones: dict[str, str]) -> dict[str, np.ndarray]:
    """Each bone's unit direction in its part's frame, the median over frames (zero for a zero-length bone)."""
    p = np.asarray(positions, np.float64)
    frames = body_frames(p)
    out = {}
    for bone, part in bones.items():
        child = JOINT_INDEX[bone]
        vector = p[:, child] - p[:, CANONICAL_PARENTS[child]]
        local = np.einsum("fij,fi->fj", frames[part], vector)  # Rᵀ v
        median = np.median(local, axis=0)
        norm = np.linalg.norm(median)
        out[bone] = median / norm if norm > 1e-6 else np.zeros(3)
    return out


def subject_from_motion(positions: np.ndarray) -> Subject:
    """The skeleton of a motion of the subject ``(frames, 21, 3)`` metres: median bone lengths, rigid and hinged
    directions (module docstring)."""
    p = np.asarray(positions, np.float64)
    return Subject(median_bone_lengths(p), _median_directions(p, RIGID_BONES), _median_directions(p, HINGED_BONES))


def _turn(source: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The smallest rotation ``(3, 3)`` taking unit vector ``source`` to ``target`` (scipy's ``align_vectors`` of
    one pair: the shortest arc); the identity when either is zero (a zero-length bone)."""
    from scipy.spatial.transform import Rotation

    if np.linalg.norm(source) < 1e-9 or np.linalg.norm(target) < 1e-9:
        return np.eye(3)
    return Rotation.align_vectors(np.asarray(target)[None], np.asarray(source)[None])[0].as_matrix()


def database_on_subject(database: MotionDatabase, subject: Subject) -> MotionDatabase:
    """``database`` with every take on the subject's bone lengths and, where given, its rigid bone directions and
    its feet's convention (each database foot bone turned in its shank's frame, module docstring)."""
    positions = np.asarray(database.positions, np.float64)
    directions = None
    if subject.rigid is not None or subject.hinged is not None:
        from stylemotion.bones import BONE_JOINTS

        vectors = positions[:, list(BONE_JOINTS)] - positions[:, [CANONICAL_PARENTS[j] for j in BONE_JOINTS]]
        directions = vectors / np.maximum(np.linalg.norm(vectors, axis=-1, keepdims=True), _EPS)
        frames = body_frames(positions)
        for bone, local in (subject.rigid or {}).items():
            directions[:, BONE_NAMES.index(bone)] = frames[RIGID_BONES[bone]] @ np.asarray(local, np.float64)
        if subject.hinged:
            own = _median_directions(positions[:: max(1, len(positions) // 50_000)], HINGED_BONES)
            for bone, local in subject.hinged.items():
                frame, b = frames[HINGED_BONES[bone]], BONE_NAMES.index(bone)
                turn = _turn(own[bone], np.asarray(local, np.float64))  # in the part's frame
                local_now = np.einsum("fji,fj->fi", frame, directions[:, b])  # Rᵀ d per frame
                directions[:, b] = np.einsum("fij,jk,fk->fi", frame, turn, local_now)
    moved = retarget_takes(positions, database.take_start, subject.lengths, directions)
    return replace(database, name=f"{database.name}-on-subject", positions=moved.astype(database.positions.dtype))


#: The two-bone limbs :func:`hold_bone_lengths` solves: (root, middle, end) joints.
LIMBS = (("UpperLeg_L", "LowerLeg_L", "Foot_L"), ("UpperLeg_R", "LowerLeg_R", "Foot_R"),
         ("UpperArm_L", "LowerArm_L", "Hand_L"), ("UpperArm_R", "LowerArm_R", "Hand_R"))


def hold_bone_lengths(positions: np.ndarray, lengths: np.ndarray, ends: dict[str, np.ndarray] | None = None
                      ) -> np.ndarray:
    """A reconstructed motion ``(frames, 21, 3)`` with every bone at ``lengths`` ``(20,)`` metres in every frame,
    the wrists and ankles kept where they were (or moved to ``ends``: limb end joint → ``(frames, 3)`` metres).

    The trunk, head and feet are placed from the root outwards, each bone keeping its direction
    (:func:`stylemotion.bones.place_bones`); each limb's middle joint (knee, elbow) is then solved by two-bone IK
    (:func:`stylemotion.geometry.two_bone_ik`) from its placed root to its end's reconstructed position, bending to
    the side the reconstruction bends (an end out of reach is pulled towards the root), and the joints below the
    end (toes) move with it.
    """
    from stylemotion.bones import place_bones
    from stylemotion.geometry import two_bone_ik
    from stylemotion.skeleton import CANONICAL_PARENTS as parents

    given = np.asarray(positions, np.float64)
    lengths = np.asarray(lengths, np.float64)
    out = place_bones(given, lengths)
    j = JOINT_INDEX
    left = given[:, j["UpperLeg_L"]] - given[:, j["UpperLeg_R"]]
    forward = np.cross(left, np.array([0.0, 1.0, 0.0]))
    for root, middle, end in LIMBS:
        a, b, c = j[root], j[middle], j[end]
        upper, lower = lengths[BONE_NAMES.index(middle)], lengths[BONE_NAMES.index(end)]
        if upper < 1e-6 or lower < 1e-6:
            continue
        bend = given[:, b] - 0.5 * (given[:, a] + given[:, c])
        default = forward if root.startswith("UpperLeg") else -forward  # knees bend forward, elbows back
        pole = bend + 1e-3 * default / np.maximum(np.linalg.norm(default, axis=-1, keepdims=True), _EPS)
        target = given[:, c] if ends is None or end not in ends else np.asarray(ends[end], np.float64)
        knee, reached = two_bone_ik(out[:, a], target, pole, upper, lower, margin=1e-5)
        move = reached - out[:, c]
        out[:, b], out[:, c] = knee, reached
        below = [k for k in range(len(parents)) if _descends(k, c, parents)]
        out[:, below] += move[:, None]
    return out


def _descends(joint: int, ancestor: int, parents: tuple[int, ...]) -> bool:
    """Whether ``joint`` lies below ``ancestor`` in the tree (not itself)."""
    k = parents[joint]
    while k >= 0:
        if k == ancestor:
            return True
        k = parents[k]
    return False
