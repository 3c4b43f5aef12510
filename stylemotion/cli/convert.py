"""``stylemotion-convert SRC.bvh DST.npz [--fps 30]``: one BVH file to canonical positions.

The work and the file's contents: :mod:`stylemotion.datasets.convert`. A bad ``--fps`` (0, negative,
nan, inf), an output that is a folder or not ``.npz``, and a file that cannot be converted end in one
line ``stylemotion-convert: …`` naming the argument or file, with exit status 2 (:mod:`stylemotion.cli.skeleton`).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from stylemotion.cli.skeleton import argparse_command


def _unit(value: str) -> float | str:
    try:
        return float(value)
    except ValueError:
        return value


def convert(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="stylemotion-convert", description=__doc__.splitlines()[0])
    parser.add_argument("src", help="BVH file (or archive.zip::member.bvh)")
    parser.add_argument("dst", help="output .npz (positions (frames, 21, 3) metres Y up, joint_names, fps)")
    parser.add_argument("--fps", type=float, default=30.0, help="output frame rate, > 0 (default 30)")
    parser.add_argument("--joint-map", default=None,
                        help="built-in map (bandai, cmu31, cmu21) or YAML file; default: auto-detect")
    parser.add_argument("--unit-scale", type=_unit, default=None,
                        help="metres per file unit or a unit name (m, cm, mm, inch, cmu); default: detect")
    parser.add_argument("--up-axis", choices=["y", "z"], default="y")
    parser.add_argument("--force", action="store_true", help="replace an existing DST")
    args = parser.parse_args(argv)
    from stylemotion.datasets.convert import check_arguments, convert_file  # after parsing: --help loads no scipy
    from stylemotion.datasets.loading import ConversionSettings

    check_arguments(args.dst, args.fps)
    settings = ConversionSettings(args.fps, args.joint_map, args.unit_scale, args.up_axis)
    positions = convert_file(args.src, args.dst, settings, args.force)
    print(f"{args.dst}: {positions.shape[0]} frames at {args.fps:g} fps, 21 joints, metres, Y up")
    return 0


main = argparse_command("stylemotion-convert", convert)


def cli() -> None:
    """Console-script entry point."""
    sys.exit(main())


if __name__ == "__main__":
    cli()
