"""Shared helpers of the ``stylemotion-style`` tests: a tiny finished reproduce run, an example BVH of a
synthetic take, and style folders made from it (``method=cvae`` and ``method=zero_shot``) — each built once
per pytest process.

The run is ``stylemotion-reproduce`` on tiny synthetic data (straight walks of normal, elderly and youthful;
CVAEs of elderly only, both stance primitives so that a walk can be generated), every stage a few seconds,
the stages one after the other in this process (``workers=1``). The example is a synthetic *exhausted* walk
(a style the run's data does not have) written as BVH with :func:`stylemotion.io.export.write_motion_bvh`.
"""

from __future__ import annotations

from pathlib import Path

import torch
from hydra import compose, initialize_config_dir

from stylemotion.cli.schemas import register_schemas
from stylemotion.config import CONFIG_DIR
from stylemotion.datasets.synthetic import generate_take
from stylemotion.io.export import write_motion_bvh
from stylemotion.training.reproduction import reproduce

register_schemas()  # the configs composed here take structured schemas (stylemotion.cli.schemas)

#: The run's data: 6 takes of 6 s per style (4 train, 1 val, 1 test): ~20 training clips per primitive.
DATA = ["data.takes_per_pair=6", "data.duration_s=6.0", "data.styles=[normal,elderly,youthful]",
        "data.contents=[walk]"]
QUIET = "trainer.enable_progress_bar=false,callbacks.progress_bar=null,trainer.enable_model_summary=false," \
        "trainer.num_sanity_val_steps=0,~logger"
#: Small samples: the style tests ask for at least this (the report's 1,000 by default).
SAMPLES = 60

_CACHE: dict[str, Path] = {}


def _stage(name: str, items: str) -> str:
    return f"stages.{name}=[" + ",".join(f"'{item}'" for item in items.split(",")) + "]"


def run_overrides(out: Path) -> list[str]:
    """``stylemotion-reproduce`` overrides of the tiny run in ``out``."""
    return DATA + [
        f"out={out}", "threads=1", "workers=1", "primitives=[walk_leftStance,walk_rightStance]", "styles=[elderly]",
        "evaluation.samples.table_5_1=60", "evaluation.samples.variance=100", "evaluation.samples.metrics=60",
        "evaluation.classifier.components=6",
        _stage("autoencoder", "experiment=smoke,model.hidden_units=32,trainer.max_steps=40,trainer.max_epochs=20,"
                              "trainer.limit_train_batches=null,datamodule.window_frames=30,datamodule.stride=15,"
                              + QUIET),
        _stage("vae", "experiment=primitive_vae,trainer.max_epochs=10,datamodule.min_train_clips=8,"
                      "callbacks.samples=null," + QUIET),
        _stage("cvae", "experiment=style_cvae,trainer.max_epochs=10,datamodule.min_train_clips=8,"
                       "callbacks.samples=null,model.style_weight=20.0," + QUIET),
    ]


def tiny_run(folder: Path) -> Path:
    """A finished tiny reproduce run (trained once per process, in ``folder`` the first time)."""
    if "run" not in _CACHE:
        threads = torch.get_num_threads()
        out = folder / "run"
        with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
            reproduce(compose(config_name="reproduce", overrides=run_overrides(out)), say=lambda _: None)
        torch.set_num_threads(threads)
        _CACHE["run"] = out
    return _CACHE["run"]


def example_bvh(folder: Path, style: str = "exhausted", duration_s: float = 4.0, fps: float = 60.0) -> Path:
    """A synthetic walk of ``style`` as a BVH file at ``fps`` (another rate than the run's 30)."""
    path = folder / f"{style}_walk_{fps:g}fps.bvh"
    if not path.is_file():
        take = generate_take("walk", style, 0, seed=5, fps=fps, duration_s=duration_s)
        write_motion_bvh(take.positions, path, fps)
    return path


def tiny_style(folder: Path) -> tuple[Path, dict]:
    """A style folder ``tired`` made from :func:`example_bvh` on :func:`tiny_run` (once per process), and
    what :func:`stylemotion.style_example.add_style` returned."""
    if "style" not in _CACHE:
        from stylemotion.style_example import add_style

        run = tiny_run(folder)
        lines: list[str] = []
        results = add_style(str(example_bvh(folder)), run, "tired", folder / "tired", samples=SAMPLES, say=lines.append)
        _CACHE["style"], _CACHE["results"], _CACHE["lines"] = folder / "tired", results, lines
    return _CACHE["style"], {"results": _CACHE["results"], "lines": _CACHE["lines"]}


#: Epochs of each zero-shot network the tests train inside the command (the experiment's 100: a minute).
NETWORK_EPOCHS = 2


def tiny_zero_shot_style(folder: Path) -> tuple[Path, dict]:
    """A style folder ``weary`` made from :func:`example_bvh` on :func:`tiny_run` with ``method=zero_shot``, its
    networks trained inside the command (once per process), and what
    :func:`stylemotion.style_example.add_style` returned and printed."""
    if "zero_shot" not in _CACHE:
        from stylemotion.style_example import add_style

        run = tiny_run(folder)
        lines: list[str] = []
        results = add_style(str(example_bvh(folder)), run, "weary", folder / "weary", method="zero_shot",
                            network_epochs=NETWORK_EPOCHS, samples=SAMPLES, say=lines.append)
        _CACHE["zero_shot"], _CACHE["zero_shot_results"] = folder / "weary", {"results": results, "lines": lines}
    return _CACHE["zero_shot"], _CACHE["zero_shot_results"]
