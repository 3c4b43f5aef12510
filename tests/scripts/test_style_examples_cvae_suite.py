"""Suite ``style_examples_cvae`` (scripts/suites/style_examples_cvae.py) on the tiny finished reproduction: each CVAE
is trained on exactly the clips suite ``style_examples`` draws (nested, train split) and records them; a second run
reuses the trainings and gives the same figures; a run of other data is refused; the block is labelled."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

from suites import style_examples, style_examples_cvae  # noqa: E402


def args(runs: Path, out: Path, **changes) -> argparse.Namespace:
    values = {"runs": runs, "train_dir": out, "data": "synthetic", "ks": [2, 1], "samples": 40, "styles": ["elderly"],
              "primitives": ["walk_leftStance"], "workers": 1}
    return argparse.Namespace(**{**values, **changes})


@pytest.fixture(scope="module")
def curve(tiny_run, tmp_path_factory) -> dict:
    base = tmp_path_factory.mktemp("style_examples_cvae")
    (base / "runs").mkdir()
    (base / "runs" / "seed0").symlink_to(tiny_run.folder, target_is_directory=True)
    first = style_examples_cvae.run(args(base / "runs", base / "out"), [0])
    again = style_examples_cvae.run(args(base / "runs", base / "out"), [0])
    return {"base": base, "first": first, "again": again}


def test_each_cvae_is_trained_on_the_drawn_train_clips(curve) -> None:
    from suites.style_examples import Judge

    from stylemotion.models.loading import load_generative

    judge = Judge(curve["base"] / "runs" / "seed0")
    train = judge.side("walk_leftStance")[0].data.split("train", "elderly")
    draws = style_examples.draw_examples(train, [1, 2], 0, "walk_leftStance", "elderly")
    assert len(draws[2]) == 2 and draws[2][:1] == draws[1]
    for k in (1, 2):
        folder = curve["base"] / "out" / "seed0" / f"walk_leftStance_elderly_k{k}"
        model = load_generative(folder / "checkpoints" / "best.ckpt")
        used = [(e["take"], e["start"]) for e in model.style_examples]
        assert used == [(c.take, c.start) for c in draws[k]]
        point = curve["first"]["per_style"]["walk_leftStance"]["elderly"]["ks"][str(k)]
        assert point["recognition"]["n"] == 1
    assert curve["first"]["ks"] == [1, 2] and "train split" in curve["first"]["splits"]["examples"]


def test_a_second_run_reuses_the_trainings_and_gives_the_same_figures(curve) -> None:
    assert curve["again"]["headline"] == curve["first"]["headline"]
    assert curve["again"]["per_style"] == curve["first"]["per_style"]


def test_the_block_names_the_model_and_its_narrowing(curve) -> None:
    record = {"results": curve["first"], "seeds": [0], "command": "c", "commit": "x", "started": "2026-01-01",
              "machine": {}, "seconds": 0}
    blocks = style_examples_cvae.render(record)
    assert blocks["headline"].startswith("**Synthetic data")
    assert "Style CVAE trained on k examples of its style" in blocks["headline"]
    assert "styles walk_leftStance/elderly" in blocks["headline"] and "left-out" not in blocks["headline"]
    assert blocks["reading"].startswith("From k = 1 to k = 2 the means over styles move V_SD ")
    assert "Rows whose minimum is the style's own column, mean over seeds per k: " in blocks["reading"]


def test_a_run_of_other_data_is_refused(curve) -> None:
    from stylemotion.evaluation.zero_shot import ZeroShotRunError

    with pytest.raises(ZeroShotRunError, match="not --data bandai"):
        style_examples_cvae.run(args(curve["base"] / "runs", curve["base"] / "out2", data="bandai"), [0])
