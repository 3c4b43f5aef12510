"""The finished ``stylemotion-reproduce`` run a new style extends.

From its folder: ``reproduce.json`` (every stage finished, with the Hydra overrides and values its
training stages were composed from), ``report/report.json`` (the data config, the seed, the
evaluation settings, the models it evaluated). A new style's models are trained with the train
config of the run's CVAE stage of the same primitive (:func:`train_config`, through
:func:`stylemotion.training.reproduction.stage_train_config`, the function the run's own stages went
through): same overrides (experiment, budget epochs, ``model.style_weight``, …), data, seed and
autoencoder; only the style and the output folder differ.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from omegaconf import DictConfig, open_dict

from stylemotion.io.outputs import safe_name
from stylemotion.models.loading import NEUTRAL, EvalModel, load_model
from stylemotion.primitives.segmentation import parse_primitive
from stylemotion.style_example.example import StyleExampleError
from stylemotion.synthesis.graph import STYLE_FOLDER_KIND as STYLE_KIND
from stylemotion.synthesis.graph import available_models
from stylemotion.training.reproduction import stage_train_config
from stylemotion.training.run_folder import FinishedRun, read_json_object

#: Stage statuses of a finished stage in ``reproduce.json``.
FINISHED = ("trained", "reused", "resumed")


class NameTakenError(StyleExampleError):
    """The new style's name is a style of the run's data or the name of one of its models."""


class SourceRun(FinishedRun):
    """A finished reproduce run (see the module doc and :class:`stylemotion.training.run_folder.FinishedRun`);
    build it with :func:`load_run`."""

    @property
    def primitives(self) -> list[str]:
        """The run's primitives, in its order."""
        return [str(s["values"]["primitive"]) for s in self.stages("vae")]

    @property
    def data_styles(self) -> list[str]:
        return list(self.summary.get("data", {}).get("styles") or [])

    @property
    def model_names(self) -> list[str]:
        """Names of the run's models: ``neutral`` and every style with CVAEs."""
        return sorted({e["name"] for e in self.meta.get("checkpoints", [])} | {NEUTRAL})

    @property
    def command(self) -> str:
        return str(self.summary.get("provenance", {}).get("command") or "stylemotion-reproduce …")

    def cvae_stage(self, primitive: str) -> dict[str, Any]:
        """The run's first CVAE stage of ``primitive`` (any CVAE stage if it has none of that primitive)."""
        stages = self.stages("cvae")
        return next((s for s in stages if s["values"].get("primitive") == primitive), stages[0])

    def models(self, primitive: str, autoencoder=None) -> list[EvalModel]:
        """The run's models of ``primitive`` (neutral VAE and style CVAEs), loaded on the CPU."""
        return [load_model(e["path"], self.settings.neutral_style, autoencoder) for e in available_models(self.folder)
                if e["primitive"] == primitive]


def _read_json(path: Path, what: str) -> dict[str, Any]:
    return read_json_object(path, what, StyleExampleError)


def load_run(folder: str | Path) -> SourceRun:
    """The finished reproduce run in ``folder``.

    Raises:
        StyleExampleError: no such folder, a ``stylemotion-style`` folder, no ``reproduce.json``, a stage not
            finished or whose checkpoint is gone, no report, no CVAE stage to copy, or a run recorded before
            stages recorded their overrides (each message says what to do).
    """
    folder = Path(folder).expanduser()
    if not folder.is_dir():
        raise StyleExampleError(f"run={folder} does not exist: point run= at a finished stylemotion-reproduce "
                                "folder (e.g. runs/reproduce/synthetic)")
    own = folder / "report.json"
    if own.is_file() and _read_json(own, "report").get("meta", {}).get("kind") == STYLE_KIND:
        base = _read_json(own, "report")["meta"].get("run")
        raise StyleExampleError(f"run={folder} is a stylemotion-style folder; give the stylemotion-reproduce run "
                                f"it extends (run={base})")
    if not (folder / "reproduce.json").is_file():
        raise StyleExampleError(f"run={folder} is not a stylemotion-reproduce folder: it has no reproduce.json")
    summary = _read_json(folder / "reproduce.json", "summary")
    run = SourceRun(folder, summary, {})
    stages = summary.get("stages") or []
    unfinished = [s.get("name") for s in stages if s.get("status") not in FINISHED or not s.get("checkpoint")
                  or not run.located(s["checkpoint"]).is_file()]
    report = folder / "report" / "report.json"
    if not stages or unfinished or "report" not in summary or not report.is_file():
        what = (f"stage(s) {unfinished} have no finished checkpoint" if unfinished
                else "it has no training stage" if not stages else f"it has no report ({report})")
        raise StyleExampleError(f"run={folder} is not a finished stylemotion-reproduce run: {what}. Finish it by "
                                f"running its command again ({run.command}); finished stages are reused")
    run.report = _read_json(report, "report")
    cvae = [s for s in stages if s.get("kind") == "cvae"]
    if not cvae:
        raise StyleExampleError(f"run={folder} trained no style CVAE, so there are no CVAE training settings to "
                                "train the new style with; use a run with at least one style (styles=null)")
    if any("overrides" not in s or "values" not in s for s in cvae):
        raise StyleExampleError(f"run={folder} was recorded before reproduce.json kept each stage's training "
                                f"overrides; run its command again ({run.command}) to record them: every finished "
                                "stage is reused, nothing is retrained")
    if not run.meta.get("data"):
        raise StyleExampleError(f"run={folder}: {report} records no data config (meta.data)")
    return run


def check_name(name: Any, run: SourceRun) -> str:
    """``name`` if it can name a new style of ``run``.

    Raises:
        StyleExampleError: empty, or not usable as a file name as it is (letters, digits, ``._+-``).
        NameTakenError: a style of the run's data, its neutral style, or one of its models' names.
    """
    text = "" if name is None else str(name).strip()
    try:
        safe = safe_name(text, "name")
    except ValueError:
        safe = None
    if not text or safe != text:
        raise StyleExampleError(f"name={name!r} cannot name a style: use letters, digits and ._+- only (it names "
                                "folders and the generate command's style=)")
    taken = {s: "a style of the run's data" for s in run.data_styles}
    taken.update({s: "a model of the run" for s in run.model_names})
    taken[run.settings.neutral_style] = "the run's neutral style"
    if text in taken or text.lower() in {t.lower() for t in taken}:
        clash = next(t for t in taken if t.lower() == text.lower())
        raise NameTakenError(f"name={text} is taken: {clash!r} is {taken[clash]} in run={run.folder} (taken: "
                             f"{sorted(taken)}); choose another name")
    return text


def run_action(run: SourceRun, action: str | None) -> str:
    """The action the example is segmented as: ``action``, or the one action of the run's primitives.

    Raises:
        StyleExampleError: ``action`` is not an action of the run's primitives, or it is None and they have several.
    """
    actions = sorted({parse_primitive(p)[0] for p in run.primitives})
    if action is None:
        if len(actions) != 1:
            raise StyleExampleError(f"the run's primitives {run.primitives} are of several actions {actions}: say "
                                    "which one the example shows with action=<one of them>")
        return actions[0]
    if action not in actions:
        raise StyleExampleError(f"action={action} is none of the actions of the run's primitives {actions}")
    return str(action)


def train_config(run: SourceRun, primitive: str, style: str, folder: Path, threads: Any = None) -> DictConfig:
    """The ``train`` config of the new style's model of ``primitive`` (see the module doc), starting afresh
    in ``folder``."""
    stage = run.cvae_stage(primitive)
    values = {**stage["values"], "primitive": primitive, "style": style}
    cfg = stage_train_config(stage["overrides"], values, run.data_cfg, folder, run.seed, threads,
                             str(run.autoencoder_ckpt))
    with open_dict(cfg):
        cfg.ckpt_path = None
    return cfg
