"""A new style from the user's own example clip (``stylemotion-style``; issue 12).

:func:`add_style` converts the user's BVH file like the datasets convert theirs, cuts it into the
primitives of a finished ``stylemotion-reproduce`` run with the run's segmentation, makes the run's
primitive models for the new style (``method=cvae``: a StyleCVAE each, exactly as the run's CVAE stage, with
the user's clips as the style example; ``method=zero_shot``: a zero-shot network each, bound to the user's
clips) and evaluates them against the run's Table 5.1 columns. The folder it writes extends the run for
``stylemotion-generate run=<folder> style=<name>``. Modules: :mod:`.example` (the example), :mod:`.base_run`
(the run), :mod:`.evaluate` (the report's numbers), :mod:`.methods` (what a method does), :mod:`.zero_shot`
(``method=zero_shot``), :mod:`.command` (the whole command and ``method=cvae``). Specification: ``docs/style.md``.

The names below load from their submodules on first use (PEP 562, :func:`stylemotion.lazy_exports`), so a light
submodule of the package loads without the heavy ones.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from stylemotion import lazy_exports

if TYPE_CHECKING:
    from stylemotion.style_example.base_run import NameTakenError, SourceRun, load_run
    from stylemotion.style_example.command import METHODS, add_style, add_style_from_config
    from stylemotion.style_example.example import ExampleSpec, StyleExampleError, convert_example, parse_example


__all__ = ["METHODS", "ExampleSpec", "NameTakenError", "SourceRun", "StyleExampleError", "add_style",
           "add_style_from_config", "convert_example", "load_run", "parse_example"]

__getattr__, __dir__ = lazy_exports(__name__, {
    "NameTakenError": "base_run",
    "SourceRun": "base_run",
    "load_run": "base_run",
    "METHODS": "command",
    "add_style": "command",
    "add_style_from_config": "command",
    "ExampleSpec": "example",
    "StyleExampleError": "example",
    "convert_example": "example",
    "parse_example": "example",
})
