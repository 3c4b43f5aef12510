"""``stylemotion-style 'example=[…]'`` (issue 27): several examples of a style on the tiny synthetic reproduce run,
with the zero-shot networks of an earlier call (no training): the command's config takes the list, every model is
conditioned on the clips of all the examples, the report records each example and measures the example clips of
all, and generate/load bind the same clips again; a list of one is exactly the single-example call; a bad item is
refused naming it, with nothing written (tests/cli/test_style_cli.py: one line)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import torch
from hydra import compose, initialize_config_dir
from log_lines import logged_lines
from style_fixtures import SAMPLES, example_bvh, tiny_zero_shot_style

from stylemotion.config import CONFIG_DIR
from stylemotion.loading import load
from stylemotion.primitives.skating import FootSkating, pooled_skating
from stylemotion.style_example import StyleExampleError, add_style, add_style_from_config
from stylemotion.style_example.evaluate import variation
from stylemotion.synthesis import load_graph

torch.set_num_threads(1)
PRIMITIVES = ("walk_leftStance", "walk_rightStance")


@pytest.fixture(scope="session")
def zero_shot(tiny_run) -> tuple[Path, dict]:
    return tiny_zero_shot_style(tiny_run.folder)


@pytest.fixture(scope="session")
def run(tiny_run) -> Path:
    return tiny_run.folder


def _style(folder: Path, name: str, examples: list[str], run: Path, network: Path) -> dict:
    """A style from ``examples`` through the command's config (the list as a Hydra override), reusing ``network``."""
    with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
        cfg = compose(config_name="style", overrides=[f"example=[{','.join(examples)}]", f"run={run}",
                                                      f"name={name}", f"out={folder / name}", "method=zero_shot",
                                                      f"network={network}", f"samples={SAMPLES}"])
    with logged_lines("stylemotion.style_example") as lines:
        results = add_style_from_config(cfg)
    return {"results": results, "lines": lines}


@pytest.fixture(scope="module")
def two(zero_shot, run, tmp_path_factory) -> tuple[Path, list[str], dict]:
    """A style from two examples (an exhausted walk at 60 fps; frames of an active walk at 30 fps) with the first
    call's networks: its folder, the two examples and what the call returned and logged."""
    folder = tmp_path_factory.mktemp("two_examples")
    examples = [str(example_bvh(folder)), f"{example_bvh(folder, 'active', fps=30.0)}:0-110"]
    made = _style(folder, "pair", examples, run, zero_shot[0] / "network")
    return folder / "pair", examples, made


def test_every_model_takes_the_clips_of_both_examples_and_the_report_records_each(two) -> None:
    out, examples, made = two
    report = json.loads((out / "report.json").read_text())
    assert report == made["results"]
    files = [e.split(":")[0] for e in examples]
    assert [e["file"] for e in report["examples"]] == files and report["example"]["count"] == 2
    assert [e["spec"] for e in report["examples"]] == examples
    assert report["examples"][1]["file_range"] == [0, 110] and report["examples"][1]["file_fps"] == 30.0
    assert [e["saved"] for e in report["examples"]] == ["example/example.npz", "example/example_2.npz"]
    assert all((out / e["saved"]).is_file() for e in report["examples"])
    entries = {e["primitive"]: e for e in report["meta"]["checkpoints"]}
    for p in PRIMITIVES:
        used = report["models"][p]["examples"]
        assert {e["file"] for e in used} == set(files)  # each model is conditioned on both examples' clips
        assert len(used) == sum(e["used_clips"][p] for e in report["examples"])
        assert entries[p]["example"] == ["example/example.npz", "example/example_2.npz"]
        assert sorted({c[2] for c in entries[p]["clips"]}) == [0, 1] and len(entries[p]["clips"]) == len(used)
        # the example's foot skating and variation are over the clips of both examples
        skating = report["foot_skating"][p]
        assert 0 <= skating["samples"]["ratio"] <= 1 and 0 <= skating["example"]["ratio"] <= 1
        assert len(report["table_5_1_columns"][p]["pair"]) == len(used)
        assert report["network"]["sampling"][p]["pooling"] == "per_sample"  # each sample on one clip (the yaml's)
    steps = [line for line in made["lines"] if line.startswith("[")]
    assert steps[0].startswith(f"[1/4] example[1]={examples[0]}: 240 of 240 frames at 60 fps")
    assert f"; example[2]={examples[1]}: 110 of 120 frames at 30 fps" in steps[0]
    assert "2 examples cut with the run's segmentation" in steps[1]
    assert "Examples (every model takes the clips of all)" in (out / "report.md").read_text()


def test_the_example_skating_pools_the_skating_of_each_examples_clips(two, zero_shot, run) -> None:
    """The example column's foot skating of two examples equals the pool of the two single-example reports'."""
    out, examples, _ = two
    report = json.loads((out / "report.json").read_text())
    singles = []
    for i, example in enumerate(examples):
        made = _style(out.parent, f"single{i}", [example], run, zero_shot[0] / "network")
        singles.append(made["results"])
    for p in PRIMITIVES:
        if not all(report["models"][p]["borrowed"] is s["models"][p]["borrowed"] is False for s in singles):
            continue  # a borrowing example pools differently (only where no example has clips of p)
        pooled = pooled_skating([FootSkating(**s["foot_skating"][p]["example"]) for s in singles])
        assert report["foot_skating"][p]["example"]["ratio"] == pytest.approx(pooled.ratio, rel=1e-9)
        assert report["foot_skating"][p]["example"] == pytest.approx(pooled.as_dict(), rel=1e-9, nan_ok=True)


def test_a_list_of_one_example_is_exactly_the_single_example_call(zero_shot, run, tmp_path: Path) -> None:
    bvh = str(example_bvh(tmp_path))
    network = zero_shot[0] / "network"
    listed = _style(tmp_path, "weary", [bvh], run, network)["results"]
    single = add_style(bvh, run, "weary", tmp_path / "single", method="zero_shot", network=str(network),
                       samples=SAMPLES)
    for key in ("table_5_1_row", "variation", "foot_skating", "foot_skating_pooled", "example", "examples"):
        assert listed[key] == single[key], key
    entries = [{k: v for k, v in e.items() if "path" not in k} for e in listed["meta"]["checkpoints"]]
    assert entries == [{k: v for k, v in e.items() if "path" not in k} for e in single["meta"]["checkpoints"]]
    assert all(e["example"] == "example/example.npz" and len(e["clips"][0]) == 2 for e in entries)


def test_generate_and_load_bind_the_clips_of_both_examples_again(two) -> None:
    out, _, made = two
    report = made["results"]
    graph = load_graph("pair", run=out)
    styles = load(out)
    for p in PRIMITIVES:  # the report's samples again: the same clips of both files, pooled the same way
        again = variation(graph.models[p.split("_")[1]].sample(SAMPLES, seed=report["meta"]["seed"]))
        assert again["pose_sd"] == pytest.approx(report["variation"][p]["samples"]["pose_sd"], rel=1e-6)
        loaded = styles.sample(SAMPLES, seed=report["meta"]["seed"], style="pair", primitive=p)
        assert variation(loaded)["v_sd"] == pytest.approx(report["variation"][p]["samples"]["v_sd"], rel=1e-6)


def test_a_loaded_style_samples_as_its_folder_records_not_as_its_checkpoint(two) -> None:
    """The style folder records how stylemotion-style sampled its network (the yaml's settings); loading the style
    applies that record, also where the checkpoint says otherwise (a network= trained before the setting); a folder
    without the record keeps the checkpoint's own; a damaged record is refused naming the style."""
    from stylemotion.synthesis.graph import RunFolderError, available_models, load_bound_style

    out, _, made = two
    entries = {e["primitive"]: e for e in available_models(out) if e["name"] == "pair"}
    for p in PRIMITIVES:
        entry = entries[p]
        assert entry["sampling"] == {"sample_temperature": 1.0, "sample_centred": True, "sample_pooling": "per_sample"}
        assert load_bound_style(entry).pooling == "per_sample"
        mean = {**entry, "sampling": {**entry["sampling"], "sample_pooling": "mean"}}
        bound = load_bound_style(mean)
        assert bound.pooling == "mean" and bound.model.sample_temperature == 1.0 and bound.model.sample_centred
        hot = load_bound_style({**entry, "sampling": {"sample_temperature": 0.5}})
        assert hot.model.sample_temperature == 0.5 and hot.pooling == "per_sample"  # the rest: the checkpoint's
        older = {k: v for k, v in entry.items() if k != "sampling"}
        assert load_bound_style(older).pooling == load_bound_style(older).model.sample_pooling
        with pytest.raises(RunFolderError, match="style pair: its recorded sampling is not usable: sample_pooling"):
            load_bound_style({**entry, "sampling": {"sample_pooling": "median"}})
        with pytest.raises(RunFolderError, match="sample_centred must be true or false, got 'yes'"):
            load_bound_style({**entry, "sampling": {"sample_centred": "yes"}})


def test_a_bad_item_of_the_list_is_refused_naming_it_and_writes_nothing(run: Path, tmp_path: Path) -> None:
    good = str(example_bvh(tmp_path))
    for items, message in (([good, f"{good}:0-20"], rf"^example\[2\]={good}:0-20: no complete step"),
                           ([good] * 17, r"lists 17 examples; at most 16")):
        with pytest.raises(StyleExampleError, match=message):
            add_style(items, run, "mine", tmp_path / "out", samples=10)
        assert not (tmp_path / "out").exists()
