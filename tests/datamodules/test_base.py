"""What every DataModule shares (:class:`SplitDataModule`): checked batch and worker settings, the takes from a
data config (built once, lazily) or given directly, the split settings, and the four loaders over ``datasets``."""

from __future__ import annotations

import pytest
import torch
from torch.utils.data import TensorDataset

from stylemotion.datamodules.base import SplitDataModule
from stylemotion.datasets.registry import load_synthetic

DATA = {"name": "synthetic", "takes_per_pair": 1, "duration_s": 1.0, "styles": ["normal"], "contents": ["walk"],
        "split": {"seed": 3, "val_fraction": 0.2, "test_fraction": 0.2}}


class Numbers(SplitDataModule):
    """A subclass as the real ones are: ``setup`` fills ``datasets``; ``check_part`` refuses an empty part."""

    def setup(self, stage: str | None = None) -> None:
        self.datasets = {part: TensorDataset(torch.arange(n, dtype=torch.float32))
                         for part, n in (("train", 10), ("val", 3), ("test", 0))}

    def check_part(self, part: str) -> None:
        if len(self.datasets[part]) == 0:
            raise ValueError(f"no {part} windows")


@pytest.mark.parametrize("kwargs, message", [
    ({}, "Numbers needs a data config or a takeset"),
    ({"data": DATA, "batch_size": 0}, r"datamodule.batch_size must be an integer ≥ 1, got 0"),
    ({"data": DATA, "batch_size": 2.5}, r"datamodule.batch_size must be an integer ≥ 1, got 2.5"),
    ({"data": DATA, "batch_size": True}, r"datamodule.batch_size must be an integer ≥ 1, got True"),
    ({"data": DATA, "eval_batch_size": 0}, r"datamodule.eval_batch_size must be an integer ≥ 1 or null, got 0"),
    ({"data": DATA, "eval_batch_size": "8"}, r"eval_batch_size must be an integer ≥ 1 or null, got '8'"),
    ({"data": DATA, "num_workers": -1}, r"datamodule.num_workers must be an integer ≥ 0, got -1"),
    ({"data": DATA, "num_workers": False}, r"datamodule.num_workers must be an integer ≥ 0, got False"),
])
def test_bad_settings_are_refused_naming_the_key(kwargs: dict, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        Numbers(**kwargs)


def test_the_takes_are_built_from_the_data_config_once_on_first_use(monkeypatch) -> None:
    built = []
    takes = load_synthetic(takes_per_pair=1, duration_s=1.0, styles=["normal"], contents=["walk"])

    def build(cfg):
        built.append(cfg)
        return takes

    monkeypatch.setattr("stylemotion.datamodules.base.build_dataset", build)
    dm = Numbers(data=DATA)
    assert built == []  # nothing built on construction
    dm.prepare_data()
    assert dm.takeset is takes and dm.fps == 30.0 and isinstance(dm.fps, float)
    assert built == [DATA]  # built once
    assert dm.data_cfg == DATA and dm.data_cfg is not DATA  # a copy of the config node
    assert dm.split_cfg == DATA["split"]


def test_a_given_takeset_is_used_and_an_explicit_split_wins() -> None:
    takes = load_synthetic(takes_per_pair=1, duration_s=1.0, styles=["normal"], contents=["walk"])
    dm = Numbers(takeset=takes, split={"seed": 1})
    assert dm.takeset is takes and dm.data_cfg is None and dm.split_cfg == {"seed": 1}
    assert Numbers(data=DATA, split={"seed": 9}).split_cfg == {"seed": 9}
    assert Numbers(data={"name": "synthetic"}).split_cfg == {}


def test_the_loaders_serve_the_parts_with_their_batch_sizes() -> None:
    dm = Numbers(data=DATA, batch_size=4, eval_batch_size=2)
    with pytest.raises(RuntimeError, match=r"call setup\(\) before asking for a DataLoader"):
        dm.train_dataloader()
    dm.setup()
    train, val = dm.train_dataloader(), dm.val_dataloader()
    assert train.batch_size == 4 and val.batch_size == 2 and train.num_workers == 0
    torch.manual_seed(0)
    drawn = torch.cat([batch[0] for batch in train])
    assert sorted(drawn.tolist()) == list(range(10)) and drawn.tolist() != list(range(10))  # shuffled
    assert [batch[0].tolist() for batch in val] == [[0.0, 1.0], [2.0]]  # in order
    with pytest.raises(ValueError, match="no test windows"):  # the subclass' check runs first
        dm.test_dataloader()
    with pytest.raises(ValueError, match="no test windows"):
        dm.predict_dataloader()  # predict = test
    assert Numbers(data=DATA, batch_size=5).eval_batch_size == 5  # defaults to batch_size


def test_worker_processes_are_kept_between_epochs() -> None:
    dm = Numbers(data=DATA, num_workers=2)
    dm.setup()
    loader = dm.train_dataloader()
    assert loader.num_workers == 2 and loader.persistent_workers
