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
from stylemotion.io.errors import BvhError, LimitError, MotionDataError
from stylemotion.io.sources import check_file_size, regular_file_stat
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


def _parse_channels(tokens: _Tokens, name: str) -> list[str]:
    """The channel names after ``CHANNELS`` (the keyword already consumed), checked."""
    chan_line = tokens.items[tokens.pos - 1][1]
    count = tokens.number(f"joint {name!r} channel count")
    if count != int(count) or count < 0:
        raise BvhError(tokens.source, f"joint {name!r}: bad channel count {count}, expected a "
                       "non-negative integer", chan_line)
    channels: list[str] = []
    for k in range(int(count)):
        ch_line = tokens.line
        ch = tokens.items[tokens.pos][0] if tokens.pos < len(tokens.items) else None
        valid = ch in _ROTATION_CHANNELS or ch in _POSITION_CHANNELS
        if not valid and (ch is None or ch_line != chan_line):
            # The channel list ran out of names: the count is larger than the list.
            raise BvhError(tokens.source, f"joint {name!r}: CHANNELS declares {int(count)} channels but "
                           f"lists {k}, expected {int(count)} channel names", chan_line)
        tokens.next(f"joint {name!r} channel name")
        if not valid:
            raise BvhError(
                tokens.source,
                f"joint {name!r}: channel {ch!r} is not one of "
                f"{sorted(_POSITION_CHANNELS) + sorted(_ROTATION_CHANNELS)} (declared {int(count)} channels)",
                ch_line,
            )
        channels.append(ch)
    if tokens.pos < len(tokens.items) and (
        tokens.items[tokens.pos][0] in _ROTATION_CHANNELS or tokens.items[tokens.pos][0] in _POSITION_CHANNELS
    ):
        raise BvhError(
            tokens.source,
            f"joint {name!r}: CHANNELS declares {int(count)} channels but lists more "
            f"({tokens.items[tokens.pos][0]!r} is extra), expected exactly {int(count)} names",
            chan_line,
        )
    axes = [_ROTATION_CHANNELS[c] for c in channels if c in _ROTATION_CHANNELS]
    positions = [c for c in channels if c in _POSITION_CHANNELS]
    if (axes and sorted(axes) != ["X", "Y", "Z"]) or len(set(positions)) != len(positions):
        raise BvhError(
            tokens.source,
            f"joint {name!r}: channels {' '.join(channels)} are not supported, expected no rotation "
            "channels or exactly one each of Xrotation, Yrotation, Zrotation (and no repeated position channel)",
            chan_line,
        )
    return channels


def _parse_hierarchy(tokens: _Tokens) -> Skeleton:
    """The skeleton of the HIERARCHY section.

    Iterative (an explicit stack of open joints), so any nesting depth parses: a chain of
    thousands of joints is bounded by memory, not by Python's recursion limit.
    """
    names: list[str] = []
    seen: set[str] = set()
    parents: list[int] = []
    offsets: list[list[float]] = []
    channels: list[list[str]] = []
    end_sites: dict[int, np.ndarray] = {}

    def offset(what: str) -> list[float]:
        tokens.expect("OFFSET")
        return [tokens.number(f"{what} OFFSET {axis}") for axis in "xyz"]

    def open_joint(parent: int) -> int:
        """Read a joint's name, '{', OFFSET and CHANNELS; returns its index."""
        line = tokens.line
        name = tokens.next("a joint name")
        if name in seen:
            raise BvhError(tokens.source, f"joint name {name!r} appears twice", line)
        tokens.expect("{")
        index = len(names)
        names.append(name)
        seen.add(name)
        parents.append(parent)
        offsets.append(offset(f"joint {name!r}"))
        chans: list[str] = []
        if tokens.pos < len(tokens.items) and tokens.items[tokens.pos][0] == "CHANNELS":
            tokens.next("CHANNELS")
            chans = _parse_channels(tokens, name)
        channels.append(chans)
        return index

    tokens.expect("HIERARCHY")
    tokens.expect("ROOT")
    stack = [open_joint(-1)]  # joints whose '}' has not been read yet, innermost last
    while stack:
        current = stack[-1]
        name = names[current]
        line = tokens.line
        tok = tokens.next(f"JOINT, End Site or '}}' closing joint {name!r}")
        if tok == "JOINT":
            stack.append(open_joint(current))
        elif tok == "End":
            tokens.expect("Site")
            tokens.expect("{")
            end_sites[current] = np.array(offset(f"End Site of {name!r}"))
            tokens.expect("}")
        elif tok == "}":
            stack.pop()
        else:
            raise BvhError(tokens.source, f"unexpected {tok!r} in joint {name!r}, expected JOINT, End Site or "
                           "'}'", line)
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


#: Default cap on frames × joints of one parsed motion (its per-joint arrays; ≈ 2–3 GB while parsing).
DEFAULT_MAX_JOINT_FRAMES = 20_000_000
#: A Frame Time at least this long (seconds) over at least this many frames looks like milliseconds.
_MS_FRAME_TIME_S, _MS_MIN_FRAMES = 1.0, 10
_UTF8_BOM = b"\xef\xbb\xbf"


def normalize_text(raw: bytes, source: str) -> bytes:
    """``raw`` with a UTF-8 byte-order mark dropped and CR-LF or CR-only line ends made LF.

    Line numbers are kept: each CR-LF, CR or LF ends one line.

    Raises:
        BvhError: for UTF-16/32 text (a byte-order mark other than UTF-8's), naming line 1.
    """
    if raw.startswith(_UTF8_BOM):
        raw = raw[len(_UTF8_BOM):]
    elif raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise BvhError(source, "file is UTF-16 or UTF-32 text (byte-order mark); expected ASCII or UTF-8, "
                       "re-save it as UTF-8", 1)
    if b"\r" in raw:
        raw = raw.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    return raw


def parse_bvh(data: bytes | str, source: str = "<memory>",
              max_joint_frames: int | None = DEFAULT_MAX_JOINT_FRAMES) -> Motion:
    """Parse BVH text into a :class:`Motion` (file units, file fps).

    LF, CR-LF and CR-only line ends and a UTF-8 byte-order mark are accepted.

    Args:
        data: the file's bytes (or text).
        source: what messages call the file.
        max_joint_frames: refuse a motion of more frames × joints than this, before allocating
            its arrays (None: no limit).

    Raises:
        BvhError: naming ``source`` and the line, for any malformed content (and a Frame Time in ms).
        LimitError: the motion is larger than ``max_joint_frames``.

    A Frame Time that looks like milliseconds (≥ 1 s over ≥ 10 frames) is a :class:`BvhError`: read as
    seconds, resampling would make a few seconds of motion a thousand times longer.
    """
    raw = normalize_text(data.encode() if isinstance(data, str) else data, source)
    skeleton, match = _parse_header(raw, source)

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
    check_joint_frames(num_frames, skeleton.num_joints, max_joint_frames, source, "in the file")
    if frame_time >= _MS_FRAME_TIME_S and num_frames >= _MS_MIN_FRAMES:
        # read as seconds, resampling would make a few seconds of motion a thousand times longer
        raise BvhError(source, f"Frame Time {time_m.group(1)} s ({1.0 / frame_time:.3g} fps) over {num_frames} "
                       f"frames looks like milliseconds; BVH Frame Time is in seconds (for {frame_time:g} ms "
                       f"write Frame Time: {frame_time / 1000:g})", first_line + 1)
    return _motion_from_channels(skeleton, values, snap_fps(1.0 / frame_time), source)


def _parse_header(raw: bytes, source: str) -> tuple[Skeleton, re.Match[bytes]]:
    """The skeleton of normalized BVH bytes and the match of their ``MOTION`` line (BvhError naming the line)."""
    match = re.search(rb"^[ \t]*MOTION[ \t]*$", raw, flags=re.MULTILINE)
    if match is None:
        # Parse what there is so that the error says where the file stops making sense.
        _raise_missing_motion(raw, source)
    motion_line = raw[: match.start()].count(b"\n") + 1
    try:
        header = raw[: match.start()].decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise BvhError(source, f"hierarchy is not UTF-8 text (byte {raw[exc.start]:#04x})", line) from None
    tokens = _Tokens(header, source, motion_line)
    if not tokens.items:
        raise BvhError(source, "empty hierarchy, expected 'HIERARCHY'", 1)
    skeleton = _parse_hierarchy(tokens)
    if tokens.pos != len(tokens.items):
        raise BvhError(source, f"unexpected {tokens.items[tokens.pos][0]!r} after the hierarchy, "
                       "expected 'MOTION'", tokens.line)
    return skeleton, match


#: Most bytes :func:`parse_bvh_skeleton` reads before the ``MOTION`` line must have come.
MAX_HIERARCHY_BYTES = 1_000_000


def parse_bvh_skeleton(head: bytes, source: str = "<memory>") -> Skeleton:
    """The skeleton (hierarchy and rest offsets, file units) of a BVH file from its first bytes, frames unread.

    Args:
        head: the file's first bytes, at least up to its ``MOTION`` line (e.g.
            :meth:`stylemotion.io.sources.FileSource.read_head` of :data:`MAX_HIERARCHY_BYTES`).
        source: what messages call the file.

    Raises:
        BvhError: naming ``source`` and the line, for a malformed hierarchy or no ``MOTION`` line in ``head``.
    """
    raw = normalize_text(head, source)
    cut = raw.rfind(b"\n") + 1
    if raw[cut:].strip() != b"MOTION":  # a line the read cut short is not parsed
        raw = raw[:cut]
    return _parse_header(raw, source)[0]


def check_joint_frames(num_frames: int, num_joints: int, limit: int | None, source: str, when: str) -> None:
    """Raise :class:`LimitError` if ``num_frames × num_joints`` exceeds ``limit`` (None: no limit)."""
    if limit is not None and num_frames * num_joints > limit:
        raise LimitError(source, f"{num_frames} frames × {num_joints} joints {when} = {num_frames * num_joints} "
                         f"joint-frames, more than the limit data.max_joint_frames={limit} "
                         "(raise it for longer or larger motions)")


def _raise_missing_motion(raw: bytes, source: str) -> None:
    """Raise the error for a file without a MOTION line, at the line where it was expected."""
    tokens = _Tokens(raw.decode("utf-8", "replace"), source)
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


def read_bvh(path: str | os.PathLike, max_file_mb: float | None = None,
             max_joint_frames: int | None = DEFAULT_MAX_JOINT_FRAMES) -> Motion:
    """Read one BVH file from disk (see :func:`parse_bvh`); ``max_file_mb`` caps its size."""
    path = Path(path)
    try:
        size = regular_file_stat(path).st_size  # a FIFO or device is refused by name, never read (it would block)
    except MotionDataError as exc:
        raise BvhError(str(path), exc.detail) from None
    try:
        check_file_size(size, max_file_mb, str(path))
        data = path.read_bytes()
    except OSError as exc:
        raise BvhError(str(path), f"cannot read file ({exc.strerror or exc})") from None
    return parse_bvh(data, str(path), max_joint_frames)


# ---------------------------------------------------------------------------------------------
# Writing


def format_bvh(motion: Motion, precision: int = 6) -> str:
    """BVH text for ``motion``, keeping its skeleton's channels and rotation orders.

    The hierarchy is written iteratively (an explicit stack), so any nesting depth works.
    """
    sk = motion.skeleton
    roots = [j for j in range(sk.num_joints) if sk.parents[j] < 0]
    if len(roots) != 1:
        raise ValueError(f"{motion.source}: a BVH file needs exactly one root joint, found {len(roots)}")
    children: list[list[int]] = [[] for _ in range(sk.num_joints)]
    for j, p in enumerate(sk.parents):
        if p >= 0:
            children[p].append(j)
    fmt = f"{{:.{precision}f}}"

    def vec(v: np.ndarray) -> str:
        return " ".join(fmt.format(float(x)) for x in v)

    out = io.StringIO()
    out.write("HIERARCHY\n")
    stack: list[tuple[int, int, bool]] = [(roots[0], 0, False)]  # (joint, depth, closing)
    while stack:
        j, depth, closing = stack.pop()
        ind = "\t" * depth
        if closing:
            if j in sk.end_sites:
                out.write(f"{ind}\tEnd Site\n{ind}\t{{\n{ind}\t\tOFFSET {vec(sk.end_sites[j])}\n{ind}\t}}\n")
            out.write(f"{ind}}}\n")
            continue
        out.write(f"{ind}{'ROOT' if sk.parents[j] < 0 else 'JOINT'} {sk.names[j]}\n{ind}{{\n")
        out.write(f"{ind}\tOFFSET {vec(sk.offsets[j])}\n")
        if sk.channels[j]:
            out.write(f"{ind}\tCHANNELS {len(sk.channels[j])} {' '.join(sk.channels[j])}\n")
        stack.append((j, depth, True))
        stack.extend((c, depth + 1, False) for c in reversed(children[j]))
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
