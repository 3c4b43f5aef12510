"""``stylemotion-eval`` with a Morphable Graph model among the checkpoints (issue 30: it evaluates every model kind):
the row ``morphable`` (``morphable:<style>`` for another style) of its primitive's Tables 5.1–5.3 beside the run's
VAE/CVAEs, its Table 5.1 distances recomputed here from the model's own samples and the run's autoencoder; what
cannot be evaluated together is refused with an :class:`EvaluationInputError` (one line from the command)."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest
import torch
from recognition_reference import example_gram

from stylemotion.datamodules.clips import ClipDataModule
from stylemotion.datasets import build_dataset
from stylemotion.evaluation.reference import primitive_data
from stylemotion.evaluation.run import run_evaluation, settings_from_config
from stylemotion.evaluation.sources import EvaluationInputError
from stylemotion.evaluation.zero_shot import read_run
from stylemotion.models.checkpoints import load_autoencoder
from stylemotion.models.loading import load_model
from stylemotion.morphable import FitSettings, fit_primitive
from stylemotion.primitives.segmentation import time_normalize
from stylemotion.synthesis.graph import available_models

PRIMITIVE, SEED = "walk_leftStance", 3
EVAL = {"samples": {"table_5_1": 40, "variance": 60, "metrics": 40}, "classifier": {"components": 8},
        "shift_baseline": False}


@pytest.fixture(scope="module")
def run(tiny_run) -> Path:
    return tiny_run.folder


@pytest.fixture(scope="module")
def graph(run, tmp_path_factory) -> Path:
    """A Morphable Graph model of the run's normal walk_leftStance train clips, in a run folder of its own."""
    source = read_run(run)
    takeset = build_dataset(source.data_cfg)
    dm = ClipDataModule(takeset=takeset, primitives=["leftStance"], styles=["normal"], split=source.data_cfg["split"])
    dm.setup()
    model = fit_primitive(dm.clips["train"], FitSettings(latent_dim=6, reduction="fpca", num_coefficients=6),
                          meta={"data": takeset.name, "seed": 0})
    folder = tmp_path_factory.mktemp("morphable")
    model.save(folder / "model.npz")
    return folder


def checkpoints(run: Path) -> dict[str, str]:
    return {e["name"]: e["path"] for e in available_models(run) if e["primitive"] == PRIMITIVE}


def evaluate(run: Path, out: Path, paths) -> dict:
    return run_evaluation(read_run(run).data_cfg, [str(p) for p in paths], EVAL, out, seed=SEED)


@pytest.mark.slow  # one evaluation of three models and the graph on the shared tiny run
def test_a_morphable_graph_is_a_row_of_its_primitive_as_computed_by_hand(run, graph, tmp_path):
    models = checkpoints(run)
    results = evaluate(run, tmp_path / "report", [models["neutral"], models["elderly"], graph])
    assert results["extra_rows"][PRIMITIVE] == ["morphable"]
    records = {c["name"]: c for c in results["meta"]["checkpoints"]}
    assert records["morphable"]["kind"] == "morphable" and records["morphable"]["style"] == "normal"
    assert Path(records["morphable"]["path"]).name == "model.npz"
    table = results["table_5_1"][PRIMITIVE]
    assert table["models"] == ["neutral", "elderly"]  # a row, not a column: it has no example
    assert "morphable" in results["variance"][PRIMITIVE]
    assert "morphable" not in results["style_recognition"]["per_model"]
    text = (tmp_path / "report" / "report.md").read_text()
    assert "*morphable* (Morphable Graph)" in text

    # by hand: the graph's samples (one draw of 60, seed SEED, the first 40) on the CVAE's timeline, encoded by the
    # run's autoencoder, Gram over time, distance to each column's target Gram
    from stylemotion.morphable import MorphableModel

    source, settings = read_run(run), settings_from_config(EVAL, SEED)
    judge = load_autoencoder(source.autoencoder_ckpt)
    cvae = load_model(models["elderly"], settings.neutral_style, judge)
    length = cvae.timeline_frames
    drawn = MorphableModel.load(graph / "model.npz").sample(60, seed=SEED).normalized_frames[:40].numpy()
    frames = np.stack([time_normalize(f, length) for f in drawn]) if drawn.shape[1] != length else drawn
    with torch.no_grad():
        features = judge.encode(torch.from_numpy(frames).float())
    grams = features @ features.transpose(-1, -2) / features.shape[-1]
    data = primitive_data(build_dataset(source.data_cfg), PRIMITIVE, length, settings.neutral_style,
                          asdict(settings.segment), source.data_cfg.get("split"))
    own = float(torch.linalg.matrix_norm(grams - example_gram(judge, data, cvae)).mean())
    assert table["extra_rows"]["morphable"][table["models"].index("elderly")] == pytest.approx(own, rel=1e-4)
    # and its pose_SD is the spread of those samples, not the VAE's
    assert results["variance"][PRIMITIVE]["morphable"] != results["variance"][PRIMITIVE]["neutral"]


@pytest.mark.slow  # the graph fitted above; each refusal before any sample is drawn
def test_what_cannot_be_evaluated_with_a_graph_is_refused(run, graph, tmp_path):
    models = checkpoints(run)
    with pytest.raises(EvaluationInputError, match="Morphable Graph models only"):
        evaluate(run, tmp_path / "a", [graph])
    from stylemotion.morphable import MorphableModel

    model = MorphableModel.load(graph / "model.npz")
    model.meta["data"] = "bandai"
    model.save(tmp_path / "bandai.npz")
    with pytest.raises(EvaluationInputError, match="fitted on data set 'bandai'"):
        evaluate(run, tmp_path / "b", [models["neutral"], tmp_path / "bandai.npz"])
    model.meta.update(data=None, primitive="rightStance")
    model.save(tmp_path / "right.npz")
    with pytest.raises(EvaluationInputError, match="walk_rightStance.*no VAE/CVAE of that primitive"):
        evaluate(run, tmp_path / "c", [models["neutral"], tmp_path / "right.npz"])
    model.meta.update(primitive="leftStance")
    model.save(tmp_path / "again.npz")
    with pytest.raises(EvaluationInputError, match="two Morphable Graph models of walk_leftStance and style normal"):
        evaluate(run, tmp_path / "d", [models["neutral"], graph, tmp_path / "again.npz"])
    assert not any((tmp_path / n).exists() for n in "abcd")
