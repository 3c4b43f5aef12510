"""``stylemotion-view PATH... --out DIR [--serve]``: motions in the browser (a static three.js page).

PATH: BVH files, motion NPZ files or run folders (see :mod:`stylemotion.viewer.motions`). The folder
``--out`` (refused if it exists, unless ``--force``) holds ``index.html`` and everything it needs, opens
from disk and from any static server; ``--serve`` serves it on 127.0.0.1 and prints the URL. Bad input,
an existing ``--out`` and a port in use end in one line ``stylemotion-view: …`` with exit status 2,
before anything is written (:mod:`stylemotion.cli.skeleton`).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence

from stylemotion.cli.skeleton import argparse_command
from stylemotion.io.errors import UserInputError
from stylemotion.io.outputs import check_new_output
from stylemotion.viewer.motions import read_inputs
from stylemotion.viewer.page import LAYOUTS, write_viewer
from stylemotion.viewer.serve import bind, serve_folder, url

#: Widest spacing of motions side by side (m).
MAX_SPACING_M = 1000.0


def _check_numbers(args: argparse.Namespace) -> None:
    """Refuse numbers no page can use (a NaN spacing would reach the page's data)."""
    if not (math.isfinite(args.spacing) and 0 <= args.spacing <= MAX_SPACING_M):
        raise UserInputError(f"--spacing {args.spacing}: expected metres in 0–{MAX_SPACING_M:g} (motions side by "
                             "side; more would put them out of sight and, far enough, out of float range)")
    if not (math.isfinite(args.fps) and args.fps > 0):
        raise UserInputError(f"--fps {args.fps}: expected a finite number of frames per second > 0")
    if args.max_samples < 1:
        raise UserInputError(f"--max-samples {args.max_samples}: expected a whole number ≥ 1")
    if not 0 <= args.port <= 65535:
        raise UserInputError(f"--port {args.port}: expected a port number in 0–65535")


def view(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="stylemotion-view", description=__doc__.splitlines()[0])
    parser.add_argument("paths", nargs="+", metavar="PATH", help="BVH file, motion NPZ or run folder")
    parser.add_argument("--out", required=True, help="output folder (index.html and its files)")
    parser.add_argument("--force", action="store_true", help="replace an existing --out folder")
    parser.add_argument("--serve", action="store_true", help="serve --out on 127.0.0.1 and print the URL")
    parser.add_argument("--port", type=int, default=8000, help="port of --serve (0: a free one; default 8000)")
    parser.add_argument("--layout", choices=LAYOUTS, default="side", help="side by side (default) or overlaid")
    parser.add_argument("--spacing", type=float, default=1.0, help="metres between motions side by side")
    parser.add_argument("--fps", type=float, default=30.0, help="frame rate BVH files are converted to")
    parser.add_argument("--max-samples", type=int, default=16, help="most motions taken from one samples file")
    parser.add_argument("--title", default="", help="page title (default: the paths)")
    args = parser.parse_args(argv)
    _check_numbers(args)
    server = None
    try:
        check_new_output(args.out, args.force, key="--out")
        if args.serve:
            server = bind(args.port)
        motions = read_inputs(args.paths, fps=args.fps, max_samples=args.max_samples)
        index = write_viewer(motions, args.out, args.force, args.title or " ".join(args.paths), args.layout,
                             args.spacing)
    except BaseException:
        if server is not None:
            server.server_close()
        raise
    print(f"{index}: {len(motions)} motion(s)")
    if server is not None:
        print(f"serving {args.out} at {url(server)} (Ctrl-C stops)", flush=True)
        try:
            serve_folder(server, args.out)
        except KeyboardInterrupt:
            pass
    return 0


main = argparse_command("stylemotion-view", view)


def cli() -> None:
    """Console-script entry point."""
    sys.exit(main())


if __name__ == "__main__":
    cli()
