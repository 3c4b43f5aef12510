"""Ground paths for trajectory following (thesis §4.5.1, Fig. 5.7): a curve on the floor, by arc length.

Coordinates are the ground plane of :mod:`stylemotion.representation`: points are ``(x, z)`` in
metres (Y is up), and a heading (yaw) ``θ`` faces ``(sin θ, cos θ)`` in ``(x, z)``, so a path
running along +Z has heading 0 and one running along +X has heading π/2.

A :class:`GroundPath` is a polyline; curves given by a few control points are sampled densely from
a smoothing spline first (:meth:`GroundPath.from_points` with ``spline=True``). Paths come from a
config list, a JSON file (``[[x, z], …]`` or ``{"points": [[x, z], …]}``) or a CSV file (two
columns x, z; an optional header line), or from :func:`s_curve`.

Path files are UTF-8 (a byte-order mark is allowed). Every coordinate must be a finite number within
±:data:`MAX_COORDINATE_M` metres: empty CSV fields, booleans (``true``, JSON ``true``), strings,
``nan``/``inf`` and values like ``1e300`` (whose squares overflow) are errors (:class:`PathError`) naming
``file:line`` (CSV), the JSON index (``points[3][1]``) or the config key (``path.points[3][1]``).
"""

from __future__ import annotations

import csv
import io
import json
import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from stylemotion.geometry import direction_yaw, wrap_angle
from stylemotion.io.errors import UserInputError

#: Spacing of the dense polyline a spline is sampled to, metres.
SPLINE_SPACING_M = 0.02
#: Largest absolute coordinate of a path point, metres (1000 km: arc lengths stay exact in float64).
MAX_COORDINATE_M = 1e6
#: CSV cells read as booleans (refused, not taken for a header).
_BOOLEAN_WORDS = frozenset({"true", "false"})


class PathError(UserInputError, ValueError):
    """A path that cannot be followed (too few points, non-finite values, zero length, bad file)."""


@dataclass(frozen=True)
class GroundPath:
    """A polyline on the ground, parameterized by arc length.

    Attributes:
        points: ``(n, 2)`` float64 vertices ``(x, z)``, metres, n ≥ 2, consecutive points distinct.
        arc: ``(n,)`` arc length at each vertex, metres (``arc[0] = 0``).
    """

    points: np.ndarray
    arc: np.ndarray

    @classmethod
    def from_points(cls, points: Sequence[Sequence[float]] | np.ndarray, spline: bool = False,
                    source: str = "path") -> GroundPath:
        """A path through ``points`` ``(n, 2)`` (x, z metres); ``spline`` interpolates them with a
        cubic spline in arc length (needs ≥ 3 points) sampled every :data:`SPLINE_SPACING_M`.

        Raises:
            PathError: fewer than two distinct points, wrong shape, a value that is not a number (a
                boolean, a string), not finite or beyond ±:data:`MAX_COORDINATE_M` (names ``source``
                and the point).
        """
        if not isinstance(points, np.ndarray):
            _check_values(points, source, finite=False)  # finite and in range: checked below, per point
        elif points.dtype == np.bool_:
            raise PathError(f"{source}: points are booleans, expected numbers in metres")
        try:
            p = np.asarray(points, dtype=np.float64)
        except (TypeError, ValueError, OverflowError) as exc:
            raise PathError(f"{source}: points must be a list of [x, z] pairs ({exc})") from None
        if p.ndim != 2 or p.shape[1] != 2:
            raise PathError(f"{source}: points must be (n, 2) [x, z] pairs in metres, got shape {p.shape}")
        bad = np.flatnonzero(~np.isfinite(p).all(1))
        if bad.size:
            raise PathError(f"{source}: point {int(bad[0])} is not finite: {p[bad[0]].tolist()}")
        far = np.flatnonzero((np.abs(p) > MAX_COORDINATE_M).any(1))
        if far.size:
            raise PathError(f"{source}: point {int(far[0])} is {p[far[0]].tolist()}: coordinates must be within "
                            f"±{MAX_COORDINATE_M:g} m")
        keep = np.concatenate([[True], np.linalg.norm(np.diff(p, axis=0), axis=1) > 1e-9])
        p = p[keep]  # repeated points carry no direction
        if len(p) < 2:
            raise PathError(f"{source}: a path needs at least two distinct points, got {len(p)}")
        if spline and len(p) >= 3:
            p = _spline_points(p)
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        return cls(points=p, arc=arc)

    @classmethod
    def from_file(cls, path: str | Path, spline: bool = False) -> GroundPath:
        """Load a path from ``.json`` or ``.csv`` (see the module doc); errors name the file and the line
        (CSV, JSON syntax) or the JSON index."""
        path = Path(path)
        if not path.is_file():
            raise PathError(f"path file {str(path)!r} does not exist")
        if path.suffix.lower() == ".json":
            try:
                data = json.loads(_read_text(path))
            except json.JSONDecodeError as exc:
                raise PathError(f"{path}:{exc.lineno}: not valid JSON ({exc.msg})") from None
            points = data.get("points") if isinstance(data, dict) else data
            if points is None:
                raise PathError(f"{path}: expected a list of [x, z] pairs or an object with key 'points'")
            _check_values(points, f"{path}: " + ("points" if isinstance(data, dict) else ""))
            return cls.from_points(points, spline=spline, source=str(path))
        if path.suffix.lower() == ".csv":
            return cls.from_points(_read_csv_points(path), spline=spline, source=str(path))
        raise PathError(f"{path}: unknown path file type {path.suffix!r} (use .json or .csv)")

    @property
    def length(self) -> float:
        """Total arc length, metres."""
        return float(self.arc[-1])

    @property
    def start(self) -> np.ndarray:
        return self.points[0].copy()

    @property
    def end(self) -> np.ndarray:
        return self.points[-1].copy()

    def _segment(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        s = np.clip(np.asarray(s, dtype=np.float64), 0.0, self.length)
        seg = np.clip(np.searchsorted(self.arc, s, side="right") - 1, 0, len(self.points) - 2)
        return s, seg

    def point_at(self, s: float | np.ndarray) -> np.ndarray:
        """``(..., 2)`` point at arc length ``s`` (clamped to the path), metres."""
        s, seg = self._segment(s)
        t = ((s - self.arc[seg]) / (self.arc[seg + 1] - self.arc[seg]))[..., None]
        return self.points[seg] * (1 - t) + self.points[seg + 1] * t

    def heading_at(self, s: float | np.ndarray) -> np.ndarray:
        """Heading (yaw, radians) of the path's direction at arc length ``s``."""
        _, seg = self._segment(s)
        d = self.points[seg + 1] - self.points[seg]
        return direction_yaw(d)

    def project(self, xz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Closest points of the path to ``xz`` ``(..., 2)``: their arc lengths and distances, metres."""
        q = np.asarray(xz, dtype=np.float64)[..., None, :]
        a, b = self.points[:-1], self.points[1:]
        ab = b - a
        t = np.clip(((q - a) * ab).sum(-1) / (ab * ab).sum(-1), 0.0, 1.0)
        dist = np.linalg.norm(a + t[..., None] * ab - q, axis=-1)
        best = dist.argmin(-1)
        take = np.take_along_axis
        seg_len = np.diff(self.arc)
        s = self.arc[best] + take(t, best[..., None], -1)[..., 0] * seg_len[best]
        return s, take(dist, best[..., None], -1)[..., 0]

    def turn_per_length(self, window_m: float) -> np.ndarray:
        """``(n,)`` absolute heading change over ``window_m`` metres of path ahead of each vertex, radians."""
        s = self.arc
        h0, h1 = self.heading_at(s), self.heading_at(np.minimum(s + window_m, self.length - 1e-9))
        return np.abs(wrap_angle(h1 - h0))


def s_curve(length_m: float = 10.0, amplitude_m: float = 1.0, waves: float = 1.0) -> GroundPath:
    """An S-shaped path of (about) ``length_m`` metres along +Z: ``x = A sin(2π·waves·z / Z)``.

    The straight extent ``Z`` is chosen so that the arc length is ``length_m`` (to 1 mm).

    Args:
        length_m: arc length, metres.
        amplitude_m: sideways amplitude ``A``, metres.
        waves: full sine periods over the path (1 = one S: a left and a right bend).
    """
    if not length_m > 0:
        raise PathError(f"s_curve: length_m must be positive, got {length_m}")
    extent = float(length_m)
    for _ in range(50):  # fixed point: scale the extent until the arc length matches
        z = np.linspace(0.0, extent, 2001)
        pts = np.stack([amplitude_m * np.sin(2 * math.pi * waves * z / extent), z], axis=1)
        arc = float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())
        if abs(arc - length_m) < 1e-3:
            break
        extent *= length_m / arc
    return GroundPath.from_points(pts, source="s_curve")


def _spline_points(points: np.ndarray) -> np.ndarray:
    """Dense samples of a natural cubic spline through ``points`` (parameterized by chord length)."""
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    spline = CubicSpline(chord, points, axis=0, bc_type="natural")
    count = max(2, int(math.ceil(chord[-1] / SPLINE_SPACING_M)) + 1)
    return spline(np.linspace(0.0, chord[-1], count))


def _check_values(points: object, where: str, finite: bool = True) -> None:
    """Each item of ``points`` must be an ``[x, z]`` pair of real numbers (not booleans or strings)
    and, with ``finite``, finite and within ±:data:`MAX_COORDINATE_M`; errors name ``<where>[i][j]``."""
    if isinstance(points, (str, bytes)) or not isinstance(points, Sequence) and not _is_list(points):
        raise PathError(f"{where}: points must be a list of [x, z] pairs in metres, got {points!r}")
    for i, point in enumerate(points):
        if isinstance(point, (str, bytes)) or not (isinstance(point, Sequence) or _is_list(point)):
            raise PathError(f"{where}[{i}] is {point!r}: points must be (n, 2) [x, z] pairs in metres")
        for j, value in enumerate(point):
            _check_number(value, f"{where}[{i}][{j}]", finite)


def _is_list(value: object) -> bool:
    """A list-like config node (OmegaConf's ``ListConfig``) or array."""
    return hasattr(value, "__len__") and hasattr(value, "__getitem__") and not isinstance(value, (str, bytes, dict))


def _check_number(value: object, where: str, finite: bool = True) -> float:
    """``value`` as a float: a real number (not a boolean) and, with ``finite``, finite and within
    ±:data:`MAX_COORDINATE_M`."""
    if isinstance(value, (bool, np.bool_)):
        raise PathError(f"{where} is {value!r} (a boolean), expected a number in metres")
    if not isinstance(value, numbers.Real):
        raise PathError(f"{where} is {value!r}, expected a number in metres")
    text = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "…"
    if isinstance(value, numbers.Integral) and abs(value) > MAX_COORDINATE_M:  # before float(): 10**400 overflows
        raise PathError(f"{where} is {text}: coordinates must be within ±{MAX_COORDINATE_M:g} m")
    if not finite:
        return float(value)
    if not math.isfinite(value):
        raise PathError(f"{where} is {text}: coordinates must be finite")
    if abs(value) > MAX_COORDINATE_M:
        raise PathError(f"{where} is {text}: coordinates must be within ±{MAX_COORDINATE_M:g} m")
    return float(value)


def _read_text(path: Path) -> str:
    """The file as UTF-8 text (an initial byte-order mark dropped); a PathError naming file:line otherwise."""
    data = path.read_bytes()
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise PathError(f"{path}:{line}: not UTF-8 text (byte 0x{data[exc.start]:02x}); save the file as UTF-8") \
            from None


def _read_csv_points(path: Path) -> list[list[float]]:
    """Rows ``x, z`` of a CSV file; blank and ``#`` lines are skipped, and a first row with no number
    and no boolean in it is a header. Errors name ``file:line``."""
    points: list[list[float]] = []
    header_allowed = True
    reader = csv.reader(io.StringIO(_read_text(path), newline=""))
    for row in reader:
        line = reader.line_num
        cells = [c.strip() for c in row]
        if not any(cells) or cells[0].startswith("#"):
            continue
        if len(cells) != 2:
            raise PathError(f"{path}:{line}: expected two columns x, z, got {len(cells)}: {row}")
        if header_allowed and all(c and not _is_float(c) and c.lower() not in _BOOLEAN_WORDS for c in cells):
            header_allowed = False
            continue
        header_allowed = False
        points.append([_csv_number(cell, f"{path}:{line}", column) for column, cell in zip(("x", "z"), cells)])
    return points


def _is_float(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _csv_number(cell: str, where: str, column: str) -> float:
    """One CSV cell as a coordinate; errors name ``where`` (``file:line``) and the column."""
    if not cell:
        raise PathError(f"{where}: empty {column} field")
    if cell.lower() in _BOOLEAN_WORDS:
        raise PathError(f"{where}: {column} is {cell!r} (a boolean), expected a number in metres")
    try:
        value = float(cell)
    except ValueError:
        raise PathError(f"{where}: not a number: {column} = {cell!r}") from None
    return _check_number(value, f"{where}: {column}")
