"""``stylemotion-eval`` on checkpoints that are not checkpoints and bad sample counts (issue 26): one line naming
the file or key, exit status 2, no traceback, no report folder."""

from __future__ import annotations

import pytest
import torch
from cli_runner import run_command

from stylemotion.evaluation.run import settings_from_config
from stylemotion.io.errors import UserInputError


def _files(folder):
    (folder / "empty.ckpt").write_bytes(b"")
    (folder / "junk.ckpt").write_bytes(b"\x80\x04junk")
    torch.save({"state_dict": {"w": torch.zeros(2)}, "global_step": 1}, folder / "whole.ckpt")
    (folder / "cut.ckpt").write_bytes((folder / "whole.ckpt").read_bytes()[:200])
    torch.save({"hyper_parameters": {"hidden_units": 8, "kernel_size": 3, "representation": "x", "fps": 30},
                "state_dict": {}}, folder / "autoencoder.ckpt")
    (folder / "graph").mkdir()
    (folder / "graph" / "model.npz").write_bytes(b"not a zip")


@pytest.mark.parametrize("name, message", [
    ("missing.ckpt", "no checkpoint matches 'missing.ckpt'"),
    ("empty.ckpt", "empty.ckpt is not a readable checkpoint"),
    ("junk.ckpt", "junk.ckpt is not a readable checkpoint"),
    ("cut.ckpt", "cut.ckpt is not a readable checkpoint"),
    ("autoencoder.ckpt", "autoencoder.ckpt is not a trained PrimitiveVAE/StyleCVAE/ZeroShotStyleVAE checkpoint"),
    ("graph", "checkpoints= holds Morphable Graph models only"),
    ("", "checkpoints= is empty"),
])
def test_a_checkpoint_that_is_not_one_is_named_in_one_line(name, message, tmp_path, capsys, monkeypatch):
    _files(tmp_path)
    done = run_command("evaluate", f"checkpoints=[{name}]", "out=report", "hydra.run.dir=hydra", capsys=capsys,
                       monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("stylemotion-eval: ") and message in line, line
    assert not (tmp_path / "report").exists()


def test_a_sample_count_below_two_names_its_key(tmp_path, capsys, monkeypatch):
    with pytest.raises(UserInputError, match=r"evaluation\.samples\.table_5_1 must be at least 2 .*got 0"):
        settings_from_config({"samples": {"table_5_1": 0}}, seed=0)
    done = run_command("evaluate", "checkpoints=[x.ckpt]", "evaluation.samples.variance=-3", "out=report",
                       "hydra.run.dir=hydra", capsys=capsys, monkeypatch=monkeypatch, cwd=tmp_path)
    assert done.returncode == 2 and done.stderr.strip() == (
        "stylemotion-eval: evaluation.samples.variance must be at least 2 (samples per model), got -3")
