"""What a reproduction stage was trained with against what its config composes now
(:mod:`stylemotion.training.stage_settings`): changed defaults are found, moved folders and new options at their
old behaviour are not."""

from __future__ import annotations

from omegaconf import OmegaConf

from stylemotion.training.stage_settings import changed_settings, changes_line, config_record, constructor_default

CVAE = "stylemotion.models.cvae.StyleCVAE"


def test_the_record_keeps_what_is_learned_and_leaves_out_where_and_how_fast() -> None:
    cfg = OmegaConf.create({"model": {"_target_": CVAE, "style_weight": 5.0, "fps": "${data.fps}"},
                            "trainer": {"max_epochs": 100, "enable_progress_bar": True},
                            "callbacks": {"progress_bar": {"refresh": 1}, "samples": {"dirpath": "${output_dir}/s"}},
                            "data": {"fps": 30}, "output_dir": "/somewhere", "threads": 2, "seed": 3,
                            "autoencoder_ckpt": "/ae.ckpt", "ckpt_path": "auto", "logger": {"name": "tb"}})
    assert config_record(cfg) == {"model._target_": CVAE, "model.style_weight": 5.0, "model.fps": "${data.fps}",
                                  "trainer.max_epochs": 100, "callbacks.samples.dirpath": "${output_dir}/s"}


def test_a_changed_default_is_named_with_both_values() -> None:
    recorded = {"model._target_": CVAE, "model.style_weight": 5.0, "trainer.max_epochs": 100}
    now = {**recorded, "model.style_weight": 50.0, "trainer.max_epochs": 10}
    assert changed_settings(now, recorded) == ["model.style_weight=5.0 (now 50.0)",
                                               "trainer.max_epochs=100 (now 10)"]
    assert changed_settings(recorded, recorded) == []


def test_a_new_model_option_counts_as_trained_at_its_constructor_default() -> None:
    recorded = {"model._target_": CVAE, "model.style_weight": 5.0, "model.removed_option": 1}
    at_default = {"model._target_": CVAE, "model.style_weight": 5.0, "model.style_duration_weight": 0.0}
    assert changed_settings(at_default, recorded) == []  # the option is new and at the old behaviour; one gone
    other = {**at_default, "model.style_duration_weight": 50.0}
    assert changed_settings(other, recorded) == ["model.style_duration_weight=0.0 (now 50.0)"]
    assert changed_settings({**at_default, "trainer.gradient_clip_val": 1.0}, recorded) == [
        "trainer.gradient_clip_val absent (now 1.0)"]  # outside the model nothing says how it was trained


def test_an_old_record_reads_the_model_keys_against_the_checkpoint() -> None:
    now = {"model._target_": CVAE, "model.style_weight": 5.0, "model.style_duration_weight": 50.0,
           "model.fps": "${data.fps}", "model.not_an_argument": 3, "trainer.max_epochs": 10}
    hparams = {"style_weight": 5.0, "fps": 30.0}  # saved before style_duration_weight existed
    assert changed_settings(now, None, hparams) == ["model.style_duration_weight=0.0 (now 50.0)"]
    assert changed_settings({**now, "model.style_duration_weight": 0}, None, hparams) == []
    assert changed_settings(now, None, {**hparams, "style_weight": 200.0})[0] == "model.style_weight=200.0 (now 5.0)"
    assert changed_settings(now, None, None) == []  # no checkpoint to read: nothing is claimed


def test_constructor_defaults_come_from_the_class_or_its_bases() -> None:
    assert constructor_default(CVAE, "style_duration_weight") == (True, 0.0)
    assert constructor_default(CVAE, "contact_weight")[0]  # a PrimitiveVAE argument
    assert constructor_default(CVAE, "no_such_argument") == (False, None)
    assert constructor_default("stylemotion.models.no_such_module.Model", "x") == (False, None)


def test_many_changes_fit_one_line() -> None:
    assert changes_line(["a", "b", "c", "d", "e"]) == "a; b; c; and 2 more"
