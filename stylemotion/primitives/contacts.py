"""Foot contacts from joint positions — the one detector used by segmentation, evaluation
(foot skating) and synthesis.

Each foot is watched at two points: the heel (the ankle joint ``Foot_*``) and the ball of the foot
(``Toes_*``). A point *touches* the ground when it is both low (height above its resting height)
and slow (horizontal speed). A foot is in contact while either of its points touches, so a heel
rise in late stance (weight on the ball) and a flat-footed shuffle are both contact.

Hysteresis is done as region growing, symmetric in time: a contact is a run of frames that pass
the *loose* thresholds and contain at least one frame passing the *strict* ones. A short median
filter then removes single-frame flickers. All thresholds are multiples of the leg length (hip to
ankle, measured from the positions) so that a child and an adult, or centimetres wrongly read
as metres, get the same decisions; speeds are per second and the filter width is in seconds, so
the result does not depend on the frame rate.

Resting heights are estimated per sequence as a low percentile of each point's height, which
handles any ground level and any joint placement inside the foot. Generated motion that may float
can be judged against the resting heights of real data by passing ``rest_heights``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from stylemotion.skeleton import FOOT_POINTS, JOINT_INDEX, NUM_JOINTS

#: Feet in the order of the last axis of every contact array.
FEET: tuple[str, str] = ("left", "right")


@dataclass(frozen=True)
class ContactSettings:
    """Thresholds of :func:`foot_contacts`; heights in leg lengths, speeds in leg lengths/second.

    With a leg length of 0.85 m the defaults are: strict 3.4 cm and 0.26 m/s, loose 6.0 cm and
    0.43 m/s. Swing feet move at 1–4 m/s even in an elderly shuffle, and the ball of a planted
    foot stays within a centimetre of its resting height. (Tuned on Bandai walks and runs of all
    seven styles and on the synthetic generator's exact contacts; see ``benchmarks/primitives.md``.)

    Attributes:
        height_on: strict height above rest (a contact must contain a frame below it).
        speed_on: strict horizontal speed.
        height_off: loose height (a contact lasts while a point stays below it ...).
        speed_off: loose horizontal speed (... and slower than this).
        filter_s: width of the median filter on the contact flags, seconds (odd frame count,
            at least 3 frames).
        fill_gap_s: a gap in one foot's contact of at most this many seconds is filled when a
            point of the foot stays below the loose height throughout it (a pivot or slide of the
            planted foot, e.g. turning on the stance foot, not a step), seconds.
        rest_percentile: percentile of a point's height taken as its resting height.
    """

    height_on: float = 0.04
    speed_on: float = 0.3
    height_off: float = 0.07
    speed_off: float = 0.5
    filter_s: float = 0.1
    fill_gap_s: float = 0.1
    rest_percentile: float = 5.0

    def __post_init__(self) -> None:
        if not (0 < self.height_on <= self.height_off and 0 < self.speed_on <= self.speed_off):
            raise ValueError(f"contact thresholds need 0 < on <= off, got {self}")


@dataclass
class FootSignals:
    """What the contact decision is made from (for plots and diagnostics).

    Attributes:
        heights: ``(..., frames, 2, 2)`` height above rest of (foot, point), metres; feet
            ``[left, right]``, points ``[heel, ball]``.
        speeds: ``(..., frames, 2, 2)`` horizontal speed of (foot, point), metres per second.
        leg_length: ``(...)`` hip-to-ankle length, metres.
        rest_heights: ``(..., 2, 2)`` resting height of each point, metres above y = 0.
    """

    heights: np.ndarray
    speeds: np.ndarray
    leg_length: np.ndarray
    rest_heights: np.ndarray


def leg_length(positions: np.ndarray) -> np.ndarray:
    """Mean hip-to-ankle length (thigh + shin, both legs), the body scale of the thresholds.

    Args:
        positions: ``(..., frames, 21, 3)`` canonical positions, metres.

    Returns:
        ``(...)`` median over frames of the leg length, metres.
    """
    p = np.asarray(positions, dtype=np.float64)
    total = 0.0
    for side in ("L", "R"):
        hip, knee, ankle = (JOINT_INDEX[f"{joint}_{side}"] for joint in ("UpperLeg", "LowerLeg", "Foot"))
        thigh = np.linalg.norm(p[..., knee, :] - p[..., hip, :], axis=-1)
        shin = np.linalg.norm(p[..., ankle, :] - p[..., knee, :], axis=-1)
        total = total + thigh + shin
    return np.median(total / 2.0, axis=-1)


def horizontal_speed(points: np.ndarray, fps: float) -> np.ndarray:
    """Ground-plane speed of points by central differences (one-sided at the ends).

    Args:
        points: ``(..., frames, k, 3)`` positions, metres, Y up; frames ≥ 2.
        fps: frames per second.

    Returns:
        ``(..., frames, k)`` speed in metres per second.
    """
    xz = np.asarray(points, dtype=np.float64)[..., [0, 2]]
    if xz.shape[-3] < 2:
        return np.zeros(xz.shape[:-1])
    return np.linalg.norm(np.gradient(xz, axis=-3), axis=-1) * fps


def foot_signals(
    positions: np.ndarray, fps: float, settings: ContactSettings | None = None,
    rest_heights: np.ndarray | None = None,
) -> FootSignals:
    """Heights above rest and horizontal speeds of heel and ball of both feet.

    Args:
        positions: ``(..., frames, 21, 3)`` canonical positions, metres, Y up.
        fps: frames per second.
        settings: thresholds (only ``rest_percentile`` is used here).
        rest_heights: ``(..., 2, 2)`` or ``(2, 2)`` resting heights of (foot, point) in metres;
            default: estimated from ``positions``.
    """
    settings = settings or ContactSettings()
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim < 3 or p.shape[-2:] != (NUM_JOINTS, 3):
        raise ValueError(f"positions must be (..., frames, {NUM_JOINTS}, 3), got {p.shape}")
    if p.shape[-3] < 2:
        raise ValueError(f"foot contacts need at least 2 frames, got {p.shape[-3]}")
    pts = p[..., FOOT_POINTS.reshape(-1), :]  # (..., frames, 4, 3)
    height = pts[..., 1]
    if rest_heights is None:
        rest = np.percentile(height, settings.rest_percentile, axis=-2)  # (..., 4)
    else:
        rest = np.broadcast_to(np.asarray(rest_heights, dtype=np.float64), p.shape[:-3] + (2, 2))
        rest = rest.reshape(p.shape[:-3] + (4,))
    lead = p.shape[:-2]
    return FootSignals(
        heights=(height - rest[..., None, :]).reshape(lead + (2, 2)),
        speeds=horizontal_speed(pts, fps).reshape(lead + (2, 2)),
        leg_length=leg_length(p),
        rest_heights=rest.reshape(p.shape[:-3] + (2, 2)),
    )


def foot_contacts(
    positions: np.ndarray, fps: float, settings: ContactSettings | None = None,
    rest_heights: np.ndarray | None = None,
) -> np.ndarray:
    """Per-frame ground contact of the left and the right foot.

    Args:
        positions: ``(..., frames, 21, 3)`` canonical positions, metres, Y up; frames ≥ 2.
        fps: frames per second.
        settings: thresholds (default :class:`ContactSettings`).
        rest_heights: ``(..., 2, 2)`` resting heights of (foot, [heel, ball]), metres above y = 0;
            default: estimated per sequence (see :func:`foot_signals`).

    Returns:
        ``(..., frames, 2)`` bool, ``[left, right]``.
    """
    settings = settings or ContactSettings()
    sig = foot_signals(positions, fps, settings, rest_heights)
    return contacts_from_signals(sig, fps, settings)


def contacts_from_signals(sig: FootSignals, fps: float, settings: ContactSettings | None = None) -> np.ndarray:
    """The contact decision of :func:`foot_contacts` from precomputed :class:`FootSignals`."""
    from scipy import ndimage  # here: scipy.ndimage costs ~0.5 s of start-up (the settings load without it)

    settings = settings or ContactSettings()
    scale = sig.leg_length[..., None, None, None]
    strict = ((sig.heights < settings.height_on * scale) & (sig.speeds < settings.speed_on * scale)).any(-1)
    loose = ((sig.heights < settings.height_off * scale) & (sig.speeds < settings.speed_off * scale)).any(-1)
    lead, frames = strict.shape[:-2], strict.shape[-2]
    strict2 = np.moveaxis(strict, -2, -1).reshape(-1, frames)  # (sequences·feet, frames)
    loose2 = np.moveaxis(loose, -2, -1).reshape(-1, frames)
    low = (sig.heights < settings.height_off * scale).any(-1)
    low2 = np.moveaxis(low, -2, -1).reshape(-1, frames)
    width = max(3, int(round(settings.filter_s * fps)) | 1)
    max_gap = int(round(settings.fill_gap_s * fps))
    out = np.empty_like(strict2)
    for i in range(strict2.shape[0]):
        grown = _grow(strict2[i], loose2[i])
        filtered = ndimage.median_filter(grown.astype(np.uint8), size=width, mode="nearest").astype(bool)
        out[i] = _fill_low_gaps(filtered, low2[i], max_gap)
    return np.moveaxis(out.reshape(lead + (2, frames)), -1, -2)


def _grow(strict: np.ndarray, loose: np.ndarray) -> np.ndarray:
    """Runs of ``loose`` that contain a ``strict`` frame (``(frames,)`` bool each)."""
    from scipy.ndimage import label

    labels, count = label(loose | strict)
    if count == 0:
        return np.zeros_like(strict)
    keep = np.zeros(count + 1, dtype=bool)
    keep[np.unique(labels[strict])] = True
    keep[0] = False
    return keep[labels]


def _fill_low_gaps(contact: np.ndarray, low: np.ndarray, max_gap: int) -> np.ndarray:
    """``contact`` with interior gaps of at most ``max_gap`` frames filled where ``low`` holds
    throughout the gap (``(frames,)`` bool each)."""
    out = contact.copy()
    if max_gap < 1:
        return out
    for a, b in contact_intervals(~contact):
        if a > 0 and b < len(contact) and b - a <= max_gap and low[a:b].all():
            out[a:b] = True
    return out


def contact_intervals(contact: np.ndarray) -> list[tuple[int, int]]:
    """Half-open ``[start, stop)`` frame intervals where ``contact`` (``(frames,)`` bool) is true."""
    c = np.asarray(contact, dtype=bool).astype(np.int8)
    edges = np.diff(np.concatenate([[0], c, [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def planted_point_speed(positions: np.ndarray, fps: float) -> np.ndarray:
    """Horizontal speed of each foot's slower point (heel or ball), the foot-skating measure.

    A planted foot pivots about its heel at strike and about its ball at push-off; the slower of
    the two points is the one holding the ground.

    Args:
        positions: ``(..., frames, 21, 3)`` canonical positions, metres, Y up.
        fps: frames per second.

    Returns:
        ``(..., frames, 2)`` metres per second, ``[left, right]``.
    """
    p = np.asarray(positions, dtype=np.float64)
    speeds = horizontal_speed(p[..., FOOT_POINTS.reshape(-1), :], fps)
    return speeds.reshape(speeds.shape[:-1] + (2, 2)).min(-1)
