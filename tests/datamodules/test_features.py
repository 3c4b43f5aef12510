"""The feature DataModule's example clips from outside the dataset (``stylemotion-style``): a style the data
does not have, encoded like the dataset's examples and recorded with the caller's values; bad requests."""

from __future__ import annotations

from pathlib import Path

import pytest
import torch
from vae_fixtures import feature_module, tiny_autoencoder_ckpt

from stylemotion.datamodules.features import encode_examples
from stylemotion.datasets.base import Take
from stylemotion.datasets.synthetic import generate_take
from stylemotion.primitives.actions import segment_action
from stylemotion.primitives.segmentation import Clip

torch.set_num_threads(1)


@pytest.fixture(scope="session")
def ae_ckpt(tmp_path_factory) -> Path:
    return tiny_autoencoder_ckpt(tmp_path_factory.mktemp("features_ae"))


def outside_clips(fps: float = 30.0) -> list[Clip]:
    """Left-stance clips of a synthetic *exhausted* walk (a style the tiny data does not have)."""
    g = generate_take("walk", "exhausted", 0, seed=9, fps=fps, duration_s=4.0)
    take = Take("mine", g.positions, fps, {"content": "walk", "style": "tired"}, "mine.bvh")
    return segment_action([take], "walk").select("walk", ["leftStance"])


def test_example_clips_from_outside_condition_a_style_the_data_lacks(ae_ckpt) -> None:
    clips = outside_clips()
    records = [{"file": "mine.bvh", "sha256": "ab" * 32, "file_frames": [2 * c.start, 2 * c.stop]} for c in clips]
    dm = feature_module(ae_ckpt, style="tired", example_clips=clips, example_records=records)
    expected = encode_examples(dm.autoencoder, clips, dm.timeline_frames)
    assert len(dm.style_features) == len(clips) >= 2
    assert all(torch.equal(a, b) for a, b in zip(dm.style_features, expected))
    spec = dm.model_spec()
    assert spec["style"] == "tired" and spec["dataset"] == "synthetic"
    for record, clip, extra in zip(spec["style_examples"], clips, records):
        assert (record["take"], record["start"], record["stop"], record["style"]) == ("mine", clip.start, clip.stop,
                                                                                      "tired")
        assert record["encoded_frames"] == dm.timeline_frames and record["file_frames"] == extra["file_frames"]
        assert record["sha256"] == extra["sha256"]
    assert "example_clips" not in dm.hparams and dm.hparams["example_records"] == records  # plain values only


@pytest.mark.parametrize("kwargs, message", [
    ({"example_clips": "clips"}, "set style=<its name> as well"),
    ({"style": "tired", "example_clips": "clips", "examples": [{"pick": "first"}]}, "not both"),
    ({"style": "tired", "example_clips": []}, "example_clips of style 'tired' is empty"),
    ({"style": "tired", "example_clips": "clips", "example_records": [{}]}, "example_records has 1 entries for"),
])
def test_bad_example_clips_are_refused(ae_ckpt, kwargs, message) -> None:
    if kwargs.get("example_clips") == "clips":
        kwargs = {**kwargs, "example_clips": outside_clips()}
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        feature_module(ae_ckpt, **kwargs)


def test_example_clips_at_another_frame_rate_are_refused(ae_ckpt) -> None:
    with pytest.raises(ValueError, match=r"is at 60 fps, the data at 30 fps"):
        feature_module(ae_ckpt, style="tired", example_clips=outside_clips(fps=60.0))


def test_feature_scale_none_gives_the_models_the_raw_features(ae_ckpt) -> None:
    """feature_scale=none (preset style_cvae_thesis): no centre and no scale, so the VAE models Y = Φ(X) itself."""
    from stylemotion.models.vae import PrimitiveVAE

    dm = feature_module(ae_ckpt, feature_scale="none")
    assert torch.equal(dm.feature_mean, torch.zeros_like(dm.feature_mean))
    assert torch.equal(dm.feature_std, torch.ones_like(dm.feature_std))
    model = PrimitiveVAE(spec=dm.model_spec())
    model._install_stats(dm)
    train = dm.datasets["train"]
    y = model.normalize(train.features[:3], train.duration_s[:3])
    torch.testing.assert_close(y[:, :-1], train.features[:3].flatten(-2))
    glob = feature_module(ae_ckpt)  # the default centres every channel
    assert not torch.allclose(glob.feature_mean, torch.zeros_like(glob.feature_mean))
    with pytest.raises(ValueError, match="feature_scale"):
        feature_module(ae_ckpt, feature_scale="raw")
