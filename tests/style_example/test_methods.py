"""The ``method`` protocol of ``stylemotion-style`` (:class:`Method`): its defaults, the methods' own keys kept
apart (a value for another method's key refused), and how ``report.json`` names a checkpoint."""

from __future__ import annotations

from pathlib import Path

import pytest

from stylemotion.config import ConfigError
from stylemotion.style_example.command import METHODS, check_method, method_options
from stylemotion.style_example.methods import Method, recorded_path


def test_a_method_without_keys_takes_one_step_per_primitive_and_records_nothing_more(tmp_path: Path) -> None:
    method = Method()
    options = {"a": 1}
    prepared = method.prepare(None, ["walk_leftStance"], options)
    assert prepared == options and prepared is not options  # the method's own copy
    assert method.keys == ()
    assert method.steps(["walk_leftStance", "walk_rightStance"], {}) == 2 and method.steps([], {}) == 0
    assert method.report({}, tmp_path, {}) == {} and method.entry("walk_leftStance", []) == {}
    with pytest.raises(NotImplementedError):
        method.make(None, "mine", None, None, tmp_path, print, 1, {})
    with pytest.raises(NotImplementedError):
        method.load(tmp_path / "x.ckpt", "walk_leftStance", [], [], "mine", "normal", None)


def test_every_method_is_a_method_and_no_two_share_a_key() -> None:
    assert set(METHODS) == {"cvae", "zero_shot"}
    assert all(isinstance(m, Method) for m in METHODS.values())
    keys = [k for m in METHODS.values() for k in m.keys]
    assert len(keys) == len(set(keys))
    assert METHODS["cvae"].keys == () and METHODS["zero_shot"].keys == ("network", "network_epochs")
    assert check_method("zero_shot") == "zero_shot"
    with pytest.raises(ConfigError, match=r"method must be one of \['cvae', 'zero_shot'\], got 'gan'"):
        check_method("gan")


def test_a_methods_options_are_its_own_keys_and_others_are_refused() -> None:
    assert method_options("zero_shot", {"network": "/n", "network_epochs": None}) == {"network": "/n",
                                                                                      "network_epochs": None}
    assert method_options("zero_shot", None) == {"network": None, "network_epochs": None}
    assert method_options("cvae", {"network": None, "network_epochs": None}) == {}  # unset keys are no values
    with pytest.raises(ConfigError, match="network_epochs=3 is a key of method=zero_shot, not of method=cvae"):
        method_options("cvae", {"network_epochs": 3})
    with pytest.raises(ConfigError, match=r"colour=red is a key of method=\?, not of method=zero_shot"):
        method_options("zero_shot", {"colour": "red"})


def test_a_checkpoint_inside_the_style_folder_is_recorded_relative_to_it(tmp_path: Path) -> None:
    folder = tmp_path / "tired"
    inside = folder / "cvae" / "walk_leftStance_tired" / "checkpoints" / "best.ckpt"
    assert recorded_path(inside, folder) == "cvae/walk_leftStance_tired/checkpoints/best.ckpt"
    assert recorded_path(str(folder / "network" / ".." / "network" / "a.ckpt"), folder) == "network/a.ckpt"
    outside = tmp_path / "earlier" / "network" / "a.ckpt"
    assert recorded_path(outside, folder) == str(outside.resolve())  # another call's network: absolute
    sibling = tmp_path / "tired_again" / "a.ckpt"  # its name starts with the folder's: still outside
    assert recorded_path(sibling, folder) == str(sibling.resolve())
