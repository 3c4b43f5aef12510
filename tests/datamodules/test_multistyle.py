"""The multi-style DataModule: an excluded style never reaches a batch, each clip's example is another clip
of its style, the timeline and the style examples are those of the neutral VAE and the style CVAEs, and
bad style names are refused naming the key."""

from __future__ import annotations

from pathlib import Path

import pytest
import torch
from vae_fixtures import TINY_DATA, feature_module, tiny_autoencoder_ckpt, tiny_takeset

from stylemotion.datamodules.multistyle import MultiStyleDataModule

torch.set_num_threads(1)


@pytest.fixture(scope="session")
def ae_ckpt(tmp_path_factory) -> Path:
    return tiny_autoencoder_ckpt(tmp_path_factory.mktemp("multistyle_ae"))


def module(ae_ckpt: Path, **kwargs) -> MultiStyleDataModule:
    kwargs.setdefault("min_train_clips", 8)
    kwargs.setdefault("batch_size", 8)
    dm = MultiStyleDataModule(takeset=tiny_takeset(), autoencoder_ckpt=str(ae_ckpt), split=TINY_DATA["split"],
                              **kwargs)
    dm.setup("fit")
    return dm


@pytest.fixture(scope="module")
def without_youthful(ae_ckpt) -> MultiStyleDataModule:
    return module(ae_ckpt, exclude_styles=["youthful"])


def test_an_excluded_style_never_appears_in_training_batches(without_youthful) -> None:
    dm = without_youthful
    youthful = dm.style_names.index("youthful")
    assert dm.styles == ["elderly", "normal"] and dm.model_spec()["excluded_styles"] == ["youthful"]
    train = dm.datasets["train"]
    seen = set()
    for _ in range(3):  # three epochs: examples are drawn afresh each time
        for batch in dm.train_dataloader():
            assert not (batch["style"] == youthful).any()
            assert torch.equal(train.pool_style[batch["example_index"]], batch["style"])
            assert torch.equal(batch["example_features"], train.features[batch["example_index"]])
            seen |= set(batch["style"].tolist())
    assert seen == {dm.style_names.index("elderly"), dm.style_names.index("normal")}
    for part in ("train", "val", "test"):
        assert {c.style for c in dm.datasets[part].clips} == {"elderly", "normal"}, part
        assert dm.summary["clips_per_style"][part]["elderly"] > 0


def test_each_clip_is_paired_with_another_clip_of_its_style(without_youthful) -> None:
    train, val = without_youthful.datasets["train"], without_youthful.datasets["val"]
    for index in range(len(train)):
        partners = {int(train[index]["example_index"]) for _ in range(12)}
        assert index not in partners and len(partners) > 1  # never itself, drawn afresh
        assert {train.clips[p].style for p in partners} == {train.clips[index].style}
    for index in range(len(val)):  # validation pairs are fixed: the same loss every epoch
        first, again = int(val[index]["example_index"]), int(val[index]["example_index"])
        assert first == again and train.clips[first].style == val.clips[index].style


def test_timeline_and_examples_are_those_of_the_neutral_vae_and_the_style_cvaes(ae_ckpt, without_youthful) -> None:
    dm = without_youthful
    cvae_data = feature_module(ae_ckpt, style="youthful")  # what a StyleCVAE of the excluded style is trained on
    assert dm.timeline_frames == cvae_data.timeline_frames
    clip, cvae_clip = dm.example_clip("youthful"), cvae_data.clip_data.style_example("youthful")
    assert (clip.take, clip.start, clip.stop) == (cvae_clip.take, cvae_clip.start, cvae_clip.stop)
    assert torch.allclose(dm.example_features("youthful"), cvae_data.style_features[0])
    record = dm.model_spec()["style_examples_by_style"]["youthful"]
    assert (record["take"], record["start"], record["encoded_frames"]) == (clip.take, clip.start, dm.timeline_frames)
    median = module(ae_ckpt, timeline="median")  # all served styles' median instead
    assert median.timeline_frames == median.features.clip_data.length


@pytest.mark.parametrize("kwargs, message", [
    ({"exclude_styles": ["angry"]}, r"datamodule.exclude_styles: style\(s\) \['angry'\] are not in dataset"),
    ({"styles": ["normal", "old"]}, r"datamodule.styles: style\(s\) \['old'\]"),
    ({"exclude_styles": "elderly"}, r"must be a list of style names, got the string 'elderly' \(write \[elderly\]\)"),
    ({"styles": ["elderly"], "exclude_styles": ["elderly"]}, "no style left to train on"),
    ({"timeline": "longest"}, "datamodule.timeline must be one of"),
])
def test_bad_styles_are_refused_naming_the_key(ae_ckpt, kwargs, message) -> None:
    with pytest.raises(ValueError, match=message):
        module(ae_ckpt, **kwargs)
