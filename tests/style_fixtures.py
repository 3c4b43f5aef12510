"""Shared helpers of the ``stylemotion-style`` tests: an example BVH of a synthetic take, and style folders made
from it (``method=cvae`` and ``method=zero_shot``) on the shared tiny reproduce run — each built once per pytest
process.

The run is conftest's ``tiny_run`` (tests/reproduce_fixtures.py: straight walks of normal, elderly and youthful;
CVAEs of elderly and youthful, both stance primitives so that a walk can be generated); the style folders lie
beside it (``<folder>/../run`` is the run). The example is a synthetic *exhausted* walk
(a style the run's data does not have) written as BVH with :func:`stylemotion.io.export.write_motion_bvh`.
"""

from __future__ import annotations

from pathlib import Path

from log_lines import logged_lines

from stylemotion.cli.schemas import register_schemas
from stylemotion.datasets.synthetic import generate_take
from stylemotion.io.export import write_motion_bvh

register_schemas()  # the configs composed here take structured schemas (stylemotion.cli.schemas)

#: Small samples: the style tests ask for at least this (the report's 1,000 by default).
SAMPLES = 60

_CACHE: dict[str, Path] = {}


def example_bvh(folder: Path, style: str = "exhausted", duration_s: float = 4.0, fps: float = 60.0) -> Path:
    """A synthetic walk of ``style`` as a BVH file at ``fps`` (another rate than the run's 30)."""
    path = folder / f"{style}_walk_{fps:g}fps.bvh"
    if not path.is_file():
        take = generate_take("walk", style, 0, seed=5, fps=fps, duration_s=duration_s)
        write_motion_bvh(take.positions, path, fps)
    return path


def tiny_style(run: Path) -> tuple[Path, dict]:
    """A style folder ``tired`` beside ``run`` (the shared tiny run, conftest's ``tiny_run``) made from
    :func:`example_bvh` (once per process), and what :func:`stylemotion.style_example.add_style` returned."""
    if "style" not in _CACHE:
        from stylemotion.style_example import add_style

        folder = run.parent
        with logged_lines("stylemotion.style_example") as lines:
            results = add_style(str(example_bvh(folder)), run, "tired", folder / "tired", method="cvae",
                                samples=SAMPLES)
        _CACHE["style"], _CACHE["results"], _CACHE["lines"] = folder / "tired", results, lines
    return _CACHE["style"], {"results": _CACHE["results"], "lines": _CACHE["lines"]}


#: Epochs of each zero-shot network the tests train inside the command (the experiment's 100: a minute).
NETWORK_EPOCHS = 2


def tiny_zero_shot_style(run: Path) -> tuple[Path, dict]:
    """A style folder ``weary`` beside ``run`` made from :func:`example_bvh` with ``method=zero_shot``, its
    networks trained inside the command (once per process), and what
    :func:`stylemotion.style_example.add_style` returned and printed."""
    if "zero_shot" not in _CACHE:
        from stylemotion.style_example import add_style

        folder = run.parent
        with logged_lines("stylemotion.style_example") as lines:
            results = add_style(str(example_bvh(folder)), run, "weary", folder / "weary", method="zero_shot",
                                network_epochs=NETWORK_EPOCHS, samples=SAMPLES)
        _CACHE["zero_shot"], _CACHE["zero_shot_results"] = folder / "weary", {"results": results, "lines": lines}
    return _CACHE["zero_shot"], _CACHE["zero_shot_results"]
