"""Leave-one-style-out evaluation of the zero-shot style network against a reproduce run's style CVAEs.

    python scripts/zero_shot_loso.py --run runs/reproduce/synthetic --out runs/zero_shot/synthetic
    python scripts/zero_shot_loso.py --run runs/reproduce/synthetic --out /tmp/zs --epochs 30 --styles elderly \\
        --primitives walk_leftStance --set model.style_weight=5
    python scripts/zero_shot_loso.py --run runs/reproduce/synthetic --out /tmp/zs2 --checkpoints /tmp/zs  # no training

Writes ``<out>/zero_shot.json``, ``<out>/zero_shot.md`` and the networks' training folders
``<out>/models/<primitive>_without_<style>/`` (see :mod:`stylemotion.evaluation.zero_shot`).
"""

from __future__ import annotations

import argparse
import logging
import sys

from stylemotion.evaluation.zero_shot import leave_one_style_out
from stylemotion.io.outputs import OutputExistsError


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--run", required=True, help="a finished stylemotion-reproduce run folder")
    parser.add_argument("--out", required=True, help="output folder (must not exist unless --force)")
    parser.add_argument("--epochs", type=int, default=None, help="training epochs per network (default: the "
                        "zero_shot experiment's)")
    parser.add_argument("--styles", nargs="+", default=None, help="styles to leave out (default: every CVAE style)")
    parser.add_argument("--primitives", nargs="+", default=None, help="default: every primitive with CVAEs")
    parser.add_argument("--samples", type=int, default=1000, help="samples per model (default 1000)")
    parser.add_argument("--seed", type=int, default=None, help="sampling seed (default: the run's)")
    parser.add_argument("--checkpoints", default=None, help="an earlier --out folder: take its networks, no training")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="a Hydra override of the networks' train config (repeatable), e.g. model.style_weight=5")
    parser.add_argument("--threads", type=int, default=None, help="torch threads")
    parser.add_argument("--force", action="store_true", help="replace an existing --out")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    try:
        results = leave_one_style_out(args.run, args.out, args.styles, args.primitives, args.epochs, args.samples,
                                      args.seed, args.checkpoints, args.overrides, args.threads, args.force)
    except (OutputExistsError, ValueError, FileNotFoundError) as err:
        print(f"zero_shot_loso: {err}", file=sys.stderr)
        return 2
    summary = results["summary"]
    print(f"recognition of the left-out style: zero-shot {summary['zero_shot']['mean_recognition']:.1%}, per-style "
          f"CVAE {summary['cvae']['mean_recognition']:.1%}, real clips {summary['real']['mean_recognition']:.1%}; "
          "own example the nearest Table 5.1 column: " + ", ".join(
              f"{kind} {summary[kind]['own_column_is_minimum']}/{summary[kind]['rows']}" for kind in summary))
    print(f"written: {args.out}/zero_shot.json, {args.out}/zero_shot.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
