"""Export canonical joint positions as BVH: rotations fitted to a fixed-bone-length skeleton.

The file this writes:

* joints: the 21 canonical joints (:data:`stylemotion.skeleton.CANONICAL_JOINTS`, the
  Bandai-Namco names), Hips the root; an End Site continues each leaf joint (Head, Hand_*,
  Toes_*) by half its bone, for viewers that draw the last bone;
* units: **metres**, Y up, the body facing +Z in the rest pose (a T-pose, see
  :func:`stylemotion.ik.rest_offsets`); bone lengths are constant (each bone's median length);
* channels: Hips ``Xposition Yposition Zposition Zrotation Xrotation Yrotation``, every other
  joint ``Zrotation Xrotation Yrotation``: intrinsic Euler angles in degrees, order ZXY (the
  order of the Bandai-Namco files), ``R = Rz @ Rx @ Ry``. With the T-pose rest, only a knee
  flexed past about 90° (running) brings the middle (X) angle near ±90°, where the angle curves
  jump; the rotations, and so the positions, stay exact;
* the Hips OFFSET is zero, so its position channels are its global position whether a reader
  adds them to the OFFSET or replaces it.

The project's loader (:func:`stylemotion.datasets.canonical.to_canonical_positions`, used by the datasets
and ``stylemotion-convert``) reads it back to the same positions: the built-in ``bandai`` joint map
is auto-detected (it names exactly these joints) and the unit is detected as metres for any
skeleton whose head-to-hips-to-foot chain is shorter than about 6 m.
"""

from __future__ import annotations

import os

import numpy as np
from scipy.spatial.transform import Rotation

from stylemotion.ik import fit_rotations
from stylemotion.io.bvh import write_bvh
from stylemotion.motion import Motion
from stylemotion.skeleton import CANONICAL_JOINTS, CANONICAL_PARENTS, Skeleton

#: Intrinsic Euler order of the rotation channels (BVH channel order Zrotation Xrotation Yrotation).
ROTATION_ORDER = "ZXY"
_ROTATION_CHANNELS = [f"{axis}rotation" for axis in ROTATION_ORDER]
_ROOT_CHANNELS = ["Xposition", "Yposition", "Zposition", *_ROTATION_CHANNELS]
#: End Site length as a fraction of the leaf joint's own bone (cosmetic; loaders ignore it).
END_SITE_FRACTION = 0.5


def canonical_skeleton(offsets: np.ndarray) -> Skeleton:
    """The canonical 21-joint BVH skeleton with ``offsets`` ``(21, 3)`` (metres).

    Hips gets 6 channels and a zero OFFSET; every other joint 3 rotation channels; leaf joints an
    End Site along their bone.
    """
    offsets = np.asarray(offsets, dtype=np.float64).copy()
    if offsets.shape != (len(CANONICAL_JOINTS), 3):
        raise ValueError(f"offsets must have shape ({len(CANONICAL_JOINTS)}, 3), got {offsets.shape}")
    root = CANONICAL_PARENTS.index(-1)
    offsets[root] = 0.0
    offsets[np.abs(offsets) < 1e-12] = 0.0  # no "-0.000000" in the file
    channels = [list(_ROOT_CHANNELS) if j == root else list(_ROTATION_CHANNELS) for j in range(len(offsets))]
    leaves = [j for j in range(len(offsets)) if j not in CANONICAL_PARENTS]
    end_sites = {j: END_SITE_FRACTION * offsets[j] for j in leaves}
    return Skeleton(list(CANONICAL_JOINTS), np.array(CANONICAL_PARENTS), offsets, channels, end_sites)


def _continuous_quaternions(quats: np.ndarray) -> np.ndarray:
    """Flip signs of ``(frames, joints, 4)`` quaternions so consecutive frames agree (q ≡ -q)."""
    if quats.shape[0] < 2:
        return quats
    agree = np.sum(quats[1:] * quats[:-1], axis=-1) >= 0
    signs = np.cumprod(np.where(agree, 1.0, -1.0), axis=0)
    out = quats.copy()
    out[1:] *= signs[..., None]
    return out


def positions_to_motion(positions: np.ndarray, fps: float, offsets: np.ndarray | None = None) -> Motion:
    """A BVH-ready :class:`Motion` whose FK reproduces canonical ``positions``.

    Args:
        positions: ``(frames, 21, 3)`` canonical global joint positions, metres, Y up.
        fps: frames per second of ``positions``.
        offsets: ``(21, 3)`` rest skeleton in metres (e.g. to give several clips the same
            skeleton), or None for :func:`stylemotion.ik.rest_offsets` of ``positions``.

    Returns:
        A Motion in metres: quaternions (x, y, z, w) of the fitted local rotations, Hips
        translations = its positions, the skeleton of :func:`canonical_skeleton`.

    Raises:
        ValueError: a bad ``fps``, or bad positions or offsets (see :func:`stylemotion.ik.fit_rotations`).
    """
    if not np.isfinite(fps) or fps <= 0:
        raise ValueError(f"fps must be a positive number of frames per second, got {fps!r}")
    fit = fit_rotations(positions, CANONICAL_PARENTS, offsets)
    num_frames, num_joints = fit.local_rotations.shape[:2]
    quats = Rotation.from_matrix(fit.local_rotations.reshape(-1, 3, 3)).as_quat()
    rotations = _continuous_quaternions(quats.reshape(num_frames, num_joints, 4))
    return Motion(canonical_skeleton(fit.offsets), rotations, fit.translations(), float(fps), "<positions>")


def write_motion_bvh(
    positions: np.ndarray, path: str | os.PathLike, fps: float, offsets: np.ndarray | None = None,
    precision: int = 6,
) -> Motion:
    """Fit rotations to canonical ``positions`` and write them to ``path`` as BVH, atomically.

    Args:
        positions: ``(frames, 21, 3)`` canonical global joint positions, metres, Y up.
        path: the ``.bvh`` file to write (folders are created).
        fps: frames per second of ``positions`` (the file's Frame Time is ``1 / fps``).
        offsets: ``(21, 3)`` rest skeleton in metres, or None to derive it from ``positions``.
        precision: decimals written (metres and degrees).

    Returns:
        The :class:`Motion` that was written.
    """
    motion = positions_to_motion(positions, fps, offsets)
    write_bvh(motion, path, precision)
    return motion
