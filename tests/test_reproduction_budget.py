"""The reproduction's budget: what the synthetic default trains with, and that a budget reaches every stage."""

from __future__ import annotations

import pytest
from hydra import compose, initialize_config_dir

from stylemotion.cli.schemas import register_schemas
from stylemotion.config import CONFIG_DIR
from stylemotion.training.reproduction import Reproduction, choose_budget

register_schemas()


def planned(*overrides: str) -> dict[str, list[str]]:
    """kind → the overrides of its first stage, as the reproduction plans them (no training)."""
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose(config_name="reproduce", overrides=list(overrides))
    choose_budget(cfg)
    repro = Reproduction(cfg)
    repro.plan(["elderly"])
    return {stage.kind: stage.overrides for stage in reversed(repro.stages)}


def test_the_synthetic_default_draws_fewer_samples_saves_less_and_renders_no_stage_gifs() -> None:
    stages = planned()
    assert "model.samples_per_item=5" in stages["cvae"] and "model.samples_per_item=10" in stages["vae"]
    assert "trainer.max_epochs=210" in stages["cvae"] and "model.style_weight=5.0" in stages["cvae"]
    for kind in ("vae", "cvae"):
        assert "callbacks.samples=null" in stages[kind]
        assert "callbacks.checkpoint_last.every_n_epochs=20" in stages[kind]
    assert not any(o.startswith("callbacks.") for o in stages["autoencoder"])


@pytest.mark.parametrize("data", ["bandai", "bvh_folder"])
def test_other_data_keep_the_thesis_settings_and_stage_gifs(data: str) -> None:
    stages = planned(f"data={data}")
    assert "model.samples_per_item=10" in stages["cvae"] and "model.samples_per_item=10" in stages["vae"]
    assert "callbacks.checkpoint_last.every_n_epochs=1" in stages["cvae"]
    assert not any(o == "callbacks.samples=null" for kind in stages for o in stages[kind])
