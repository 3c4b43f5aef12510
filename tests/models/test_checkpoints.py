"""The one checkpoint-loading path (stylemotion.models.checkpoints): reads only with
``weights_only=True``, generative checkpoints that embed their autoencoder (bit-identical samples), a
run folder that moved (sampling, ``stylemotion-eval``, synthesis), checkpoints written before the
embedding, and a models package that does not import the data side."""

from __future__ import annotations

import ast
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import torch
from vae_fixtures import TINY_DATA, feature_module, fit, tiny_autoencoder_ckpt

import stylemotion
from stylemotion.evaluation.run import run_evaluation
from stylemotion.models import checkpoints
from stylemotion.models.autoencoder import IncompatibleModelError
from stylemotion.models.checkpoints import (
    EMBEDDED_AUTOENCODER,
    MissingAutoencoderError,
    find_checkpoints,
    fingerprint,
    is_model_checkpoint,
    load_autoencoder,
    read_checkpoint,
)
from stylemotion.models.loading import load_generative, load_model
from stylemotion.models.vae import PrimitiveVAE
from stylemotion.synthesis import load_graph

torch.set_num_threads(1)
PRIMITIVES = ("walk_leftStance", "walk_rightStance")
EVAL = {"samples": {"table_5_1": 40, "variance": 60, "metrics": 40}, "classifier": {"components": 6}}
SAMPLE_FIELDS = ("positions", "frames", "num_frames", "duration_s", "latent", "features")


def train_run(root: Path, autoencoder: Path) -> Path:
    """A run folder laid out like a reproduction's: ``autoencoder/checkpoints/best.ckpt`` (a copy of
    ``autoencoder``) and tiny neutral VAEs of both walk stances in ``vae/<primitive>/checkpoints/best.ckpt``."""
    ae = root / "autoencoder" / "checkpoints" / "best.ckpt"
    ae.parent.mkdir(parents=True)
    shutil.copy(autoencoder, ae)
    for primitive in PRIMITIVES:
        torch.manual_seed(0)
        model = PrimitiveVAE(latent_dim=4, hidden=[32], samples_per_item=2)
        fit(model, feature_module(ae, primitive=primitive), steps=16, folder=root / "vae" / primitive / "checkpoints")
    return root


@pytest.fixture(scope="module")
def tiny_ae(tmp_path_factory) -> Path:
    return tiny_autoencoder_ckpt(tmp_path_factory.mktemp("checkpoints_ae"))


@pytest.fixture(scope="module")
def run(tmp_path_factory, tiny_ae) -> Path:
    return train_run(tmp_path_factory.mktemp("checkpoints") / "run", tiny_ae)


def vae_ckpt(root: Path, primitive: str = "walk_leftStance") -> Path:
    return root / "vae" / primitive / "checkpoints" / "best.ckpt"


def assert_same_samples(a, b) -> None:
    for name in SAMPLE_FIELDS:
        assert torch.equal(getattr(a, name), getattr(b, name)), name


def numbers(results: dict) -> dict:
    """An evaluation's results without what names files (meta, autoencoder path, model checkpoints)."""
    out = {k: v for k, v in results.items() if k not in ("meta", "autoencoder", "models")}
    out["models"] = [{k: v for k, v in m.items() if k != "checkpoint"} for m in results["models"]]
    out["autoencoder"] = {k: v for k, v in results["autoencoder"].items() if k != "path"}
    return out


def as_older_checkpoint(ckpt: Path, autoencoder: Path) -> None:
    """Rewrite ``ckpt`` as written before autoencoders were embedded, by a model trained on the
    autoencoder at ``autoencoder`` (recorded as an absolute path)."""
    raw = torch.load(ckpt, weights_only=True)
    del raw[EMBEDDED_AUTOENCODER]
    raw["hyper_parameters"]["spec"]["autoencoder"]["path"] = str(autoencoder)
    torch.save(raw, ckpt)


# -- one loading path, safe reads


def test_the_models_package_does_not_import_the_data_side() -> None:
    script = ("import sys, stylemotion.models, stylemotion.models.checkpoints, stylemotion.models.cvae\n"
              "print(sorted(m for m in sys.modules if m.startswith('stylemotion.datamodules')))")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.strip() == "[]"


def test_every_torch_load_is_in_the_checkpoint_module_with_weights_only_true() -> None:
    """No other module of the package reads a checkpoint (torch.load, Lightning's load_from_checkpoint)."""
    package = Path(stylemotion.__file__).parent
    loads, lightning_loads = [], []
    for path in sorted(package.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
                where = f"{path.relative_to(package)}:{node.lineno}"
                if node.func.attr == "load" and ast.unparse(node.func.value) == "torch":
                    explicit = any(k.arg == "weights_only" and isinstance(k.value, ast.Constant)
                                   and k.value.value is True for k in node.keywords)
                    loads.append((where, explicit))
                elif node.func.attr == "load_from_checkpoint":
                    lightning_loads.append(where)
    assert loads and all(where.startswith("models/checkpoints.py:") and explicit for where, explicit in loads), loads
    assert not lightning_loads


def test_loading_calls_torch_load_only_with_explicit_weights_only(run, monkeypatch, tmp_path) -> None:
    """Every read of a model, its autoencoder and a folder of checkpoints passes weights_only=True itself
    (torch < 2.6 would otherwise unpickle anything)."""
    real_load, calls = torch.load, []

    def strict_load(*args, **kwargs):
        calls.append(kwargs.get("weights_only"))
        assert kwargs.get("weights_only") is True, kwargs
        return real_load(*args, **kwargs)

    monkeypatch.setattr(torch, "load", strict_load)
    found = find_checkpoints([str(run / "vae")])
    assert found == [vae_ckpt(run, p) for p in PRIMITIVES] and is_model_checkpoint(found[0])
    entry = load_model(found[0])
    entry.source.sample(2, seed=0)
    load_autoencoder(run / "autoencoder" / "checkpoints" / "best.ckpt")
    assert len(calls) >= 4 and set(calls) == {True}


class _Payload:
    """An object whose unpickling would write a file."""

    def __init__(self, target: str):
        self.target = target

    def __reduce__(self):
        return (Path.write_text, (Path(self.target), "code ran"))


def test_a_checkpoint_holding_code_is_refused_without_running_it(tmp_path) -> None:
    target = tmp_path / "pwned.txt"
    torch.save({"hyper_parameters": {"payload": _Payload(str(target))}, "state_dict": {}}, tmp_path / "evil.ckpt")
    with pytest.raises(IncompatibleModelError, match=r"evil\.ckpt is not a readable checkpoint of plain values"):
        read_checkpoint(tmp_path / "evil.ckpt")
    with pytest.raises(IncompatibleModelError, match="evil.ckpt"):
        load_generative(tmp_path / "evil.ckpt")
    assert not target.exists()
    with pytest.raises(FileNotFoundError, match="model checkpoint '.*nope.ckpt' does not exist"):
        load_generative(tmp_path / "nope.ckpt")


# -- the embedded autoencoder


def test_generative_checkpoints_embed_their_autoencoder_and_sample_bit_identically(run, monkeypatch) -> None:
    ckpt = vae_ckpt(run)
    raw = torch.load(ckpt, weights_only=True)  # tensors and plain values only
    original = load_autoencoder(run / "autoencoder" / "checkpoints" / "best.ckpt")
    embedded = raw[EMBEDDED_AUTOENCODER]["state_dict"]
    assert embedded.keys() == original.state_dict().keys()
    assert all(torch.equal(embedded[k], v) for k, v in original.state_dict().items())  # the same weights
    assert raw[EMBEDDED_AUTOENCODER]["hyper_parameters"] == dict(original.hparams)
    reference = load_generative(ckpt, autoencoder=original).sample(6, seed=3)

    def no_file(*args, **kwargs):
        raise AssertionError("the autoencoder was read from a file, not from the checkpoint")

    monkeypatch.setattr(checkpoints, "load_autoencoder", no_file)
    for model in (PrimitiveVAE.load_from_checkpoint(ckpt), load_generative(ckpt)):  # Lightning's loader too
        assert_same_samples(model.sample(6, seed=3), reference)
        assert fingerprint(model.autoencoder) == raw["hyper_parameters"]["spec"]["autoencoder"]["fingerprint"]


def test_an_embedded_autoencoder_with_other_weights_is_refused(run, tmp_path) -> None:
    raw = torch.load(vae_ckpt(run), weights_only=True)
    raw[EMBEDDED_AUTOENCODER]["state_dict"]["net.encoder.bias"] += 1e-3
    torch.save(raw, tmp_path / "tampered.ckpt")
    model = load_generative(tmp_path / "tampered.ckpt")
    with pytest.raises(IncompatibleModelError, match=r"embedded in .*tampered\.ckpt has weights .* trained on"):
        model.sample(2, seed=0)


# -- a run folder that moved


def test_a_moved_run_samples_evaluates_and_synthesizes(tiny_ae, tmp_path) -> None:
    first = train_run(tmp_path / "first" / "run", tiny_ae)
    before = run_evaluation(TINY_DATA, [str(first / "vae")], EVAL, first / "report", root=first)
    meta = before["meta"]
    assert meta["paths_relative_to"] == ".."  # from the report folder to the run folder
    assert meta["autoencoder"]["path"] == "autoencoder/checkpoints/best.ckpt"
    assert [c["path"] for c in meta["checkpoints"]] == [f"vae/{p}/checkpoints/best.ckpt" for p in PRIMITIVES]
    samples = load_generative(vae_ckpt(first)).sample(5, seed=1)

    moved = tmp_path / "elsewhere" / "renamed"
    moved.parent.mkdir()
    shutil.move(first, moved)
    shutil.rmtree(tmp_path / "first")
    assert_same_samples(PrimitiveVAE.load_from_checkpoint(vae_ckpt(moved)).sample(5, seed=1), samples)

    again = run_evaluation(TINY_DATA, [str(moved / "vae")], EVAL, tmp_path / "eval")  # stylemotion-eval
    assert again["meta"]["autoencoder"]["path"] == str(vae_ckpt(moved))  # the recorded one is gone: embedded there
    assert [c["path"] for c in again["meta"]["checkpoints"]] == [str(vae_ckpt(moved, p)) for p in PRIMITIVES]
    assert [m["checkpoint"] for m in before["models"]] == [c["path"] for c in meta["checkpoints"]]
    assert json.dumps(numbers(again), sort_keys=True) == json.dumps(numbers(before), sort_keys=True)

    graph = load_graph("neutral", run=moved)
    assert graph.sources == {p.split("_")[1]: str(vae_ckpt(moved, p)) for p in PRIMITIVES}
    assert graph.models["leftStance"].autoencoder is graph.models["rightStance"].autoencoder
    assert_same_samples(graph.models["leftStance"].sample(5, seed=1), samples)


def test_an_older_checkpoint_finds_its_autoencoder_relative_to_itself(run, tmp_path) -> None:
    """Checkpoints written before the embedding record the autoencoder's absolute path only: after a
    move it is found at the same place relative to the checkpoint, else the error says what was tried."""
    first = tmp_path / "first" / "run"
    shutil.copytree(run, first)
    reference = load_generative(vae_ckpt(first)).sample(4, seed=2)
    recorded = first / "autoencoder" / "checkpoints" / "best.ckpt"
    as_older_checkpoint(vae_ckpt(first), recorded)
    moved = tmp_path / "moved" / "run"
    shutil.move(tmp_path / "first", tmp_path / "moved")
    model = load_generative(vae_ckpt(moved))
    assert_same_samples(model.sample(4, seed=2), reference)
    assert model.autoencoder_path == str(moved / "autoencoder" / "checkpoints" / "best.ckpt")

    (moved / "autoencoder" / "checkpoints" / "best.ckpt").unlink()
    with pytest.raises(MissingAutoencoderError, match="embeds none") as err:
        load_generative(vae_ckpt(moved)).sample(1)
    assert f"{recorded} (no such file)" in str(err.value) and str(vae_ckpt(moved)) in str(err.value)
    assert "attach_autoencoder" in str(err.value)
