"""Suite ``zero_shot`` (scripts/suites/zero_shot.py): spreads over seeds and own-column counts computed from planted
per-seed results of the leave-one-style-out evaluation (no training), each seed's evaluation run with its own seed
and ``resume``, the judge's data checked, and the blocks labelled (synthetic, narrowed)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import zero_shot  # noqa: E402

import stylemotion.evaluation.zero_shot as library  # noqa: E402

#: Planted recognition of the zero-shot rows per seed and style, and whether their own column is the minimum.
SHARES = {0: {"feminine": 0.2, "youthful": 0.6}, 1: {"feminine": 0.4, "youthful": 0.9}, 2: {"feminine": 0.9,
                                                                                             "youthful": 0.3}}
OWN = {0: {"feminine": True, "youthful": False}, 1: {"feminine": True, "youthful": True},
       2: {"feminine": False, "youthful": False}}


def planted(seed: int) -> dict:
    def row(share: float, own: bool, sd: float) -> dict:
        return {"recognition": share, "own_column_is_minimum": own, "nearest_column": "x", "pose_across_sd": sd,
                "table_5_1_row": {}}

    styles = {s: {"zero_shot": {**row(SHARES[seed][s], OWN[seed][s], 1.0), "train_seconds": 60.0},
                  "cvae": row(1.0, True, 0.5), "real": row(0.8, True, 2.0), "reconstructed": row(0.5, False, 1.5),
                  "generator_autoencoder": {"train_seconds": 120.0}} for s in ("feminine", "youthful")}
    primitives = {"walk_leftStance": {"styles": styles, "classifier": {"heldout_accuracy": 0.9, "chance": 0.25}}}
    summary = {kind: {"mean_recognition": sum(st[kind]["recognition"] for st in styles.values()) / 2,
                      "own_column_is_minimum": sum(st[kind]["own_column_is_minimum"] for st in styles.values()),
                      "rows": 2} for kind in ("zero_shot", "cvae", "real", "reconstructed")}
    return {"primitives": primitives, "summary": summary, "meta": {"seconds": 1.0},
            "splits": {"data": {"kind": "by take", "seed": 0, "val_fraction": 0.1, "test_fraction": 0.1}}}


@pytest.fixture
def suite(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> list[dict]:
    calls: list[dict] = []
    source = SimpleNamespace(seed=0, data_cfg={"name": "synthetic"}, autoencoder_ckpt=tmp_path / "judge" / "ae.ckpt",
                             primitives=["walk_leftStance"], styles=lambda p: ["feminine", "masculine", "youthful"])

    def fake(run, out, styles, primitives, epochs, samples, seed, **kwargs):
        calls.append({"out": Path(out), "seed": seed, "styles": styles, "epochs": epochs, **kwargs})
        Path(out).mkdir(parents=True, exist_ok=True)
        result = planted(seed)
        if kwargs.get("shared_autoencoder"):  # the leaky protocol: every network recognized
            for row in result["primitives"]["walk_leftStance"]["styles"].values():
                row["zero_shot"]["recognition"] = 1.0
            result["summary"]["zero_shot"]["mean_recognition"] = 1.0
        (Path(out) / "zero_shot.json").write_text(json.dumps(result))
        return result

    monkeypatch.setattr(library, "leave_one_style_out", fake)
    monkeypatch.setattr(library, "read_run", lambda folder: source)
    return calls


def args(tmp_path: Path, **changes) -> argparse.Namespace:
    values = {"data": "synthetic", "run": tmp_path / "judge", "judge_seed": 0, "runs": tmp_path / "runs",
              "styles": ["feminine", "youthful"], "primitives": ["walk_leftStance"], "epochs": 30, "samples": 100,
              "workers": 1, "leaky": False}
    return argparse.Namespace(**{**values, **changes})


def test_spreads_and_counts_are_over_seeds(suite, tmp_path: Path) -> None:
    results = zero_shot.run(args(tmp_path), [0, 1, 2])
    assert [c["seed"] for c in suite] == [0, 1, 2] and all(c["resume"] and c["epochs"] == 30 for c in suite)
    assert not any(c.get("shared_autoencoder") for c in suite) and results["kinds"] == [
        "zero_shot", "cvae", "real", "reconstructed"]
    assert len({c["out"].parent for c in suite}) == 1 and suite[0]["out"].name == "seed0"
    feminine = results["per_style"]["walk_leftStance"]["feminine"]["zero_shot"]
    assert feminine["recognition"]["mean"] == pytest.approx(0.5) and feminine["recognition"]["sd"] == pytest.approx(
        ((0.3 ** 2 + 0.1 ** 2 + 0.4 ** 2) / 2) ** 0.5)
    assert (feminine["recognition"]["min"], feminine["recognition"]["max"]) == (0.2, 0.9)
    assert feminine["own_column_is_minimum"] == 2 and feminine["spread_vs_real"]["mean"] == pytest.approx(0.5)
    head = results["headline"]["zero_shot"]
    means = [(SHARES[k]["feminine"] + SHARES[k]["youthful"]) / 2 for k in (0, 1, 2)]
    assert head["mean_recognition"]["mean"] == pytest.approx(sum(means) / 3)
    assert (head["own_column_is_minimum"]["min"], head["own_column_is_minimum"]["max"]) == (0, 2)
    assert results["splits"]["data"]["kind"] == "by take" and "judge run" in results["splits"]["seed_varies"]
    record = {"results": results, "seeds": [0, 1, 2], "command": "c", "commit": "x", "started": "2026-01-01",
              "machine": {}, "seconds": 0}
    blocks = zero_shot.render(record)
    assert set(blocks) == {"headline", "per_style", "per_seed"}
    assert "Synthetic data" in blocks["headline"] and "Narrowed" in blocks["headline"]
    assert "0.500 ± 0.361 (0.200–0.900)" in blocks["per_style"] and "| 2/3 |" in blocks["per_style"]


def test_a_judge_of_other_data_is_refused(suite, tmp_path: Path) -> None:
    with pytest.raises(library.ZeroShotRunError, match="holds 'synthetic' data, not --data bandai"):
        zero_shot.run(args(tmp_path, data="bandai"), [0])


def test_the_leaky_protocol_is_a_labelled_row_of_its_own_folder(suite, tmp_path: Path) -> None:
    results = zero_shot.run(args(tmp_path, leaky=True), [0, 1])
    leaky = [c for c in suite if c.get("shared_autoencoder")]
    assert [c["seed"] for c in leaky] == [0, 1] and leaky[0]["out"].name == "seed0_leaky"
    row = results["per_style"]["walk_leftStance"]["feminine"]
    assert row["zero_shot_leaky"]["recognition"]["mean"] == 1.0
    assert row["zero_shot"]["recognition"]["mean"] == pytest.approx(0.3)
    assert results["headline"]["zero_shot_leaky"]["mean_recognition"]["mean"] == 1.0
    record = {"results": results, "seeds": [0, 1], "command": "c", "commit": "x", "started": "2026-01-01",
              "machine": {}, "seconds": 0}
    assert "LEAKY: zero-shot network on the judge's autoencoder" in zero_shot.render(record)["headline"]
