"""One tiny finished ``stylemotion-reproduce`` run for the whole test run (the ``tiny_run`` fixture of conftest.py).

The run trains on tiny synthetic data (6 takes of 6 s per style: straight walks of normal, elderly and youthful;
about 20 training clips per stance primitive): the autoencoder, the neutral VAEs of both stance primitives (so that
a walk can be generated) and CVAEs of elderly and youthful (so that a style can be left out), every stage a few
seconds, the VAE/CVAE stages two at a time in worker processes (``workers=2``), then the report. It is trained once
per pytest process into the session's temporary folder; the tests that read a finished run share it, and the ones
that change a run work on a copy (:func:`copy_run`). Tests that test training itself (resuming, ``workers=1``
against ``workers=2``, settings that conflict) build on :func:`tiny_overrides`.
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass, field
from pathlib import Path

import torch
from hydra import compose, initialize_config_dir
from log_lines import logged_lines

from stylemotion.cli.schemas import register_schemas
from stylemotion.config import CONFIG_DIR

register_schemas()  # the configs composed here take structured schemas (stylemotion.cli.schemas)

#: The run's data: 6 takes of 6 s per style (4 train, 1 val, 1 test).
DATA = ["data.takes_per_pair=6", "data.duration_s=6.0", "data.styles=[normal,elderly,youthful]",
        "data.contents=[walk]"]
#: The run's evaluation: small samples (the report's 1,000 by default).
EVAL = ["evaluation.samples.table_5_1=100", "evaluation.samples.variance=300", "evaluation.samples.metrics=100",
        "evaluation.classifier.components=8"]
QUIET = "trainer.enable_progress_bar=false,callbacks.progress_bar=null,trainer.enable_model_summary=false," \
        "trainer.num_sanity_val_steps=0,~logger"
#: The VAE stages keep the configs' progress-bar callback: worker processes must drop it themselves. (The CVAE
#: stages drop it in their overrides, as stylemotion-style's CVAE training in-process then does too.)
QUIET_MODELS = "trainer.enable_model_summary=false,trainer.num_sanity_val_steps=0,~logger"
PRIMITIVES = ("walk_leftStance", "walk_rightStance")
STYLES = ("elderly", "youthful")
#: Epochs of the VAE and CVAE stages; α of the CVAEs (20: the style term must act within 10 epochs).
EPOCHS = 10
STYLE_WEIGHT = 20.0


def stage_list(name: str, items: str) -> str:
    """``stages.<name>=['a=1','b=2']``: a list of overrides as one override (quoted items)."""
    return f"stages.{name}=[" + ",".join(f"'{item}'" for item in items.split(",")) + "]"


def tiny_overrides(out: Path, vae_epochs: int = EPOCHS) -> list[str]:
    """``stylemotion-reproduce`` overrides of the tiny run in ``out`` (add e.g. ``primitives=[…]`` to narrow it:
    its stages then have the same settings as the shared run's, and a copy of those is reused)."""
    return DATA + EVAL + [
        f"out={out}", "threads=1", "workers=2", f"primitives=[{','.join(PRIMITIVES)}]", "styles=null",
        "++budget.stage_samples=true",  # the CVAE stages render their sample GIFs (callbacks.samples)
        stage_list("autoencoder", "experiment=smoke,model.hidden_units=32,trainer.max_steps=40,trainer.max_epochs=20,"
                                  "trainer.limit_train_batches=null,datamodule.window_frames=30,datamodule.stride=15,"
                                  + QUIET),
        stage_list("vae", f"experiment=primitive_vae,trainer.max_epochs={vae_epochs},datamodule.min_train_clips=8,"
                          "callbacks.samples=null," + QUIET_MODELS),
        stage_list("cvae", f"experiment=style_cvae,trainer.max_epochs={EPOCHS},datamodule.min_train_clips=8,"
                           f"callbacks.samples.num_samples=4,model.style_weight={STYLE_WEIGHT}," + QUIET),
    ]


def reproduce(overrides: list[str], lines: list[str] | None = None) -> dict:
    """``stylemotion-reproduce`` in this process (the lines it logs appended to ``lines``); the summary. Torch's
    thread count is restored afterwards (the run sets it to ``threads``)."""
    from stylemotion.training.reproduction import reproduce as run_reproduction

    threads = torch.get_num_threads()
    try:
        with initialize_config_dir(config_dir=str(CONFIG_DIR), version_base="1.3"):
            cfg = compose(config_name="reproduce", overrides=overrides)
            with logged_lines("stylemotion.training.reproduction") as logged:
                try:
                    return run_reproduction(cfg)
                finally:
                    if lines is not None:
                        lines.extend(logged)
    finally:
        torch.set_num_threads(threads)


@dataclass
class TinyRun:
    """The shared finished run: its folder (never change it: see :func:`copy_run`), the summary
    ``reproduce`` returned and the lines it printed."""

    folder: Path
    summary: dict
    lines: list[str] = field(default_factory=list)


_RUN: list[TinyRun] = []


def train_tiny_run(base: Path) -> TinyRun:
    """The shared run, trained into ``base/tiny_run/run`` the first time it is asked for in this process."""
    if not _RUN:
        out = base / "tiny_run" / "run"
        lines: list[str] = []
        summary = reproduce(tiny_overrides(out), lines)
        _RUN.append(TinyRun(out, summary, lines))
    return _RUN[0]


def copy_run(run: TinyRun | Path, dest: Path, parts: tuple[str, ...] | None = None) -> Path:
    """A copy of the run folder at ``dest`` for a test that changes it (``parts``: only these sub-folders, e.g.
    ``("autoencoder", "vae/walk_leftStance")``, as finished stages for a narrower run to reuse)."""
    source = run.folder if isinstance(run, TinyRun) else Path(run)
    if parts is None:
        shutil.copytree(source, dest)
    else:
        for part in parts:
            shutil.copytree(source / part, dest / part)
    return dest
