"""Settings defaults live once, in their dataclasses: the Hydra configs take them as structured
configs, typed and checked, instead of restating them."""

from __future__ import annotations

from dataclasses import asdict

import pytest
import yaml
from hydra import compose, initialize_config_dir
from hydra.errors import ConfigCompositionException
from omegaconf import OmegaConf

from stylemotion.cli.schemas import (
    CONFIG_SCHEMAS,
    PACKAGES,
    SCHEMAS,
    check_overrides,
    register_schemas,
    register_schemas_for,
)
from stylemotion.config import CONFIG_DIR, ConfigError, build_settings, structured_schema
from stylemotion.config import settings_from_config as config_settings
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


# -- the commands whose own keys are one settings dataclass at the top level of their config (schema@_here_)

TOP_LEVEL = sorted(name for name, schemas in CONFIG_SCHEMAS.items() if any(PACKAGES[s] == "" for s in schemas))
#: What each top-level config needs on the command line to be complete.
REQUIRED = {"search": {"query": "q"}, "reconstruct": {"markers": "m"}, "keyframes": {"keys": "k.json"},
            "texture": {"motion": "m"}, "style": {"example": "e.bvh", "name": "mine"}, "annotate": {}}


def _settings_class(name: str) -> type:
    (schema,) = CONFIG_SCHEMAS[name]
    return SCHEMAS[schema]()


def test_the_top_level_schemas_are_the_six_commands():
    assert TOP_LEVEL == ["annotate", "keyframes", "reconstruct", "search", "style", "texture"]


@pytest.mark.parametrize("name", TOP_LEVEL)
def test_top_level_yaml_holds_no_value_the_dataclass_defines(name):
    """A default cannot drift between the YAML and its dataclass: the YAML has none of the dataclass's keys."""
    raw = yaml.safe_load((CONFIG_DIR / f"{name}.yaml").read_text())
    fields = set(structured_schema(_settings_class(name)).keys())
    assert not fields & set(raw), f"{name}.yaml restates {sorted(fields & set(raw))}; they live in the dataclass"
    where = raw["defaults"].index({"schema@_here_": name})
    assert where < raw["defaults"].index("_self_"), "the YAML's own keys (out's interpolation…) come after the schema"


@pytest.mark.parametrize("name", TOP_LEVEL)
def test_top_level_config_composes_to_the_dataclass_defaults(name):
    cls = _settings_class(name)
    cfg = _compose(name, [f"{k}={v}" for k, v in REQUIRED[name].items()] + ["out=o"])
    plain = OmegaConf.to_container(cfg, resolve=True)
    plain.pop("data", None)
    assert build_settings(cls, plain, "") == cls(**REQUIRED[name], out="o")


def _footer_defaults(name: str) -> dict[str, str]:
    """``key=value`` in the ``== Main keys ==`` part of ``--help`` that state a default: a number, or the first of
    ``a|b|…`` alternatives (a single ``true``/``false``, ``N`` or a ``<placeholder>`` is an example, not a
    default)."""
    help_text = yaml.safe_load((CONFIG_DIR / "hydra" / "help" / f"{name}.yaml").read_text())["footer"]
    keys = help_text.split("== Main keys ==", 1)[1].split("==", 1)[0]
    found = {}
    for token in keys.split():
        key, _, value = token.partition("=")
        plain_key = key.replace(".", "").replace("_", "").isalnum()
        if not value or value == "N" or value.startswith(("<", "[", "'")) or not plain_key:
            continue
        if "|" in value:
            found[key] = value.split("|")[0]
        elif value not in ("true", "false"):
            found[key] = value
    return found


@pytest.mark.parametrize("name", TOP_LEVEL)
def test_help_footers_state_the_dataclass_defaults(name):
    """Every default ``--help`` states is the dataclass's (``model.weights.control=4`` of texture is an example of
    a key without a single default)."""
    defaults = OmegaConf.to_container(structured_schema(_settings_class(name)))
    stated = {k: v for k, v in _footer_defaults(name).items() if k != "model.weights.control"}
    assert stated, f"{name}: no default found in its help footer"
    for key, value in stated.items():
        node = defaults
        for part in key.split("."):
            node = node[part]
        want = yaml.safe_load(value) if value not in ("y", "z") else value
        assert node == want, f"stylemotion-{name} --help states {key}={value}, the dataclass {node!r}"


@pytest.mark.parametrize(("name", "override", "message"), [
    ("search", "k=abc", "k=abc: Value 'abc' of type 'str' could not be converted to Integer"),
    ("search", "export.bogus=1", "export.bogus=1: Key 'bogus' not in 'ExportSettings'"),
    ("annotate", "keyframes.count=many", "keyframes.count=many: "),
    ("reconstruct", "model.variance=x", "model.variance=x: "),
    ("texture", "gif=maybe", "gif=maybe: "),
    ("segment", "segment.max_step_s=abc", "segment.max_step_s=abc: "),
])
def test_a_bad_override_of_a_schema_key_is_one_line_naming_it(name, override, message):
    with pytest.raises(ConfigError) as caught:
        check_overrides(name, ["data.fps=30", "hydra.run.dir=x", "out=o", override])
    assert str(caught.value).startswith(message) and "\n" not in str(caught.value)


@pytest.mark.parametrize("overrides", [["k=5", "export.top=2", "radius=null", "data.contents=[walk]"],
                                       ["k=1,2", "--cfg", "job", "+extra=1", "~radius"], ["bad=[syntax"]])
def test_good_overrides_and_what_hydra_handles_pass_the_check(overrides):
    check_overrides("search", overrides)


def test_a_missing_mandatory_key_is_named():
    with pytest.raises(ConfigError, match="^query: "):
        config_settings({"data": {}, "out": "o"}, _settings_class("search"), "search")
