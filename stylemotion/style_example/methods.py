"""How a new style's primitive models come about: the ``method`` of ``stylemotion-style``.

A :class:`Method` checks its own keys before any work (:meth:`Method.prepare`), makes one checkpoint per
primitive of the example's action (:meth:`Method.make`), loads each as the model the report evaluates
(:meth:`Method.load`) and may add values to ``report.json`` (:meth:`Method.report`) and to the style
folder's ``meta.checkpoints`` entries (:meth:`Method.entry`, what ``stylemotion-generate`` reads).
``stylemotion.style_example.command.METHODS`` maps each ``method`` to one.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from stylemotion.models.loading import EvalModel
from stylemotion.primitives.segmentation import Clip

#: Prints one ``[k/N]`` progress line of the command (``command.Progress``).
ProgressLine = Callable[[str], None]


class Method:
    """The steps a method takes (defaults: no keys of its own, one progress line per primitive, nothing more
    to record).

    Attributes:
        keys: the method's own keys of the command (given values of another method's keys are refused).
    """

    keys: tuple[str, ...] = ()

    def prepare(self, run, primitives: Sequence[str], options: Mapping[str, Any]) -> dict[str, Any]:
        """Check the method's ``options`` (its :attr:`keys`) against the run before any work; returns them as
        :meth:`make` takes them.

        Raises:
            StyleExampleError, ConfigError: a value the method cannot use (nothing is written then).
        """
        return dict(options)

    def steps(self, primitives: Sequence[str], options: Mapping[str, Any]) -> int:
        """Progress lines :meth:`make` prints for ``primitives``."""
        return len(primitives)

    def make(self, run, name: str, examples, cut, folder: Path, progress: ProgressLine, threads: Any,
             options: Mapping[str, Any]) -> dict[str, Path]:
        """The style's checkpoints, primitive → file (made in ``folder``, or taken from elsewhere); ``examples``: the
        converted examples, ``cut``: their pooled clips (:func:`.example.cut_examples`)."""
        raise NotImplementedError

    def load(self, checkpoint: Path, primitive: str, clips: Sequence[Clip], records: Sequence[Mapping[str, Any]],
             name: str, neutral_style: str, autoencoder) -> EvalModel:
        """The model of ``primitive`` the report evaluates, from its ``checkpoint`` and the example ``clips`` (of
        every example; ``records``: plain values of each clip in the user's file)."""
        raise NotImplementedError

    def report(self, models: Mapping[str, EvalModel], folder: Path, options: Mapping[str, Any]) -> dict[str, Any]:
        """Further ``report.json`` values of the method (none by default)."""
        return {}

    def entry(self, primitive: str, clips: Sequence[Clip], origin: Sequence[int] = (), examples: int = 1
              ) -> dict[str, Any]:
        """Further values of ``primitive``'s entry in ``meta.checkpoints`` (none by default); ``origin``: the example
        (0-based) of each clip, of ``examples`` in all."""
        return {}


def recorded_path(path: str | os.PathLike, folder: Path) -> str:
    """How ``report.json`` names a checkpoint: relative to the style ``folder`` (``/`` separated) when inside
    it, else absolute (e.g. a network made by an earlier call)."""
    resolved, root = Path(path).resolve(), folder.resolve()
    return resolved.relative_to(root).as_posix() if resolved.is_relative_to(root) else str(resolved)
