"""Settings defaults live once, in their dataclasses: the Hydra configs take them as structured
configs, typed and checked, instead of restating them."""

from __future__ import annotations

from dataclasses import asdict

import pytest
import yaml
from hydra import compose, initialize_config_dir
from hydra.errors import ConfigCompositionException
from omegaconf import OmegaConf

from stylemotion.cli.schemas import register_schemas, register_schemas_for
from stylemotion.config import CONFIG_DIR, ConfigError, build_settings
from stylemotion.evaluation.run import settings_from_config
from stylemotion.evaluation.settings import EvalSettings, SampleCounts
from stylemotion.primitives.segmentation import SegmentSettings
from stylemotion.synthesis.controller import FollowSettings

register_schemas()  # the configs composed here take structured schemas (stylemotion.cli.schemas)


def _compose(name: str, overrides: list[str]):
    with initialize_config_dir(str(CONFIG_DIR), version_base="1.3"):
        return compose(config_name=name, overrides=overrides)


@pytest.mark.parametrize("name", ["eval", "reproduce"])
def test_evaluation_node_is_the_dataclass_defaults(name):
    cfg = _compose(name, ["checkpoints=[x]"] if name == "eval" else [])
    assert settings_from_config(cfg.evaluation, int(cfg.seed)) == EvalSettings(seed=int(cfg.seed))


def test_evaluation_overrides_reach_the_settings():
    cfg = _compose("reproduce", ["evaluation.samples.variance=2000", "evaluation.segment.max_step_s=1.2", "seed=3"])
    settings = settings_from_config(cfg.evaluation, int(cfg.seed))
    assert settings.samples == SampleCounts(1000, 2000, 1000)
    assert settings.segment.max_step_s == 1.2 and settings.seed == 3


def test_segment_and_follow_nodes_are_the_dataclass_defaults():
    segment = _compose("segment", [])
    assert SegmentSettings.from_dict(OmegaConf.to_container(segment.segment)) == SegmentSettings()
    generate = _compose("generate", ["follow.candidates=3"])
    assert FollowSettings(**OmegaConf.to_container(generate.follow)) == FollowSettings(candidates=3)


@pytest.mark.parametrize(("name", "override"), [("segment", "segment.max_step_s=abc"),
                                                ("segment", "segment.contacts.height_onn=0.1"),
                                                ("generate", "follow.candidates=many"),
                                                ("reproduce", "evaluation.samples.variance=abc")])
def test_a_bad_settings_override_is_refused_naming_the_key(name, override):
    with pytest.raises(ConfigCompositionException, match=override.split("=")[0].replace(".", r"\.")):
        _compose(name, [override])


def test_settings_from_plain_values_name_the_bad_key():
    with pytest.raises(ConfigError, match=r"evaluation\.samples\.variance"):
        settings_from_config({"samples": {"variance": "abc"}}, 0)
    with pytest.raises(ConfigError, match=r"evaluation\.sample"):
        settings_from_config({"sample": 3}, 0)
    built = build_settings(EvalSettings, {"classifier": {"C": 2}}, "evaluation")
    assert asdict(built)["classifier"] == {"components": 32, "C": 2.0}


@pytest.mark.parametrize(("file", "node"), [("segment.yaml", "segment"), ("generate.yaml", "follow"),
                                           ("evaluation/default.yaml", "samples")])
def test_yaml_files_do_not_restate_the_defaults(file, node):
    raw = yaml.safe_load((CONFIG_DIR / file).read_text())
    assert node not in raw, f"{file} restates the defaults of '{node}'; they live in the settings dataclass"


@pytest.mark.parametrize("name", sorted(p.stem for p in CONFIG_DIR.glob("*.yaml")))
def test_each_command_registers_the_schemas_its_config_needs(name):
    """``hydra_command`` registers only ``CONFIG_SCHEMAS[name]`` (importing no other settings module):
    every packaged config composes with just those."""
    from hydra.core.config_store import ConfigStore

    repo = ConfigStore.instance().repo
    saved = repo.pop("schema", None)
    try:
        register_schemas_for(name)
        _compose(name, [])
    finally:
        repo.pop("schema", None)
        if saved is not None:
            repo["schema"] = saved
