"""Suite ``zero_shot_actors`` (scripts/suites/zero_shot_actors.py): actor groups read from the BVH files' rest poses
(not typed in), the neutral style's actor left out style by style and labelled, and the block (hand-made rows and a
hand-made zip, no training)."""

from __future__ import annotations

import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_method, zero_shot_actors, zero_shot_test  # noqa: E402


def bvh(hips: tuple[float, float, float]) -> str:
    """A two-joint BVH whose Hips rest offset (from the root) is ``hips``."""
    x, y, z = hips
    return ("HIERARCHY\nROOT joint_Root\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation "
            f"Xrotation Yrotation\n  JOINT Hips\n  {{\n    OFFSET {x:g} {y:g} {z:g}\n    CHANNELS 3 Zrotation "
            "Xrotation Yrotation\n    End Site\n    {\n      OFFSET 0 10 0\n    }\n  }\n}\nMOTION\nFrames: 1\n"
            "Frame Time: 0.0333333\n0 0 0 0 0 0 0 0 0\n")


def archive(folder: Path, takes: dict[str, tuple[float, float, float]]) -> dict:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "data.zip"
    with zipfile.ZipFile(path, "w") as z:
        for name, hips in takes.items():
            z.writestr(f"{name}.bvh", bvh(hips))
            z.writestr(f"{name}.json", "{}")
    return {"root": str(path)}


def test_actor_groups_are_the_styles_that_share_a_rest_pose(tmp_path) -> None:
    a, b, c = (4.6, 91.5, -427.2), (-17.2, 93.2, 453.0), (-0.7, 93.3, -2.0)
    data = archive(tmp_path, {"dataset-2_walk_active_001": a, "dataset-2_walk_active_002": a,
                              "dataset-2_walk_elderly_001": a, "dataset-2_walk_feminine_001": b,
                              "dataset-2_walk_normal_001": c, "dataset-2_walk_masculine_001": c,
                              "dataset-2_run_feminine_001": c})  # another content: not read
    groups = zero_shot_actors.actor_groups(data, ["active", "elderly", "feminine", "masculine", "normal"])
    assert groups == {"active": ["active", "elderly"], "elderly": ["active", "elderly"], "feminine": ["feminine"],
                      "masculine": ["masculine", "normal"], "normal": ["masculine", "normal"]}
    mixed = archive(tmp_path / "mixed", {"dataset-2_walk_active_001": a, "dataset-2_walk_active_002": b})
    with pytest.raises(SystemExit, match=r"styles without exactly one rest pose .*\{'active': 2\}"):
        zero_shot_actors.actor_groups(mixed, ["active"])
    with pytest.raises(SystemExit, match=r"\{'youthful': 0\}"):
        zero_shot_actors.actor_groups(data, ["youthful"])


REAL = {"variation": {"pose_sd": 2.0, "v_sd": 0.4, "step_sd": 4.0, "diversity": 1.0}, "foot_skating": {"ratio": 0.05}}


def row(recognition: float, skating: float) -> dict:
    return {"recognition": recognition, "own_column_is_minimum": True, "foot_skating": {"ratio": skating},
            "variation": {"pose_sd": 1.0, "v_sd": 0.3, "step_sd": 2.0, "diversity": 0.6}}


def test_the_block_names_each_styles_group_and_whether_its_actor_was_unseen() -> None:
    def case(recognition: float) -> dict:  # no CVAE on the autoencoder without the group (the default)
        return style_method.case_figures({"zero_shot": row(recognition, 0.1), "cvae": row(0.99, 0.2), "real": REAL})

    per_seed = {str(k): {"cases": {"walk_leftStance/active": case(0.7), "walk_leftStance/masculine": case(0.95)}}
                for k in (100, 101, 102)}
    actors = {"active": ["active", "elderly"], "elderly": ["active", "elderly"],
              "masculine": ["masculine", "normal"], "normal": ["masculine", "normal"]}
    results = {"data": "bandai", "epochs": 10, "samples": 100, "contact_weight": 0.0,
               "sampling": {"sample_temperature": 1.0, "sample_centred": True},
               "narrowed": {"primitives": None, "styles": None}, "actors": actors,
               "groups": {"active": ["active", "elderly"], "masculine": ["masculine"]},
               "cross_actor": {"active": True, "masculine": False},
               "judges": {str(k): f"j{k}" for k in (100, 101, 102)}, "per_seed": per_seed,
               "summary": style_method.method_summaries(per_seed), "aims": zero_shot_test.aims(per_seed)}
    assert set(results["summary"]) == {"zero_shot", "cvae"}  # no cvae_unseen row without it
    record = {"suite": "zero_shot_actors", "command": "c", "commit": "0" * 40, "started": "2026-12-07T06:00:00",
              "machine": {"cpu": "x", "cores": 2}, "seeds": [100, 101, 102], "seconds": 1.0, "results": results}
    headline = zero_shot_actors.render(record)["headline"]
    assert "A style **and its actor** never seen, judged on **test** clips only" in headline
    assert "active, elderly; masculine, normal" in headline
    assert "styles recognized ≥ 0.8: 1/2 (least: active)" in headline
    assert "| active | active, elderly | yes | 0.700 ± 0.000 (0.700–0.700) | 3/3 |" in headline
    assert "| masculine | masculine | **no**: its actor's other style is the neutral one |" in headline
