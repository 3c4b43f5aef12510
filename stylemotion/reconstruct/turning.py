"""Shortest forward paths of bounded curvature on the ground (Dubins paths), as a cost-to-go for the keyframe search.

A walker at ground point ``p`` facing yaw ``θ`` who must stand at ``q`` facing ``φ`` walks forwards and turns no
tighter than a radius ``r``: the shortest such path is one of the six Dubins words (L/R arcs of radius ``r``, S
straight lines: LSL, RSR, LSR, RSL, RLR, LRL). Its length is the heading-aware distance that
:class:`~stylemotion.reconstruct.keyframes.DynamicMotionGraph` uses to choose which nodes to expand when
``turn_radius_m > 0``: a key turned against the direction of travel is far in this measure even when it is near
in position, so the trees grow along a loop instead of stalling face to face (docs/reconstruct.md).

Conventions (:mod:`stylemotion.geometry`): ground points ``(x, z)`` metres, yaw ``θ`` radians faces ``(sin θ,
cos θ)``, a positive yaw change is a left turn. Internally the plane is ``(a, b) = (z, x)`` with heading angle
``θ`` measured counter-clockwise from ``+a`` (left = ``+b``), the usual frame of the textbook formulas.
"""

from __future__ import annotations

import numpy as np

from stylemotion.geometry import rotate_yaw_xz

_TWO_PI = 2.0 * np.pi
#: End-pose mismatch (in turning radii, and radians) below which a word's formula counts as reaching the goal.
_REACH_TOLERANCE = 1e-6


def _mod(angle: np.ndarray) -> np.ndarray:
    """Angles in ``[0, 2π)``, one within rounding below 2π taken as 0 (an arc of length 0, not a full circle)."""
    out = np.mod(angle, _TWO_PI)
    return np.where(out > _TWO_PI - 1e-9, 0.0, out)


def _root(square: np.ndarray) -> np.ndarray:
    """Square root of a length² that rounding may have put just below 0 (a word whose line has length 0)."""
    return np.sqrt(np.where(square > -1e-9, np.maximum(square, 0.0), np.nan))


def _end_pose(word: str, t: np.ndarray, p: np.ndarray, q: np.ndarray, alpha: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """End ``(a, b, heading)`` of ``word`` (three letters of L, R, S) with lengths ``t, p, q`` (in radii)
    started at the origin with heading ``alpha``, unit radius."""
    a, b, h = np.zeros_like(alpha), np.zeros_like(alpha), alpha.copy()
    for letter, length in zip(word, (t, p, q)):
        if letter == "S":
            a, b = a + length * np.cos(h), b + length * np.sin(h)
        elif letter == "L":  # centre on the left: (a, b) + (−sin h, cos h)
            a, b = a + np.sin(h + length) - np.sin(h), b - np.cos(h + length) + np.cos(h)
            h = h + length
        else:  # centre on the right
            a, b = a - np.sin(h - length) + np.sin(h), b + np.cos(h - length) - np.cos(h)
            h = h - length
    return a, b, h


def _csc(d: np.ndarray, alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Shortest of LSL, RSR, LSR, RSL from ``(0, 0, alpha)`` to ``(d, 0, beta)``, unit radius (inf where none
    exists; the four formulas are checked against :func:`_end_pose` by tests/reconstruct/test_turning.py)."""
    sa, sb, ca, cb = np.sin(alpha), np.sin(beta), np.cos(alpha), np.cos(beta)
    cab = np.cos(alpha - beta)
    best = np.full(d.shape, np.inf)
    with np.errstate(invalid="ignore"):
        p = _root(2.0 + d * d - 2.0 * cab + 2.0 * d * (sa - sb))  # LSL
        tmp = np.arctan2(cb - ca, d + sa - sb)
        best = np.fmin(best, _mod(tmp - alpha) + p + _mod(beta - tmp))
        p = _root(2.0 + d * d - 2.0 * cab + 2.0 * d * (sb - sa))  # RSR
        tmp = np.arctan2(ca - cb, d - sa + sb)
        best = np.fmin(best, _mod(alpha - tmp) + p + _mod(tmp - beta))
        p = _root(-2.0 + d * d + 2.0 * cab + 2.0 * d * (sa + sb))  # LSR
        tmp = np.arctan2(-ca - cb, d + sa + sb) - np.arctan2(-2.0, p)
        best = np.fmin(best, _mod(tmp - alpha) + p + _mod(tmp - beta))
        p = _root(-2.0 + d * d + 2.0 * cab - 2.0 * d * (sa + sb))  # RSL
        tmp = np.arctan2(ca + cb, d - sa - sb) - np.arctan2(2.0, p)
        best = np.fmin(best, _mod(alpha - tmp) + p + _mod(beta - tmp))
    return best


def _ccc(d: np.ndarray, alpha: np.ndarray, beta: np.ndarray) -> np.ndarray:
    """Shortest of RLR and LRL (each middle arc's two roots tried, each candidate checked by :func:`_end_pose`)
    from ``(0, 0, alpha)`` to ``(d, 0, beta)``, unit radius; inf where none reaches the goal."""
    sa, sb, ca, cb = np.sin(alpha), np.sin(beta), np.cos(alpha), np.cos(beta)
    cab = np.cos(alpha - beta)
    best = np.full(d.shape, np.inf)
    with np.errstate(invalid="ignore"):
        for word, x, tmp in (("RLR", (6.0 - d * d + 2.0 * cab + 2.0 * d * (sa - sb)) / 8.0,
                              np.arctan2(ca - cb, d - sa + sb)),
                             ("LRL", (6.0 - d * d + 2.0 * cab + 2.0 * d * (sb - sa)) / 8.0,
                              np.arctan2(cb - ca, d + sa - sb))):
            root = np.arccos(np.where(np.abs(x) <= 1.0 + 1e-9, np.clip(x, -1.0, 1.0), np.nan))
            for p in (root, _TWO_PI - root):
                if word == "RLR":
                    t = _mod(alpha - tmp + p / 2.0)
                    q = _mod(alpha - beta - t + p)
                else:
                    t = _mod(tmp - alpha + p / 2.0)
                    q = _mod(beta - alpha - t + p)
                a, b, h = _end_pose(word, t, p, q, alpha)
                reached = ((np.abs(a - d) < _REACH_TOLERANCE * np.maximum(1.0, d))
                           & (np.abs(b) < _REACH_TOLERANCE * np.maximum(1.0, d))
                           & (np.abs(np.sin(0.5 * (h - beta))) < _REACH_TOLERANCE))
                best = np.where(reached, np.fmin(best, t + p + q), best)
    return best


def dubins_length(start: np.ndarray, start_yaw: np.ndarray, end: np.ndarray, end_yaw: np.ndarray,
                  radius: float) -> np.ndarray:
    """Length (metres) of the shortest forward path of curvature radius ≥ ``radius`` from ground point ``start``
    ``(..., 2)`` ``(x, z)`` m facing ``start_yaw`` ``(...)`` rad to ``end`` ``(..., 2)`` facing ``end_yaw``
    (broadcast together); ``(...)``. ``radius`` must be > 0 (ValueError otherwise)."""
    if not (np.isfinite(radius) and radius > 0):
        raise ValueError(f"radius={radius} must be a positive number of metres")
    start, end = np.asarray(start, np.float64), np.asarray(end, np.float64)
    start_yaw, end_yaw = np.asarray(start_yaw, np.float64), np.asarray(end_yaw, np.float64)
    delta = (end - start) / radius  # (x, z), in radii
    shape = np.broadcast_shapes(delta.shape[:-1], start_yaw.shape, end_yaw.shape)
    delta = np.broadcast_to(delta, shape + (2,))
    d = np.hypot(delta[..., 0], delta[..., 1])
    # the frame (a, b) = (z, x) turned so that the goal lies on +a: heading angles are yaws minus the goal's bearing
    bearing = np.arctan2(delta[..., 0], delta[..., 1])
    alpha = _mod(np.broadcast_to(start_yaw, shape) - bearing)
    beta = _mod(np.broadcast_to(end_yaw, shape) - bearing)
    d, alpha, beta = d.ravel(), alpha.ravel(), beta.ravel()
    best = _csc(d, alpha, beta)
    near = np.flatnonzero(d < 4.0 + 1e-6)  # a CCC word exists only for goals within 4 radii
    if near.size:
        best[near] = np.fmin(best[near], _ccc(d[near], alpha[near], beta[near]))
    best = best.reshape(shape)
    return best * radius


def walk_end(start: np.ndarray, start_yaw: float, word: str, lengths: tuple[float, float, float],
             radius: float) -> tuple[np.ndarray, float]:
    """Ground point ``(2,)`` ``(x, z)`` m and yaw (rad) reached from ``start`` facing ``start_yaw`` by ``word``
    (three of L, R, S) with arc/line ``lengths`` in metres: the forward model the lengths above are checked by."""
    t, p, q = (np.asarray(v / radius, np.float64) for v in lengths)
    a, b, h = _end_pose(word, t, p, q, np.asarray(0.0))
    local = np.array([float(b), float(a)]) * radius  # (x, z) in the start's frame facing +z
    return np.asarray(start, np.float64) + rotate_yaw_xz(local, float(start_yaw)), float(start_yaw + h)


__all__ = ["dubins_length", "walk_end"]
