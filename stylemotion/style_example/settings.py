"""The settings of ``stylemotion-style``: every key of ``configs/style.yaml`` and its one default.

``configs/style.yaml`` takes :class:`StyleSettings` as its structured config (``- schema@_here_: style``,
:mod:`stylemotion.cli.schemas`) and repeats no value; the keyword defaults of
:func:`stylemotion.style_example.command.add_style` read it. This module imports no numpy or torch, so
``stylemotion-style --help`` stays fast.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from omegaconf import MISSING

from stylemotion.config import MotionFileKeys


@dataclass(frozen=True)
class StyleSettings(MotionFileKeys):
    """Every key of ``stylemotion-style``, with its default.

    ``example``: ``<BVH>[:start-end]``: a file (or ``archive.zip::member.bvh``), optionally frames start to end of
    the FILE's own frame rate, 0-based, end exclusive (``walk.bvh:120-480``); or a list of them, several examples of
    the style (``'example=[a.bvh,b.bvh:0-900]'``, at most 16): every model is conditioned on the clips of all (the
    CVAE's Gram target: their mean Gram matrix; the zero-shot network: their mean embedding). ``run``: a finished
    ``stylemotion-reproduce`` folder: its data, segmentation, CVAE training. ``name``: the new style's name: not a
    style of the run's data nor one of its models. ``out``: a new folder (an existing one is refused); nothing is
    left there on failure. ``method``: how the style's primitive models come about: ``cvae`` = the run's StyleCVAE
    training with the example's clips as the style example; ``zero_shot`` = one zero-shot network per primitive
    bound to the example's clips (no training for the style; the default, chosen on validation clips by suite
    ``zero_shot_centred``: docs/style.md). ``network``: ``method=zero_shot``: the networks, a
    folder with ``<primitive>/checkpoints/best.ckpt`` (``out/network`` of an earlier zero_shot call) or
    ``{primitive: checkpoint}``; None = train them on all the run's styles into ``out/network`` (reusable).
    ``network_epochs``: ``method=zero_shot``, ``network=None``: epochs per network; None =
    ``experiment=zero_shot``'s. ``action``: what the example shows (walk, run); None = the action of the run's
    primitives. ``samples``: samples per model for the report (Table 5.1 row, variation, foot skating). ``seed``:
    sampling seed; None = the run's seed (training always uses the run's seed). ``threads``: torch threads (None =
    torch's default).
    ``joint_map``, ``unit_scale``, ``up_axis``: the example file's (:class:`~stylemotion.config.MotionFileKeys`).
    """

    example: Any = MISSING
    run: str = "runs/reproduce/synthetic"
    name: str = MISSING
    out: str = "runs/style/${name}"
    method: str = "zero_shot"
    network: Any = None
    network_epochs: int | None = None
    action: str | None = None
    samples: int = 1000
    seed: int | None = None
    threads: Any = 1
