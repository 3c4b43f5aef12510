"""Completion as style transfer on Bandai (Krüger §4.2): the legs of a normal test walk, the upper body completed
from a database of normal walks and from one of elderly walks; posture of the head and hands in the body frame
against the take and a real elderly test walk (JSON lines on stdout).

    python scripts/bench_style_transfer.py [--style elderly] [--data bandai]
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from stylemotion.datasets import TakeSet
from stylemotion.reconstruct.benchmark import benchmark_split
from stylemotion.reconstruct.texture import LEG_JOINTS, MotionTexturer
from stylemotion.search.database import MotionDatabase
from stylemotion.search.features import body_frame_positions
from stylemotion.skeleton import CANONICAL_JOINTS, JOINT_INDEX

UPPER = [JOINT_INDEX[j] for j in CANONICAL_JOINTS if j not in LEG_JOINTS]
HANDS = [JOINT_INDEX["Hand_L"], JOINT_INDEX["Hand_R"]]


def posture(positions: np.ndarray, fps: float) -> dict:
    """Mean head forward of the hips, head height and hand height in the body frame, cm."""
    body = body_frame_positions(positions, fps, "2d")
    head = JOINT_INDEX["Head"]
    return {"head_forward_cm": round(float(body[:, head, 2].mean() * 100), 2),
            "head_height_cm": round(float(body[:, head, 1].mean() * 100), 2),
            "hand_height_cm": round(float(body[:, HANDS, 1].mean() * 100), 2)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", choices=("bandai", "synthetic"), default="bandai")
    parser.add_argument("--style", default="elderly")
    parser.add_argument("--content", default="walk")
    parser.add_argument("--synthetic-takes", type=int, default=3, help="takes per content and style (synthetic)")
    args = parser.parse_args(argv)
    data, train, test = benchmark_split(args.data, synthetic_takes=args.synthetic_takes)
    def pick(style: str):  # a test take, else (small data sets) a train take, which then leaves the databases
        found = [t for t in test if t.content == args.content and t.style == style]
        found += [t for t in train if t.content == args.content and t.style == style]
        if not found:
            raise SystemExit(f"no {args.content} take of style {style} in {data.name}")
        return found[0]

    take, real = pick("normal"), pick(args.style)
    truth = np.asarray(take.positions, dtype=np.float64)
    legs = truth.copy()
    legs[:, UPPER] = np.nan
    rows = [{"kind": "real", "take": take.name, **posture(truth, data.fps)},
            {"kind": "real", "take": real.name, **posture(np.asarray(real.positions, np.float64), data.fps)}]
    for style in ("normal", args.style):
        takes = [t for t in train if t.content == args.content and t.style == style and t.name != take.name]
        database = MotionDatabase.from_takeset(TakeSet(data.name, takes, data.fps))
        done = MotionTexturer(database, "complete").apply(legs).positions
        rows.append({"kind": "completed", "take": take.name, "database": f"{args.content} {style}",
                     "db_takes": len(takes), **posture(done, data.fps),
                     "upper_cm_to_take": round(float(np.linalg.norm(done[:, UPPER] - truth[:, UPPER],
                                                                   axis=-1).mean() * 100), 3)})
    for row in rows:
        print(json.dumps(row), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
