"""The Morphable Graph's neutral models as extra rows of Tables 5.1–5.3 (``stylemotion-reproduce morphable=true``):
the evaluation's extra-row hook, the report, and fitting/reusing the models of a run's data."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import torch
from log_lines import logged_lines
from vae_fixtures import TINY_DATA, tiny_autoencoder_ckpt, tiny_takeset

from stylemotion.config import ConfigError
from stylemotion.evaluation.markdown import format_markdown
from stylemotion.evaluation.pipeline import evaluate_models
from stylemotion.evaluation.reference import primitive_data
from stylemotion.evaluation.settings import ClassifierSettings, EvalSettings, SampleCounts
from stylemotion.evaluation.sources import RealClipSource
from stylemotion.models.checkpoints import autoencoder_info, load_autoencoder
from stylemotion.models.loading import NEUTRAL, EvalModel
from stylemotion.models.sampling import MotionSamples
from stylemotion.morphable.rows import ROW, neutral_models
from stylemotion.training.reproduction import StageConflictError

torch.set_num_threads(1)
SETTINGS = EvalSettings(samples=SampleCounts(table_5_1=60, variance=120, metrics=60),
                        classifier=ClassifierSettings(components=6))
PRIMITIVE = "walk_leftStance"


@pytest.fixture(scope="module")
def evaluated(tmp_path_factory):
    """The neutral oracle model and, as an extra row, a second source drawing the same clips (so the row must
    equal the neutral one), plus a "short" source whose samples are on another timeline."""
    path = tiny_autoencoder_ckpt(tmp_path_factory.mktemp("rows_ae"))
    ae = load_autoencoder(path)
    info = autoencoder_info(ae, path)
    data = primitive_data(tiny_takeset(), PRIMITIVE, 16, split=TINY_DATA["split"])
    neutral = EvalModel(NEUTRAL, PRIMITIVE, "normal", RealClipSource(data.training_data(), 16), autoencoder=info,
                        timeline_frames=16, dataset="synthetic")
    extra = {PRIMITIVE: {ROW: RealClipSource(data.training_data(), 16),
                         "short": RealClipSource(data.training_data(), 12)}}
    results = evaluate_models([neutral], tiny_takeset(), ae, SETTINGS, split=TINY_DATA["split"],
                              autoencoder_info=info, extra_rows=extra)
    return ae, info, neutral, results


def test_an_extra_row_drawing_the_neutral_clips_equals_the_neutral_row(evaluated) -> None:
    _, _, _, results = evaluated
    assert results["extra_rows"] == {PRIMITIVE: [ROW, "short"]}
    table = results["table_5_1"][PRIMITIVE]
    assert table["models"] == [NEUTRAL]  # no column, no diagonal entry
    assert table["extra_rows"][ROW] == pytest.approx(table["distance"][0], rel=1e-6)
    assert results["variance"][PRIMITIVE][ROW] == results["variance"][PRIMITIVE][NEUTRAL]
    assert results["variance_ratio"][PRIMITIVE][ROW] == results["variance_ratio"][PRIMITIVE][NEUTRAL]
    # samples on a 12-frame timeline are resampled to the evaluation's 16 before encoding: close, not equal
    assert table["extra_rows"]["short"][0] == pytest.approx(table["distance"][0][0], rel=0.2)
    assert ROW not in results["frechet"][PRIMITIVE] and ROW not in results["style_recognition"]["per_model"]


def test_the_report_shows_extra_rows_and_keeps_them_out_of_the_style_ranges(evaluated) -> None:
    _, _, _, results = evaluated
    text = format_markdown({**results, "meta": {"data_name": "synthetic", "seed": 0, "samples": {},
                                                "checkpoints": [], "autoencoder": {}, "seconds": 1.0}}, [], [])
    assert f"*{ROW}* (Morphable Graph)" in text
    assert "style models pose_sd / training data" not in text  # the only non-neutral rows are extra rows
    assert f"| {ROW} |" in text  # its Tables 5.2/5.3 row


def test_extra_rows_need_a_model_of_their_primitive_and_a_free_name(evaluated) -> None:
    ae, info, neutral, _ = evaluated
    source = neutral.source
    for extra, message in (({PRIMITIVE: {NEUTRAL: source}}, "taken"), ({PRIMITIVE: {"training_data": source}}, "taken"),
                           ({"walk_rightStance": {ROW: source}}, "no VAE/CVAE of that primitive")):
        with pytest.raises(ValueError, match=message):
            evaluate_models([neutral], tiny_takeset(), ae, SETTINGS, split=TINY_DATA["split"], autoencoder_info=info,
                            extra_rows=extra)


def test_neutral_models_are_fitted_on_the_run_data_and_reused(tmp_path: Path) -> None:
    data = {**TINY_DATA}
    with logged_lines("stylemotion.morphable.rows") as lines:
        models = neutral_models(data, [PRIMITIVE], "normal", tmp_path, seed=0)
    model = models[PRIMITIVE]
    assert (tmp_path / PRIMITIVE / "model.npz").is_file() and "fitted on" in lines[-1]
    samples = model.sample(20, seed=0)
    assert isinstance(samples, MotionSamples) and samples.normalized_frames.shape[1] == model.length
    with logged_lines("stylemotion.morphable.rows") as lines:
        again = neutral_models(data, [PRIMITIVE], "normal", tmp_path, seed=0)[PRIMITIVE]
    assert "reused" in lines[-1]
    np.testing.assert_allclose(again.sample(5, seed=1).positions, model.sample(5, seed=1).positions, atol=1e-5)
    with pytest.raises(ConfigError, match="other data or settings"):
        neutral_models({**data, "takes_per_pair": 5}, [PRIMITIVE], "normal", tmp_path, seed=0)


@pytest.mark.slow
def test_reproduce_with_morphable_adds_its_rows_to_the_report(tiny_run, tmp_path: Path) -> None:
    """On the shared tiny run's autoencoder and walk_leftStance VAE (a copy of those finished stages, reused)."""
    from reproduce_fixtures import copy_run, reproduce, tiny_overrides

    out = copy_run(tiny_run, tmp_path / "run", ("autoencoder", f"vae/{PRIMITIVE}"))
    narrow = tiny_overrides(out) + [f"primitives=[{PRIMITIVE}]", "styles=[]"]
    lines: list[str] = []
    summary = reproduce(narrow + ["morphable=true"], lines)
    assert [s["kind"] for s in summary["stages"]] == ["autoencoder", "vae"]
    assert [s["status"] for s in summary["stages"]] == ["reused", "reused"]
    assert (out / "morphable" / PRIMITIVE / "model.npz").is_file()
    report = (out / "report" / "report.md").read_text()
    assert f"*{ROW}* (Morphable Graph)" in report and f"| {ROW} |" in report
    results = json.loads((out / "report" / "report.json").read_text())
    assert results["extra_rows"] == {PRIMITIVE: [ROW]}
    ratio = results["variance_ratio"][PRIMITIVE][ROW]
    assert 0.5 < ratio["pose_sd"] < 1.5, ratio  # a model of the neutral clips varies about as much as they do
    # a rerun reuses the report and the models; without the switch the report is of other settings
    reproduce(narrow + ["morphable=true"], lines)
    assert any("evaluation: reused" in line for line in lines)
    with pytest.raises(StageConflictError, match="other models or settings"):
        reproduce(narrow, [])
