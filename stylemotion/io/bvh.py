"""BVH reading and writing for any skeleton.

Supports 3 or 6 (or any) channels per joint, position channels that replace the OFFSET, any
Euler rotation order (the order of a joint's rotation channels, intrinsic), End Sites and any
frame time. Every error names the file and line.
"""

from __future__ import annotations

import io
import os
import re
import warnings
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.errors import BvhError
from stylemotion.motion import Motion
from stylemotion.skeleton import Skeleton

_ROTATION_CHANNELS = {"Xrotation": "X", "Yrotation": "Y", "Zrotation": "Z"}
_POSITION_CHANNELS = {"Xposition": 0, "Yposition": 1, "Zposition": 2}
_TOKEN = re.compile(r"\S+")


class _Tokens:
    """Whitespace tokens of the hierarchy section, with their line numbers."""

    def __init__(self, text: str, source: str, motion_line: int | None = None):
        self.source = source
        self.items: list[tuple[str, int]] = []
        for lineno, line in enumerate(text.split("\n"), start=1):
            self.items.extend((tok, lineno) for tok in _TOKEN.findall(line))
        self.pos = 0
        # Line of the MOTION keyword that ends the hierarchy, or None when the file has none.
        self.motion_line = motion_line
        self.last_line = text.count("\n") + 1

    @property
    def line(self) -> int:
        if self.pos < len(self.items):
            return self.items[self.pos][1]
        return self.items[-1][1] if self.items else 1

    def next(self, expected: str) -> str:
        if self.pos >= len(self.items):
            if self.motion_line is not None:
                raise BvhError(self.source, f"hierarchy is incomplete: found 'MOTION', expected {expected}",
                               self.motion_line)
            raise BvhError(self.source, f"file ends inside the hierarchy, expected {expected}",
                           self.line)
        tok = self.items[self.pos][0]
        self.pos += 1
        return tok

    def expect(self, word: str) -> None:
        line = self.line
        tok = self.next(repr(word))
        if tok != word:
            raise BvhError(self.source, f"expected {word!r}, found {tok!r}", line)

    def number(self, what: str) -> float:
        line = self.line
        tok = self.next(what)
        try:
            value = float(tok)
        except ValueError:
            raise BvhError(self.source, f"expected a number for {what}, found {tok!r}", line) from None
        if not np.isfinite(value):
            raise BvhError(self.source, f"{what} is {tok!r}, expected a finite number", line)
        return value


def _parse_hierarchy(tokens: _Tokens) -> Skeleton:
    names: list[str] = []
    parents: list[int] = []
    offsets: list[list[float]] = []
    channels: list[list[str]] = []
    end_sites: dict[int, np.ndarray] = {}

    def offset(what: str) -> list[float]:
        tokens.expect("OFFSET")
        return [tokens.number(f"{what} OFFSET {axis}") for axis in "xyz"]

    def joint(parent: int) -> None:
        line = tokens.line
        name = tokens.next("a joint name")
        if name in names:
            raise BvhError(tokens.source, f"joint name {name!r} appears twice", line)
        tokens.expect("{")
        index = len(names)
        names.append(name)
        parents.append(parent)
        offsets.append(offset(f"joint {name!r}"))
        channels.append([])
        if tokens.pos < len(tokens.items) and tokens.items[tokens.pos][0] == "CHANNELS":
            chan_line = tokens.line
            tokens.next("CHANNELS")
            count = tokens.number(f"joint {name!r} channel count")
            if count != int(count) or count < 0:
                raise BvhError(tokens.source, f"joint {name!r}: bad channel count {count}, expected a "
                               "non-negative integer", chan_line)
            for k in range(int(count)):
                ch_line = tokens.line
                ch = tokens.items[tokens.pos][0] if tokens.pos < len(tokens.items) else None
                valid = ch in _ROTATION_CHANNELS or ch in _POSITION_CHANNELS
                if not valid and (ch is None or ch_line != chan_line):
                    # The channel list ran out of names: the count is larger than the list.
                    raise BvhError(
                        tokens.source,
                        f"joint {name!r}: CHANNELS declares {int(count)} channels but lists {k}, "
                        f"expected {int(count)} channel names",
                        chan_line,
                    )
                tokens.next(f"joint {name!r} channel name")
                if not valid:
                    raise BvhError(
                        tokens.source,
                        f"joint {name!r}: channel {ch!r} is not one of "
                        f"{sorted(_POSITION_CHANNELS) + sorted(_ROTATION_CHANNELS)} "
                        f"(declared {int(count)} channels)",
                        ch_line,
                    )
                channels[index].append(ch)
            if tokens.pos < len(tokens.items) and (
                tokens.items[tokens.pos][0] in _ROTATION_CHANNELS
                or tokens.items[tokens.pos][0] in _POSITION_CHANNELS
            ):
                raise BvhError(
                    tokens.source,
                    f"joint {name!r}: CHANNELS declares {int(count)} channels but lists more "
                    f"({tokens.items[tokens.pos][0]!r} is extra), expected exactly {int(count)} names",
                    chan_line,
                )
            axes = [_ROTATION_CHANNELS[c] for c in channels[index] if c in _ROTATION_CHANNELS]
            positions = [c for c in channels[index] if c in _POSITION_CHANNELS]
            if (axes and sorted(axes) != ["X", "Y", "Z"]) or len(set(positions)) != len(positions):
                raise BvhError(
                    tokens.source,
                    f"joint {name!r}: channels {' '.join(channels[index])} are not supported, expected "
                    "no rotation channels or exactly one each of Xrotation, Yrotation, Zrotation "
                    "(and no repeated position channel)",
                    chan_line,
                )
        while True:
            line = tokens.line
            tok = tokens.next(f"JOINT, End Site or '}}' closing joint {name!r}")
            if tok == "JOINT":
                joint(index)
            elif tok == "End":
                tokens.expect("Site")
                tokens.expect("{")
                end_sites[index] = np.array(offset(f"End Site of {name!r}"))
                tokens.expect("}")
            elif tok == "}":
                return
            else:
                raise BvhError(
                    tokens.source, f"unexpected {tok!r} in joint {name!r}, expected JOINT, End Site or '}}'",
                    line,
                )

    tokens.expect("HIERARCHY")
    tokens.expect("ROOT")
    joint(-1)
    return Skeleton(names, np.array(parents), np.array(offsets), channels, end_sites)


def _token_counts_per_line(data: bytes) -> np.ndarray:
    """Number of whitespace-separated tokens on each line of ``data`` (vectorized)."""
    b = np.frombuffer(data, dtype=np.uint8)
    if b.size == 0:
        return np.zeros(0, dtype=np.int64)
    ws = (b == 32) | (b == 9) | (b == 13) | (b == 10) | (b == 11) | (b == 12)
    starts = ~ws
    starts[1:] &= ws[:-1]
    newlines = np.flatnonzero(b == 10)
    line_starts = np.concatenate(([0], newlines + 1))
    line_starts = line_starts[line_starts < b.size]
    return np.add.reduceat(starts.astype(np.int64), line_starts)


def parse_bvh(data: bytes | str, source: str = "<memory>") -> Motion:
    """Parse BVH text into a :class:`Motion` (file units, file fps).

    Raises:
        BvhError: naming ``source`` and the line, for any malformed content.
    """
    raw = data.encode() if isinstance(data, str) else data
    match = re.search(rb"^[ \t]*MOTION[ \t\r]*$", raw, flags=re.MULTILINE)
    if match is None:
        # Parse what there is so that the error says where the file stops making sense.
        _raise_missing_motion(raw, source)
    motion_line = raw[: match.start()].count(b"\n") + 1
    try:
        header = raw[: match.start()].decode("utf-8")
    except UnicodeDecodeError as exc:
        raise BvhError(source, f"hierarchy is not text ({exc})") from None
    tokens = _Tokens(header, source, motion_line)
    if not tokens.items:
        raise BvhError(source, "empty hierarchy, expected 'HIERARCHY'", 1)
    skeleton = _parse_hierarchy(tokens)
    if tokens.pos != len(tokens.items):
        raise BvhError(source, f"unexpected {tokens.items[tokens.pos][0]!r} after the hierarchy, "
                       "expected 'MOTION'", tokens.line)

    # MOTION section: "Frames: n" and "Frame Time: t" lines, then one row per frame.
    first_line = raw[: match.start()].count(b"\n") + 2  # line number after "MOTION"
    rest = raw[match.end() :]
    if rest.startswith(b"\n"):
        rest = rest[1:]
    lines = rest.split(b"\n", 2)
    head = [ln.decode("utf-8", "replace").strip() for ln in lines[:2]]
    frames_m = re.fullmatch(r"Frames:\s*(\S+)", head[0]) if head else None
    if frames_m is None:
        raise BvhError(source, f"expected 'Frames: <count>', found {head[0] if head else 'end of file'!r}",
                       first_line)
    try:
        num_frames = int(frames_m.group(1))
    except ValueError:
        raise BvhError(source, f"frame count {frames_m.group(1)!r} is not an integer", first_line) from None
    if num_frames <= 0:
        raise BvhError(source, f"file has {num_frames} frames, expected at least one", first_line)
    time_m = re.fullmatch(r"Frame\s+Time:\s*(\S+)", head[1]) if len(head) > 1 else None
    if time_m is None:
        raise BvhError(source, f"expected 'Frame Time: <seconds>', found "
                       f"{head[1] if len(head) > 1 else 'end of file'!r}", first_line + 1)
    try:
        frame_time = float(time_m.group(1))
    except ValueError:
        frame_time = float("nan")
    if not np.isfinite(frame_time) or frame_time <= 0:
        raise BvhError(source, f"frame time {time_m.group(1)!r} is not a positive number of seconds",
                       first_line + 1)

    body = lines[2] if len(lines) > 2 else b""
    body_line = first_line + 2
    num_channels = sum(len(c) for c in skeleton.channels)
    values = _parse_rows(body, num_frames, num_channels, source, body_line)
    return _motion_from_channels(skeleton, values, snap_fps(1.0 / frame_time), source)


def _raise_missing_motion(raw: bytes, source: str) -> None:
    """Raise the error for a file without a MOTION line, at the line where it was expected."""
    header = raw.decode("utf-8", "replace")
    tokens = _Tokens(header, source)
    if not tokens.items:
        raise BvhError(source, "empty file, expected 'HIERARCHY'", 1)
    _parse_hierarchy(tokens)  # raises, naming the line, when the file ends inside the hierarchy
    if tokens.pos < len(tokens.items):
        found = tokens.items[tokens.pos][0]
        raise BvhError(source, f"expected 'MOTION' after the hierarchy, found {found!r}", tokens.line)
    raise BvhError(source, "file ends after the hierarchy, expected 'MOTION'", tokens.last_line)


def snap_fps(fps: float, tolerance: float = 1e-3) -> float:
    """Round ``fps`` to an integer when it is within ``tolerance`` (relative) of one.

    BVH files store the frame time with few digits (``0.016667``, ``0.0333333``); 59.9988 fps is
    meant as 60.
    """
    nearest = round(fps)
    return float(nearest) if nearest > 0 and abs(fps - nearest) <= tolerance * fps else float(fps)


def _parse_rows(body: bytes, num_frames: int, num_channels: int, source: str, body_line: int) -> np.ndarray:
    """``(num_frames, num_channels)`` float64 from the frame rows; errors name the row's line."""
    counts = _token_counts_per_line(body)
    nonempty = np.flatnonzero(counts > 0)
    if nonempty.size < num_frames:
        if nonempty.size and counts[nonempty[-1]] != num_channels:
            # Cut inside the last row: point at that row.
            last = int(nonempty[-1])
            raise BvhError(source, f"file is truncated inside frame row {nonempty.size}: it has "
                           f"{int(counts[last])} values, expected {num_channels}; header says "
                           f"{num_frames} frames", body_line + last)
        # Whole rows missing: point at the line where the next row was expected.
        missing = body_line + (int(nonempty[-1]) + 1 if nonempty.size else 0)
        raise BvhError(source, f"file is truncated: header says {num_frames} frames, found "
                       f"{nonempty.size} frame rows; expected frame row {nonempty.size + 1}", missing)
    if nonempty.size > num_frames:
        extra = body_line + int(nonempty[num_frames])
        raise BvhError(source, f"found {nonempty.size} frame rows, header says {num_frames}", extra)
    bad = nonempty[counts[nonempty] != num_channels]
    if bad.size:
        line = int(bad[0])
        cut_short = line == nonempty[-1] and counts[line] < num_channels
        ends_mid_row = not body.rstrip(b" \t").endswith(b"\n")
        hint = "; the file looks truncated inside its last row" if cut_short and ends_mid_row else ""
        raise BvhError(source, f"frame row has {int(counts[line])} values, expected {num_channels} "
                       f"(the hierarchy declares {num_channels} channels){hint}", body_line + line)
    try:
        with warnings.catch_warnings():
            # numpy warns (DeprecationWarning) and stops at an unparsable token; we report it below.
            warnings.simplefilter("ignore", DeprecationWarning)
            values = np.fromstring(body, dtype=np.float64, sep=" ")  # noqa: NPY201 - text mode is supported
        ok = values.size == num_frames * num_channels
    except ValueError:
        ok = False
    if not ok or not np.all(np.isfinite(values)):
        _raise_first_bad_value(body, source, body_line)
    return values.reshape(num_frames, num_channels)


def _raise_first_bad_value(body: bytes, source: str, body_line: int) -> None:
    for offset, line in enumerate(body.split(b"\n")):
        for column, tok in enumerate(line.split(), start=1):
            try:
                value = float(tok)
            except ValueError:
                value = None
            if value is None or not np.isfinite(value):
                raise BvhError(source, f"value {tok.decode('utf-8', 'replace')!r} in column {column} "
                               "is not a finite number", body_line + offset)
    raise BvhError(source, "could not parse the frame rows", body_line)


def _motion_from_channels(skeleton: Skeleton, values: np.ndarray, fps: float, source: str) -> Motion:
    num_frames = values.shape[0]
    num_joints = skeleton.num_joints
    translations = np.broadcast_to(skeleton.offsets, (num_frames, num_joints, 3)).copy()
    rotations = np.zeros((num_frames, num_joints, 4))
    rotations[..., 3] = 1.0
    column = 0
    # Group joints by rotation order so that each order is one vectorized scipy call.
    by_order: dict[str, list[tuple[int, list[int]]]] = {}
    for j, chans in enumerate(skeleton.channels):
        rot_cols: list[int] = []
        order = ""
        for ch in chans:
            if ch in _POSITION_CHANNELS:
                translations[:, j, _POSITION_CHANNELS[ch]] = values[:, column]
            else:
                order += _ROTATION_CHANNELS[ch]
                rot_cols.append(column)
            column += 1
        if order:
            if len(order) != 3 or len(set(order)) != 3:
                raise BvhError(source, f"joint {skeleton.names[j]!r}: rotation channels {order} are not "
                               "three distinct axes")
            by_order.setdefault(order, []).append((j, rot_cols))
    for order, joints in by_order.items():
        idx = [j for j, _ in joints]
        angles = values[:, [c for _, cols in joints for c in cols]].reshape(num_frames, len(idx), 3)
        quats = Rotation.from_euler(order, angles.reshape(-1, 3), degrees=True).as_quat()
        rotations[:, idx] = quats.reshape(num_frames, len(idx), 4)
    return Motion(skeleton, rotations, translations, fps, source)


def read_bvh(path: str | os.PathLike) -> Motion:
    """Read one BVH file from disk."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise BvhError(str(path), f"cannot read file ({exc.strerror or exc})") from None
    return parse_bvh(data, str(path))


# ---------------------------------------------------------------------------------------------
# Writing


def format_bvh(motion: Motion, precision: int = 6) -> str:
    """BVH text for ``motion``, keeping its skeleton's channels and rotation orders."""
    sk = motion.skeleton
    out = io.StringIO()
    out.write("HIERARCHY\n")
    children: dict[int, list[int]] = {j: sk.children(j) for j in range(sk.num_joints)}
    fmt = f"{{:.{precision}f}}"

    def vec(v: np.ndarray) -> str:
        return " ".join(fmt.format(float(x)) for x in v)

    def write_joint(j: int, depth: int) -> None:
        ind = "\t" * depth
        out.write(f"{ind}{'ROOT' if sk.parents[j] < 0 else 'JOINT'} {sk.names[j]}\n{ind}{{\n")
        out.write(f"{ind}\tOFFSET {vec(sk.offsets[j])}\n")
        if sk.channels[j]:
            out.write(f"{ind}\tCHANNELS {len(sk.channels[j])} {' '.join(sk.channels[j])}\n")
        for c in children[j]:
            write_joint(c, depth + 1)
        if j in sk.end_sites:
            out.write(f"{ind}\tEnd Site\n{ind}\t{{\n{ind}\t\tOFFSET {vec(sk.end_sites[j])}\n{ind}\t}}\n")
        out.write(f"{ind}}}\n")

    roots = [j for j in range(sk.num_joints) if sk.parents[j] < 0]
    if len(roots) != 1:
        raise ValueError(f"{motion.source}: a BVH file needs exactly one root joint, found {len(roots)}")
    write_joint(roots[0], 0)
    out.write(f"MOTION\nFrames: {motion.num_frames}\nFrame Time: {1.0 / motion.fps:.8f}\n")
    out.write(_format_rows(motion, precision))
    return out.getvalue()


def _format_rows(motion: Motion, precision: int) -> str:
    sk = motion.skeleton
    columns: list[np.ndarray] = []
    for j, chans in enumerate(sk.channels):
        order = "".join(_ROTATION_CHANNELS[c] for c in chans if c in _ROTATION_CHANNELS)
        angles = (Rotation.from_quat(motion.rotations[:, j]).as_euler(order, degrees=True)
                  if order else None)
        k = 0
        for ch in chans:
            if ch in _POSITION_CHANNELS:
                columns.append(motion.translations[:, j, _POSITION_CHANNELS[ch]])
            else:
                columns.append(angles[:, k])
                k += 1
    if not columns:
        return "\n" * motion.num_frames
    table = np.stack(columns, axis=1)
    buf = io.StringIO()
    np.savetxt(buf, table, fmt=f"%.{precision}f", delimiter=" ")
    return buf.getvalue()


def write_bvh(motion: Motion, path: str | os.PathLike, precision: int = 6) -> None:
    """Write ``motion`` to ``path`` atomically (a temporary file renamed into place)."""
    path = Path(path)
    text = format_bvh(motion, precision)
    atomic_write_bytes(path, text.encode("utf-8"))
