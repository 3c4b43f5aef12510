"""``stylemotion.load`` reads every kind of model the commands write (stylemotion/loading.py).

The outputs walked are the shared tiny ``stylemotion-reproduce`` run (conftest's ``tiny_run``: its stage folders are
``stylemotion-train`` run folders of an autoencoder, VAEs and CVAEs), the two ``stylemotion-style`` folders made
from it (``method=cvae`` and ``method=zero_shot``, tests/style_fixtures.py; the zero-shot one holds the trained
networks) and a Morphable Graph primitive trained here by ``stylemotion-train experiment=morphable_graph`` (~2 s).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import torch
from cli_runner import run_command
from style_fixtures import example_bvh, tiny_style, tiny_zero_shot_style

import stylemotion
from stylemotion.io.errors import UserInputError
from stylemotion.loading import Description, LoadError, Model, ModelSet, NotFoundError, load
from stylemotion.models.loading import load_generative
from stylemotion.models.sampling import MotionSamples
from stylemotion.morphable import MorphableModel

MORPHABLE = ["data.takes_per_pair=3", "data.duration_s=5.0", "model.latent_dim=5", "model.reduction=fpca",
             "model.num_coefficients=6", "model.tree.samples=300", "samples=false", "threads=1"]


@pytest.fixture
def morphable_run(tmp_path, capsys, monkeypatch) -> Path:
    """A ``stylemotion-train experiment=morphable_graph`` run folder of ``walk_leftStance``."""
    out = tmp_path / "walk_leftStance"
    done = run_command("train", "experiment=morphable_graph", "primitive=walk_leftStance", f"hydra.run.dir={out}",
                       *MORPHABLE, capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    return out


def check_samples(samples, n: int = 3) -> None:
    assert isinstance(samples, MotionSamples) and len(samples) == n
    assert samples.positions.shape[2:] == (21, 3) and torch.isfinite(samples.positions).all()


def test_a_reproduce_run_loads_as_a_set_of_every_style(tiny_run):
    run = load(tiny_run.folder)
    assert isinstance(run, ModelSet) and run.kind == "reproduce"
    assert run.styles == ["neutral", "elderly", "youthful"]
    assert run.primitives == ["walk_leftStance", "walk_rightStance"]
    about = run.describe()
    assert isinstance(about, Description) and about.kind == "reproduce" and about.data == "synthetic"
    assert about.command and about.commit and len(about.models) == 6
    check_samples(run.sample(3, seed=0))
    one = run.sample(3, seed=1, style="elderly", primitive="walk_rightStance")
    again = run.model("elderly", "walk_rightStance").sample(3, seed=1)
    assert torch.equal(one.positions, again.positions)
    assert run.model("elderly", "walk_rightStance").describe().style == "elderly"
    with pytest.raises(LoadError, match="no model of style 'tired'.*styles: \\['neutral', 'elderly', 'youthful'\\]"):
        run.model("tired")


@pytest.mark.parametrize("stage, kind, style", [("vae/walk_leftStance", "vae", "neutral"),
                                               ("cvae/walk_rightStance_youthful", "cvae", "youthful")])
def test_training_run_folders_and_their_checkpoints_load_as_one_model(tiny_run, stage, kind, style):
    folder = tiny_run.folder / stage
    for path in (folder, folder / "checkpoints" / "best.ckpt"):
        model = load(path)
        assert isinstance(model, Model) and model.kind == kind
        about = model.describe()
        assert (about.kind, about.primitive, about.style, about.data) == (kind, stage.split("/")[1][:len(
            about.primitive)], style, "synthetic")
        assert about.command and about.commit and about.path == str(folder / "checkpoints" / "best.ckpt")
        check_samples(model.sample(3, seed=0))
    # the old entry point is the same model underneath
    old = load_generative(folder / "checkpoints" / "best.ckpt")
    assert torch.equal(old.sample(2, seed=4).positions, load(folder).sample(2, seed=4).positions)
    with pytest.raises(LoadError, match="its style is built in"):
        load(folder).sample(2, example="walk.bvh")


def test_an_autoencoder_loads_and_describes_itself_but_does_not_sample(tiny_run):
    model = load(tiny_run.folder / "autoencoder")
    assert model.kind == "autoencoder" and model.describe().data == "synthetic"
    with pytest.raises(LoadError, match="does not sample"):
        model.sample(2)


def test_style_folders_of_both_methods_load_with_the_run_they_extend(tiny_run):
    cvae_style = load(tiny_style(tiny_run.folder)[0])
    assert cvae_style.kind == "style" and cvae_style.default_style == "tired"
    assert cvae_style.styles[0] == "tired" and {"neutral", "elderly", "youthful"} <= set(cvae_style.styles)
    about = cvae_style.describe()
    assert about.style == "tired" and about.data == "synthetic" and about.commit
    check_samples(cvae_style.sample(3, seed=0))
    assert cvae_style.model().kind == "cvae"

    zero_shot = load(tiny_zero_shot_style(tiny_run.folder)[0])
    assert zero_shot.default_style == "weary" and zero_shot.model().kind == "zero_shot"
    check_samples(zero_shot.sample(3, seed=0))  # bound to the style's own example: no example= needed
    check_samples(zero_shot.sample(3, seed=0, style="neutral"))


def test_a_zero_shot_network_samples_the_style_of_an_example_file(tiny_run):
    folder = tiny_zero_shot_style(tiny_run.folder)[0]
    network = load(folder / "network" / "walk_leftStance")
    assert network.kind == "zero_shot" and network.describe().primitive == "walk_leftStance"
    with pytest.raises(LoadError, match="pass example="):
        network.sample(2)
    example = example_bvh(tiny_run.folder.parent)
    samples = network.sample(3, seed=0, example=str(example))
    check_samples(samples)
    other = network.sample(3, seed=0, example=str(example_bvh(tiny_run.folder.parent, style="elderly")))
    assert not torch.equal(samples.positions, other.positions)  # the example decides the style


def test_a_morphable_graph_model_loads_from_its_file_and_its_run_folder(morphable_run):
    for path in (morphable_run, morphable_run / "model.npz"):
        model = load(path)
        assert model.kind == "morphable" and isinstance(model.model, MorphableModel)
        about = model.describe()
        assert (about.primitive, about.style, about.data) == ("walk_leftStance", "normal", "synthetic")
        assert "morphable_graph" in about.command
        check_samples(model.sample(3, seed=0))
    old = MorphableModel.load(morphable_run)
    assert torch.equal(old.sample(2, seed=1).positions, load(morphable_run).sample(2, seed=1).positions)


def test_what_is_no_model_is_one_clear_error(tmp_path, tiny_run):
    with pytest.raises(NotFoundError, match="does not exist"):
        load(tmp_path / "nothing")
    with pytest.raises(LoadError, match="folder of no stylemotion model"):
        load(tmp_path)
    (tmp_path / "notes.ckpt").write_text("hello")
    with pytest.raises(UserInputError, match="not a readable checkpoint"):
        load(tmp_path / "notes.ckpt")
    unfinished = tmp_path / "unfinished"
    unfinished.mkdir()
    shutil.copy(tiny_run.folder / "reproduce.json", unfinished / "reproduce.json")
    with pytest.raises(LoadError, match="has not finished"):
        load(unfinished)


def test_the_package_exports_load_and_sample(tiny_run):
    assert stylemotion.load is load
    check_samples(stylemotion.sample(tiny_run.folder / "vae" / "walk_rightStance", 3, seed=2))
