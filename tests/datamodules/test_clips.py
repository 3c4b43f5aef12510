"""The clip DataModule: filters, take-based split, canonical length, style examples, bad requests."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch
from hydra.utils import instantiate
from omegaconf import OmegaConf

from stylemotion.config import CONFIG_DIR
from stylemotion.datamodules.clips import PRIMITIVE_INDEX, ClipDataModule, NoClipsError
from stylemotion.datasets import Take, TakeSet, load_dataset
from stylemotion.datasets.registry import load_synthetic
from stylemotion.datasets.synthetic import STYLES
from stylemotion.primitives.segmentation import PRIMITIVES

SPLIT = {"seed": 3, "val_fraction": 0.25, "test_fraction": 0.25}


@pytest.fixture(scope="module")
def synthetic() -> TakeSet:
    return load_synthetic(takes_per_pair=4, seed=0, duration_s=3.0, contents=["walk", "walk-turn-left", "run"])


def module(takeset: TakeSet, **kwargs) -> ClipDataModule:
    kwargs.setdefault("split", SPLIT)
    dm = ClipDataModule(takeset=takeset, **kwargs)
    dm.setup()
    return dm


def test_batches_filters_and_canonical_length(synthetic: TakeSet) -> None:
    dm = module(synthetic, primitives=["leftStance", "rightStance"], styles=["normal", "elderly"], batch_size=8)
    train = dm.clips["train"]
    assert dm.length == int(round(float(np.median([c.num_frames for c in train]))))
    assert {c.primitive for c in train} == {"leftStance", "rightStance"}
    assert {c.style for c in train} == {"normal", "elderly"} and {c.action for c in train} == {"walk"}
    batch = next(iter(dm.train_dataloader()))
    assert batch["frames"].shape == (8, dm.length, 66) and batch["frames"].dtype == torch.float32
    assert batch["duration_s"].shape == (8,) and (batch["duration_s"] > 0.2).all()
    assert set(batch["primitive"].tolist()) <= {PRIMITIVES.index("leftStance"), PRIMITIVES.index("rightStance")}
    assert {dm.style_names[i] for i in batch["style"].tolist()} <= {"normal", "elderly"}
    fixed = module(synthetic, timeline=24)
    assert next(iter(fixed.val_dataloader()))["frames"].shape[1] == 24


def test_split_is_the_datasets_take_split(synthetic: TakeSet) -> None:
    dm = module(synthetic, styles=None)
    expected = {part: {t.name for t in takes} for part, takes in synthetic.split(**SPLIT).items()}
    for part in ("train", "val", "test"):
        takes = {c.take for c in dm.clips[part]}
        assert takes and takes <= expected[part], part
    again = module(synthetic, styles=None)
    assert [(c.take, c.start) for c in again.clips["test"]] == [(c.take, c.start) for c in dm.clips["test"]]


def test_one_style_example_per_style(synthetic: TakeSet) -> None:
    dm = module(synthetic, primitives=["rightStance"], styles=["normal"])
    examples = dm.style_examples()
    assert sorted(examples) == sorted(STYLES)
    for style, clip in examples.items():
        assert clip.style == style and clip.primitive == "rightStance" and clip.content == "walk"
        candidates = [c for c in dm.segmentation.clips if c.style == style and c.primitive == "rightStance"
                      and c.content == "walk"]
        median = np.median([c.duration_s for c in candidates])
        assert abs(clip.duration_s - median) == min(abs(c.duration_s - median) for c in candidates)
    assert dm.example_frames("elderly").shape == (dm.length, 66)
    first = module(synthetic, example={"pick": "first", "primitive": "leftStance", "content": "walk-turn-left"})
    clip = first.style_example("youthful")
    assert clip.primitive == "leftStance" and clip.content == "walk-turn-left"
    chosen = module(synthetic, example={"pick": "take", "take": clip.take, "start": clip.start,
                                        "primitive": "leftStance", "content": "walk-turn-left"})
    assert chosen.style_example("youthful") is not clip and chosen.style_example("youthful").start == clip.start
    third = module(synthetic, example={"pick": "index", "index": 2})
    assert third.style_example("normal") is not third.style_example("active")


def test_style_without_example_clip_is_a_clear_error(synthetic: TakeSet) -> None:
    takes = [t for t in synthetic.takes if not (t.style == "exhausted" and t.content == "walk")]
    dm = module(TakeSet("partial", takes, synthetic.fps))
    with pytest.raises(NoClipsError, match="style 'exhausted' has no example clip.*styles with such clips"):
        dm.style_example("exhausted")
    with pytest.raises(NoClipsError, match="no example"):
        dm.style_examples()
    assert dm.style_example("normal").style == "normal"
    with pytest.raises(NoClipsError, match="out of range"):
        module(synthetic, example={"pick": "index", "index": 10_000}).style_example("normal")
    with pytest.raises(NoClipsError, match="in take 'nope'"):
        module(synthetic, example={"pick": "take", "take": "nope"}).style_example("normal")


def test_bad_requests(synthetic: TakeSet) -> None:
    with pytest.raises(ValueError, match="unknown motion primitive 'stance'.*leftStance"):
        ClipDataModule(takeset=synthetic, primitives=["stance"])
    with pytest.raises(ValueError, match="unknown motion primitive 'LeftStance'"):
        ClipDataModule(takeset=synthetic, example={"primitive": "LeftStance"})
    with pytest.raises(ValueError, match="unknown example pick"):
        ClipDataModule(takeset=synthetic, example={"pick": "best"})
    with pytest.raises(ValueError, match="unknown style example option"):
        ClipDataModule(takeset=synthetic, example={"clip": 3})
    with pytest.raises(ValueError, match="unknown action 'jog'"):
        ClipDataModule(takeset=synthetic, action="jog")
    with pytest.raises(NoClipsError, match="style 'sleepy' is not in dataset"):
        module(synthetic, styles=["sleepy"])
    with pytest.raises(NoClipsError, match=r"no walk clip of primitive\(s\) \['beginLeftStance'\].*leftStance/"):
        module(synthetic, primitives=["beginLeftStance"])


def test_hydra_config_instantiates(synthetic: TakeSet) -> None:
    cfg = OmegaConf.load(CONFIG_DIR / "datamodule" / "clips.yaml")
    data = {"name": "synthetic", "takes_per_pair": 3, "duration_s": 3.0, "contents": ["walk", "run"],
            "styles": ["normal", "active"], "split": {"seed": 0, "val_fraction": 0.2, "test_fraction": 0.2}}
    dm = instantiate(cfg, data=data, action="run", _convert_="all")
    dm.setup()
    assert dm.clips["train"] and {c.action for c in dm.clips["train"]} == {"run"}
    assert dm.hparams["data"]["name"] == "synthetic" and dm.hparams["example"]["pick"] == "median"
    assert set(dm.style_examples()) == {"normal", "active"}


@pytest.mark.realdata
def test_bandai_style_examples_for_all_seven_styles(bandai_zip_path: Path) -> None:
    full = load_dataset("bandai", root=bandai_zip_path, contents=["walk", "walk-turn-left", "walk-turn-right", "run"])
    keep: dict[tuple[str, str], list[Take]] = {}
    for take in full.takes:
        group = keep.setdefault((take.content, take.style), [])
        if len(group) < 4:
            group.append(take)
    takeset = TakeSet("bandai-subset", [t for g in keep.values() for t in g], full.fps)
    dm = module(takeset, styles=["normal"])
    examples = dm.style_examples()
    assert sorted(examples) == sorted(STYLES)
    assert all(c.content == "walk" and c.primitive == "leftStance" for c in examples.values())
    assert 10 <= dm.length <= 25  # a walking step at 30 fps


def test_median_timeline_is_at_least_min_length(synthetic: TakeSet) -> None:
    median = module(synthetic, action="run", primitives=["leftStance"]).length
    stretched = module(synthetic, action="run", primitives=["leftStance"], min_length=median + 7)
    assert stretched.length == median + 7
    assert next(iter(stretched.val_dataloader()))["frames"].shape[1] == median + 7
    assert module(synthetic, action="run", primitives=["leftStance"], min_length=2).length == median


@pytest.mark.realdata
def test_bandai_arm_action_serves_its_raise_clips(bandai_zip_path: Path) -> None:
    full = load_dataset("bandai", root=bandai_zip_path, contents=["raise-up-right-hand"])
    takes = [t for style in ("normal", "elderly") for t in [t for t in full.takes if t.style == style][:12]]
    takeset = TakeSet("bandai-raise", takes, full.fps)
    dm = module(takeset, action="raise-up-right-hand", primitives=["raise"], styles=["normal"])
    clips = [c for part in ("train", "val", "test") for c in dm.clips[part]]
    assert clips and {(c.action, c.primitive, c.style) for c in clips} == {("raise-up-right-hand", "raise", "normal")}
    batch = next(iter(dm.train_dataloader()))
    assert set(batch["primitive"].tolist()) == {PRIMITIVE_INDEX.index("raise")}
    assert dm.style_example("elderly").primitive == "raise"
    with pytest.raises(ValueError, match="has no 'wave' primitive"):
        ClipDataModule(takeset=takeset, action="raise-up-right-hand", primitives=["wave"])
