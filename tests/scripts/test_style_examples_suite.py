"""Suite ``style_examples`` (scripts/suites/style_examples.py): the k examples are nested seeded draws from the given
clips; spreads over seeds, own-column counts and the k = 4 aims computed from planted per-style curves (no
network, no judge); suite zero_shot's trainings are read per seed, a leaky one or a judge of other data refused;
the blocks are labelled."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_examples  # noqa: E402

import stylemotion.evaluation.zero_shot as library  # noqa: E402

STYLES = ("feminine", "youthful")
#: Planted recognition per seed, style and k; V_SD / real grows with k (the held-out real V_SD is 2.0).
SHARES = {0: {"feminine": [0.5, 0.7, 0.95, 0.9], "youthful": [0.2, 0.4, 0.92, 1.0]},
          1: {"feminine": [0.6, 0.8, 0.91, 0.9], "youthful": [0.1, 0.5, 0.6, 0.8]},
          2: {"feminine": [0.4, 0.9, 0.99, 1.0], "youthful": [0.3, 0.3, 0.95, 0.9]}}
V_SD = {1: 0.8, 2: 1.2, 4: 1.7, 8: 1.9}


def clips(n: int) -> list[SimpleNamespace]:
    return [SimpleNamespace(take=f"t{i % 3}", start=10 * i) for i in range(n)]


def test_the_examples_are_nested_seeded_draws_of_the_given_clips() -> None:
    pool = clips(10)
    draws = style_examples.draw_examples(pool, [1, 2, 4, 8, 16], 0, "walk_leftStance", "feminine")
    assert sorted(draws) == [1, 2, 4, 8]  # 16 > the 10 clips: left out
    assert all(draws[k] == draws[8][:k] for k in (1, 2, 4))
    assert len({(c.take, c.start) for c in draws[8]}) == 8 and all(c in pool for c in draws[8])
    again = style_examples.draw_examples(list(reversed(pool)), [8], 0, "walk_leftStance", "feminine")
    assert again[8] == draws[8]  # the clips' order does not matter, the seed does
    others = [style_examples.draw_examples(pool, [8], seed, "walk_leftStance", style)[8]
              for seed, style in ((1, "feminine"), (0, "youthful"))]
    assert all(o != draws[8] for o in others)


def curve(seed: int, style: str, ks: list[int], poolings: tuple[str, ...] = ("mean",)) -> dict:
    real = {"pose_sd": 4.0, "v_sd": 2.0, "step_sd": 10.0, "pose_across_sd": 3.0, "diversity": 5.0}
    out = {"train_clips": 9, "heldout_clips": 4, "real": real, "ks": {}}
    for label in style_examples.row_labels(ks, list(poolings)):
        k = int(label.split()[0])
        i = list(V_SD).index(k)
        spread_out = 1.5 if label.endswith("per_sample") else 1.0  # one clip per sample: more variation
        figures = {"pose_sd": 4.0, "v_sd": V_SD[k] * spread_out, "step_sd": 10.0 * V_SD[k] / 2.0, "pose_across_sd": 1.5,
                   "diversity": 5.0 * (0.6 if style == "youthful" else 0.8)}
        out["ks"][label] = {"recognition": SHARES[seed][style][i], "own_column_is_minimum": k >= 4 or seed == 0,
                             "nearest_column": style, "table_5_1_row": {}, **figures,
                             "vs_real": {m: figures[m] / real[m] for m in figures}, "examples": []}
    return out


@pytest.fixture
def planted(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> dict:
    calls: dict = {"curves": [], "networks": []}
    loso = tmp_path / "loso"
    for seed in (0, 1, 2):
        styles = {s: {"zero_shot": {"checkpoint": f"/nets/seed{seed}/{s}.ckpt"},
                      "generator_autoencoder": {"fingerprint": f"ae{seed}{s}"}} for s in STYLES}
        (loso / f"seed{seed}").mkdir(parents=True)
        (loso / f"seed{seed}" / "zero_shot.json").write_text(json.dumps(
            {"primitives": {"walk_leftStance": {"styles": styles}}, "meta": {"run": str(tmp_path / "judge"),
                                                                              "leaky": False}}))

    class FakeJudge:
        def __init__(self, folder, report="report"):
            calls.setdefault("judges", []).append(folder)
            calls.setdefault("reports", []).append(report)
            self.source = SimpleNamespace(data_cfg={"name": "synthetic"},
                                          settings=SimpleNamespace(neutral_style="normal"))
            styles = calls.get("data_styles", ["normal", *STYLES])  # the data's styles: those left out + neutral
            self.takeset = SimpleNamespace(label_values=lambda key: list(styles) if key == "style" else [])

    def fake_curve(judge, network, primitive, style, ks, samples, seed, poolings=("mean",)):
        calls["curves"].append((seed, style, tuple(ks), samples, poolings))
        return curve(seed, style, ks, poolings)

    monkeypatch.setattr(style_examples, "Judge", FakeJudge)
    monkeypatch.setattr(style_examples, "style_curve", fake_curve)
    monkeypatch.setattr(library, "load_left_out",
                        lambda path, p, s, fp: calls["networks"].append((str(path), p, s, fp)) or object())
    calls["loso"] = loso
    return calls


def args(loso: Path, **changes) -> argparse.Namespace:
    values = {"loso": loso, "data": "synthetic", "ks": [8, 1, 2, 4], "samples": 50, "styles": None, "primitives": None,
              "pooling": ["mean"]}
    return argparse.Namespace(**{**values, **changes})


def test_spreads_counts_and_aims_are_over_seeds(planted) -> None:
    results = style_examples.run(args(planted["loso"]), [0, 1, 2])
    assert planted["judges"] == [str(planted["loso"].parent / "judge")]  # one judge, built once
    assert planted["reports"] == ["report"]  # records without meta.report: the run's own report
    assert [c[:2] for c in planted["curves"]] == [(s, st) for s in (0, 1, 2) for st in STYLES]
    assert all(c[2] == (1, 2, 4, 8) and c[3] == 50 for c in planted["curves"])
    assert planted["networks"][1] == ("/nets/seed0/youthful.ckpt", "walk_leftStance", "youthful", "ae0youthful")
    four = results["headline"]["4"]
    means = [(SHARES[s]["feminine"][2] + SHARES[s]["youthful"][2]) / 2 for s in (0, 1, 2)]
    assert four["recognition"]["mean"] == pytest.approx(sum(means) / 3)
    assert four["v_sd"]["mean"] == pytest.approx(1.7 / 2.0) and four["diversity"]["mean"] == pytest.approx(0.7)
    # aims at k = 4: V_SD 85 %, step_SD 85 % for all; diversity 80 % (feminine) / 60 % (youthful); recognition ≥ 90 %
    assert [four["aims_met"]["min"], four["aims_met"]["max"]] == [1, 1]
    one = results["headline"]["1"]
    assert one["own_column_is_minimum"]["mean"] == pytest.approx(2 / 3) and one["aims_met"]["max"] == 0
    youthful = results["per_style"]["walk_leftStance"]["youthful"]["ks"]["8"]
    assert youthful["recognition"]["mean"] == pytest.approx(0.9) and youthful["own_column_is_minimum"] == 3
    assert youthful["vs_real"]["v_sd"]["mean"] == pytest.approx(0.95)
    assert results["ks"] == [1, 2, 4, 8] and "train-split" in results["splits"]["examples"]
    record = {"results": results, "seeds": [0, 1, 2], "command": "c", "commit": "x", "started": "2026-01-01",
              "machine": {}, "seconds": 0}
    blocks = style_examples.render(record)
    assert set(blocks) == {"headline", "per_style", "real"}
    assert "Synthetic data" in blocks["headline"] and "| 4 | 0.887 ± 0." in blocks["headline"]
    assert "Narrowed" not in blocks["headline"]  # every style of the data was left out
    assert "| walk_leftStance | youthful | 8 | 0.900 ± 0.100 | 3/3 | 0.95 ± 0.00 |" in blocks["per_style"]


def test_narrowing_a_leaky_training_and_other_data(planted) -> None:
    results = style_examples.run(args(planted["loso"], styles=["youthful"], ks=[2]), [1])
    assert results["left_out"] == ["walk_leftStance/youthful"] and list(results["headline"]) == ["2"]
    record = {"results": results, "seeds": [1], "command": "c", "commit": "x", "started": "2026-01-01",
              "machine": {}, "seconds": 0}
    assert "**Narrowed to fit the machine**" in style_examples.render(record)["headline"]
    # narrowed upstream: suite zero_shot left out fewer styles than the judge's data has
    planted["data_styles"] = ["normal", *STYLES, "angry"]
    results = style_examples.run(args(planted["loso"], ks=[2]), [1])
    record = {**record, "results": results}
    assert results["subsample"]["styles"] == sorted(STYLES)
    assert "**Narrowed to fit the machine**" in style_examples.render(record)["headline"]
    with pytest.raises(library.ZeroShotRunError, match="holds 'synthetic' data, not --data bandai"):
        style_examples.run(args(planted["loso"], data="bandai"), [0])
    leaky = planted["loso"] / "seed0" / "zero_shot.json"
    record = json.loads(leaky.read_text())
    record["meta"]["leaky"] = "shared autoencoder"
    leaky.write_text(json.dumps(record))
    with pytest.raises(library.ZeroShotRunError, match="leaky protocol"):
        style_examples.run(args(planted["loso"]), [0])
    with pytest.raises(Exception, match="seed7"):
        style_examples.run(args(planted["loso"]), [7])


def test_per_sample_pooling_is_a_row_of_its_own_for_k_of_two_and_more(planted) -> None:
    assert style_examples.row_labels([1, 2, 4], ["per_sample", "mean"]) == ["1", "2", "2 per_sample", "4",
                                                                           "4 per_sample"]
    results = style_examples.run(args(planted["loso"], pooling=["per_sample", "mean"], ks=[1, 4]), [0, 1])
    assert all(c[4] == ("mean", "per_sample") for c in planted["curves"])
    assert results["rows"] == ["1", "4", "4 per_sample"] and results["poolings"] == ["mean", "per_sample"]
    assert results["headline"]["4 per_sample"]["v_sd"]["mean"] == pytest.approx(1.5 * 1.7 / 2.0)
    assert results["headline"]["4"]["v_sd"]["mean"] == pytest.approx(1.7 / 2.0)
    record = {"results": results, "seeds": [0, 1], "command": "c", "commit": "x", "started": "2026-01-01",
              "machine": {}, "seconds": 0}
    assert "| 4 per_sample | " in style_examples.render(record)["headline"]
