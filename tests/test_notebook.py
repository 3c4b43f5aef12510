"""``notebooks/01_autoencoder.ipynb`` runs top to bottom on a checkpoint trained here."""

from __future__ import annotations

from pathlib import Path

import nbformat
import pytest
import torch
from hydra import compose, initialize_config_dir
from nbclient import NotebookClient

from stylemotion.config import config_dir
from stylemotion.training.fit import run

NOTEBOOK = Path(__file__).resolve().parents[1] / "notebooks" / "01_autoencoder.ipynb"


@pytest.fixture(scope="module")
def checkpoint(tmp_path_factory) -> Path:
    """A small autoencoder trained for a few steps on a tiny synthetic dataset."""
    out = tmp_path_factory.mktemp("run")
    overrides = ["experiment=smoke", "data=synthetic", "data.takes_per_pair=3", "data.duration_s=4.0",
                 "data.styles=[normal,feminine]", "data.contents=[walk]", f"output_dir={out}"]
    with initialize_config_dir(config_dir(), version_base="1.3"):
        run(compose("train", overrides=overrides))
    return out / "checkpoints" / "best.ckpt"


def test_notebook_reconstructs_and_plots_a_take(checkpoint, tmp_path, monkeypatch):
    figure = tmp_path / "figure.png"
    monkeypatch.setenv("STYLEMOTION_CKPT", str(checkpoint))
    monkeypatch.setenv("STYLEMOTION_FIGURE", str(figure))
    nb = nbformat.read(NOTEBOOK, as_version=4)
    NotebookClient(nb, timeout=180, kernel_name="python3",
                   resources={"metadata": {"path": str(NOTEBOOK.parent)}}).execute()
    text = "".join(out.get("text", "") for cell in nb.cells if cell.cell_type == "code" for out in cell.outputs)
    assert f"checkpoint: {checkpoint}" in text
    assert "on data: synthetic" in text
    take = torch.load(checkpoint, weights_only=True)["datamodule_hyper_parameters"]["data"]
    assert take["styles"] == ["normal", "feminine"]
    assert "take synthetic_walk_" in text and "features (1, 32, 60) reconstruction (120, 66)" in text
    assert "MPJPE over the take:" in text
    images = [out for cell in nb.cells if cell.cell_type == "code" for out in cell.outputs
              if "image/png" in out.get("data", {})]
    assert len(images) == 1
    assert figure.is_file() and figure.stat().st_size > 10_000
