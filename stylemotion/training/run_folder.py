"""What later tools read of a finished ``stylemotion-reproduce`` run folder: its ``reproduce.json``
(stages, their checkpoints, overrides and values) and the ``meta`` of its ``report/report.json`` (data
config, seed, evaluation settings). Used by ``stylemotion-style`` (:mod:`stylemotion.style_example`) and
the leave-one-style-out evaluation (:mod:`stylemotion.evaluation.zero_shot`), which each check what
they need of it."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

from stylemotion.evaluation.run import settings_from_config
from stylemotion.evaluation.settings import EvalSettings
from stylemotion.io.jsonfile import JsonFileError, read_json
from stylemotion.synthesis.graph import relocated


def read_json_object(path: Path, what: str, error: type[Exception] = ValueError) -> dict[str, Any]:
    """The JSON object in ``path`` (``what`` names it in messages); ``error`` if unreadable or not an object."""
    try:
        value = read_json(path, what)
    except JsonFileError as exc:
        raise error(f"run={Path(path).parent}: cannot read its {what} {path} ({exc})") from None
    if not isinstance(value, dict):
        raise error(f"run={Path(path).parent}: {path} does not hold a JSON object")
    return value


@dataclass
class FinishedRun:
    """A finished reproduce run.

    Attributes:
        folder: the run folder.
        summary: ``reproduce.json``.
        report: ``report/report.json`` (``{}`` until read).
    """

    folder: Path
    summary: dict[str, Any]
    report: dict[str, Any]

    @property
    def meta(self) -> dict[str, Any]:
        return self.report.get("meta", {})

    @property
    def data_cfg(self) -> dict[str, Any]:
        """The run's ``data`` config node (plain values)."""
        return dict(self.meta["data"])

    @property
    def seed(self) -> int:
        return int(self.meta.get("seed", 0))

    @cached_property
    def settings(self) -> EvalSettings:
        """The run's evaluation settings (segmentation, neutral style, classifier, skating threshold, …)."""
        values = {k: v for k, v in (self.meta.get("settings") or {}).items() if k != "seed"}
        return settings_from_config(values, self.seed)

    def stages(self, kind: str) -> list[dict[str, Any]]:
        """The run's stages of ``kind`` (``autoencoder``, ``vae``, ``cvae``), in its order."""
        return [s for s in self.summary.get("stages") or [] if s.get("kind") == kind]

    def located(self, path: str) -> Path:
        """A path recorded in ``reproduce.json``: relative ones are relative to the run folder; absolute
        ones are found under the folder if it has moved since (:func:`stylemotion.synthesis.graph.relocated`)."""
        recorded = Path(path)
        return Path(relocated(recorded, self.folder)) if recorded.is_absolute() else self.folder / recorded

    @property
    def autoencoder_ckpt(self) -> Path:
        """The run's autoencoder checkpoint (what its VAE and CVAE stages were trained on)."""
        return self.located(self.stages("autoencoder")[0]["checkpoint"])
