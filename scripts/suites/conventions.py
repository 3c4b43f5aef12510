"""Suite ``conventions``: forward kinematics against an independent implementation (bvhio), the BVH writer's round
trip, and the representation's round trip (positions → frames → positions), on the three other-skeleton walks
and three Bandai takes (the longest walk among them). Deterministic: nothing is tuned or random.
"""

from __future__ import annotations

import argparse
import re
import tempfile
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, md_table, provenance_line

DESCRIPTION = "FK vs bvhio, BVH write → read and representation round trips on six real files of four conventions"
DEFAULT_SEEDS = (0,)
OTHER = {"walk_21joint_60fps.bvh": "cmu21", "female-walk_21joint_60fps.bvh": "cmu21",
         "xia_neutral_01_000_31joint_120fps.bvh": "cmu31"}
BANDAI = ("dataset-2_walk_normal_001.bvh", "dataset-2_run_feminine_021.bvh")


def _bvhio_positions(path: Path, frames: list[int]) -> np.ndarray:
    import bvhio

    root = bvhio.readAsHierarchy(str(path))
    layout = [joint for joint, _, _ in root.layout()]
    out = []
    for f in frames:
        root.loadPose(int(f), recursive=True)
        out.append([list(joint.PositionWorld) for joint in layout])
    return np.array(out, dtype=np.float64)


def measure(path: Path, label: str, joint_map: str) -> dict[str, Any]:
    """FK gap to bvhio (file units, 8 frames), BVH write → read FK error (file units), the representation's round
    trip error (m), head height range and lowest foot (m) of one file."""
    from stylemotion.datasets.canonical import to_canonical_positions
    from stylemotion.io.bvh import format_bvh, parse_bvh, read_bvh
    from stylemotion.representation import frames_to_positions, positions_to_frames
    from stylemotion.skeleton import FOOT_POINTS, JOINT_INDEX

    motion = read_bvh(path)
    n = motion.num_frames
    frames = sorted({0, 1, n // 3, n // 2, n - 1, *np.random.default_rng(0).integers(0, n, 3).tolist()})
    fk = motion.global_positions()
    gap = float(np.abs(fk[frames] - _bvhio_positions(path, frames)).max())
    again = parse_bvh(format_bvh(motion), "written")
    written = float(np.abs(again.global_positions() - fk).max())
    positions = to_canonical_positions(motion, joint_map)
    rep, start_xz, start_yaw = positions_to_frames(positions, 30.0)
    back = frames_to_positions(rep, 30.0, start_xz, start_yaw)
    head = positions[:, JOINT_INDEX["Head"], 1]
    return {"file": label, "joint_map": joint_map, "file_frames": n, "file_fps": round(float(motion.fps), 3),
            "frames_30fps": int(positions.shape[0]), "fk_gap_vs_bvhio": gap, "bvh_round_trip": written,
            "representation_round_trip_m": float(np.abs(back - positions).max()),
            "head_height_m": [float(head.min()), float(head.max())],
            "lowest_foot_m": float(positions[:, FOOT_POINTS.ravel(), 1].min())}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    rows = [measure(DATA_ROOT / "other-skeletons" / name, name.removesuffix(".bvh"), jm) for name, jm in OTHER.items()]
    archive = DATA_ROOT / "bandai-namco-motion-2" / "data.zip"
    with zipfile.ZipFile(archive) as zf, tempfile.TemporaryDirectory() as tmp:
        walks = {i.filename: i.file_size for i in zf.infolist()
                 if re.fullmatch(r"dataset-2_walk_[a-z]+_\d+\.bvh", i.filename)}
        longest = max(walks, key=walks.get)  # the largest walk file: the longest walk
        for member in (*BANDAI, longest):
            path = Path(tmp) / member
            path.write_bytes(zf.read(member))  # bvhio reads paths only
            rows.append(measure(path, "Bandai " + member.removeprefix("dataset-2_").removesuffix(".bvh")
                                + (" (longest walk)" if member == longest else ""), "bandai"))
    return {"splits": {"kind": "none: six named files"}, "files": rows}


def render(record: dict[str, Any]) -> dict[str, str]:
    rows = [[r["file"], r["joint_map"], f"{r['file_frames']:,} @ {r['file_fps']:g} → {r['frames_30fps']:,}",
             f"{r['fk_gap_vs_bvhio']:.1e}", f"{r['bvh_round_trip']:.1e}", f"{r['representation_round_trip_m']:.1e} m",
             f"{r['head_height_m'][0]:.3f}–{r['head_height_m'][1]:.3f}", f"{r['lowest_foot_m']:.3f}"]
            for r in record["results"]["files"]]
    table = md_table(["file", "joint map", "frames → at 30 fps", "worst FK gap vs bvhio (file units, 8 frames)",
                      "BVH write → read FK error (file units)", "positions → frames → positions", "head height (m)",
                      "lowest foot (m)"], rows)
    note = ("bvhio computes in float32, so its gap grows with the distance from the origin (Bandai takes sit metres "
            "away); our writer keeps 6 decimals.")
    return {"headline": f"{table}\n\n{note} {provenance_line(record)}"}
