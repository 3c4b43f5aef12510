"""The reproduction (what ``stylemotion-reproduce`` runs): data → autoencoder → VAEs → CVAEs → evaluation.

    stylemotion-reproduce                                   # the embedded synthetic data, a few minutes
    stylemotion-reproduce data=bandai 'data.contents=[walk,walk-turn-left,walk-turn-right]'
    stylemotion-reproduce data=bandai ... out=runs/reproduce/bandai_2   # a second, independent run

Stages, each in its own folder under ``out`` (default ``runs/reproduce/<data name>``):

1. ``data``: build (or load from the cache) the dataset, segment it, count the clips of each
   primitive and style (``data.json``);
2. ``autoencoder``: ``stylemotion-train`` with ``stages.autoencoder`` overrides (default
   ``experiment=autoencoder``) on all takes of the data;
3. ``vae/<primitive>``: the neutral PrimitiveVAE of each primitive (``experiment=primitive_vae``);
4. ``cvae/<primitive>_<style>``: a StyleCVAE per primitive and style (``experiment=style_cvae``);
5. ``report`` (or ``report=<name>``: another report of the same stages, e.g. under other ``evaluation.*``
   settings, recorded in ``evaluation_<name>.json``): ``stylemotion-eval`` of all of them
   (:mod:`stylemotion.evaluation.run`); with
   ``morphable=true`` also the Morphable Graph's neutral models (fitted into ``morphable/<primitive>/``,
   :mod:`stylemotion.morphable.rows`) as extra rows of Tables 5.1–5.3.

Each training stage composes the ``train`` config with its overrides, takes this command's ``data``
node, and runs :func:`stylemotion.training.run`: the autoencoder in this process, then the VAEs and
CVAEs (which need only the autoencoder) on the ``executor``: ``pool`` (default) runs them
``workers`` at a time, each in a spawned process with ``threads`` torch threads (``workers=1``: all
in this process, one after the other); ``local`` and ``slurm`` submit each as a submitit job (the
engine of ``hydra/launcher=slurm``; ``local`` runs ``workers`` jobs at a time on this machine,
``slurm`` submits all and lets the cluster schedule them). Every stage that finishes is recorded,
even if another one fails. A stage that finished writes
``done.json`` (its checkpoint, metrics, seconds and a hash of its settings, including the hash of
the stage it builds on); a rerun **reuses** it, and a stage interrupted mid-training **resumes**
from its ``checkpoints/last.ckpt``. A stage whose recorded settings differ from the current ones
stops the run with an error (choose another ``out`` or delete that stage's folder) — results are
never overwritten silently. ``reproduce.json`` under ``out`` summarizes the stages (each with the Hydra
overrides and values it was composed from, which ``stylemotion-style`` trains a new style with).

Training lengths come from ``configs/budget/<data config name>.yaml``, or from
``budget/default.yaml`` (Bandai's) for data without a budget of its own; the first line says which.
Paths recorded in ``reproduce.json``, ``done.json``, ``evaluation.json`` and the report that point
inside ``out`` are relative to ``out``, so a moved run folder describes itself (and resumes).
"""

from __future__ import annotations

import hashlib
import json
import logging
import multiprocessing
import os
import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from hydra import compose
from omegaconf import DictConfig, OmegaConf, open_dict

from stylemotion.config import ConfigError, positive_int, set_torch_threads  # also registers the configs' resolvers
from stylemotion.datasets import build_dataset, data_config_key
from stylemotion.evaluation.run import recorded_path, run_evaluation, settings_from_config, summary_lines
from stylemotion.io.errors import OutputWriteError, UserInputError
from stylemotion.io.jsonfile import JsonFileError, json_text, read_json_object, write_json
from stylemotion.io.outputs import check_new_output, inside, safe_name
from stylemotion.primitives.actions import segment_actions
from stylemotion.primitives.segmentation import SegmentSettings, parse_primitive
from stylemotion.provenance import provenance
from stylemotion.training.stage_settings import changed_settings, changes_line, config_record

log = logging.getLogger(__name__)


#: Where the VAE/CVAE stages run (``executor.engine``): this machine's process pool, or submitit jobs.
ENGINES = ("pool", "local", "slurm")
#: Names in a run folder that a report (``report=<name>``) may not take.
RUN_PARTS = ("autoencoder", "vae", "cvae", "morphable", "hydra", "data.json", "reproduce.json", "evaluation.json")
#: Seconds between looks at running submitit jobs.
POLL_SECONDS = 2.0


class StageConflictError(UserInputError, RuntimeError):
    """A stage folder holds results of different settings than the current run's."""


@dataclass
class Stage:
    """One step of the reproduction.

    Attributes:
        kind: ``autoencoder``, ``vae`` or ``cvae``.
        name: display name (e.g. ``cvae walk_leftStance/elderly``).
        folder: its output folder.
        overrides: Hydra overrides of the ``train`` config.
        values: config values set after composing (primitive, style, autoencoder_ckpt).
        parent: the stage whose checkpoint it builds on.
    """

    kind: str
    name: str
    folder: Path
    overrides: list[str]
    values: dict[str, Any] = field(default_factory=dict)
    parent: Stage | None = None
    status: str = "pending"
    checkpoint: str | None = None
    seconds: float = 0.0
    metrics: dict[str, Any] = field(default_factory=dict)
    settings_hash: str = ""
    config: dict[str, Any] = field(default_factory=dict)


def _hash(payload: Any) -> str:
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=str).encode()).hexdigest()[:16]


def check_out_folder(out: str | Path) -> Path:
    """``out`` as a Path, refused in one line (:class:`~stylemotion.io.errors.OutputWriteError` naming ``out``)
    when it is a file, lies below a file or in a read-only folder; an existing folder is a run to resume."""
    path = Path(str(out)).expanduser()
    if path.exists() and not path.is_dir():
        raise OutputWriteError(f"out={path} is a file, not a folder; the reproduction writes a folder of stages "
                               "there: choose another out=…")
    return path if path.is_dir() else check_new_output(path, key="out")


class Reproduction:
    """The stages of one reproduction run (see the module doc) and their execution.

    Args:
        cfg: the composed ``reproduce`` config.
    """

    def __init__(self, cfg: DictConfig):
        self.cfg = cfg
        self.out = Path(str(cfg.out)).expanduser()
        self.data_cfg = OmegaConf.to_container(cfg.data, resolve=True)
        self.primitives = [str(p) for p in cfg.primitives]
        for p in self.primitives:
            try:
                parse_primitive(p)
            except ValueError as exc:
                raise ConfigError(f"primitives: {exc}") from None
        self.provenance = provenance()  # version, commit and command of this run (in reproduce.json)
        self.started = time.perf_counter()
        self.stages: list[Stage] = []
        self.data_summary: dict[str, Any] = {}
        self.evaluated = False  # whether this run (re)computed the report

    # -- stages

    def total_steps(self) -> int:
        return len(self.stages) + 2

    def _line(self, step: int, text: str) -> None:
        elapsed = time.perf_counter() - self.started
        log.info(f"[{step}/{self.total_steps()}] {text}  (at {elapsed / 60:.1f} min)")

    def plan(self, styles: Sequence[str]) -> None:
        """The training stages for the primitives and ``styles`` (called by :meth:`data_stage`)."""
        stages_cfg = self.cfg.stages
        # budget.stage_samples false: no sample GIF per VAE/CVAE stage (the report shows samples)
        no_gif = [] if self.cfg.budget.stage_samples else ["callbacks.samples=null"]
        ae = Stage("autoencoder", "autoencoder", self.out / "autoencoder", list(stages_cfg.autoencoder))
        self.stages = [ae]
        for p in self.primitives:
            self.stages.append(Stage("vae", f"vae {p}", self.out / "vae" / p, list(stages_cfg.vae) + no_gif,
                                     {"primitive": p}, ae))
        folders: dict[Path, str] = {}
        for p in self.primitives:
            for s in styles:
                try:
                    folder = inside(self.out, "cvae", f"{p}_{safe_name(s, 'style label')}")
                except ValueError as exc:
                    raise ConfigError(f"styles: {exc}; rename it in the data's labels") from None
                if folder in folders:
                    raise ConfigError(f"style labels {folders[folder]!r} and {s!r} would share the folder {folder}; "
                                     "rename one in the data's labels")
                folders[folder] = s
                self.stages.append(Stage("cvae", f"cvae {p}/{s}", folder, list(stages_cfg.cvae) + no_gif,
                                         {"primitive": p, "style": s}, ae))

    def data_stage(self) -> None:
        """Build and segment the data, count its clips, and plan the training stages."""
        t0 = time.perf_counter()
        takeset = build_dataset(self.data_cfg)
        settings = SegmentSettings.from_dict(dict(self.cfg.evaluation.get("segment") or {}))
        seg = segment_actions(takeset.takes, [parse_primitive(p)[0] for p in self.primitives], settings)
        counts = Counter((f"{c.action}_{c.primitive}", c.style) for c in seg.clips)
        styles = takeset.label_values("style")
        neutral = str(self.cfg.evaluation.neutral_style)
        if neutral not in styles:
            raise ConfigError(f"evaluation.neutral_style: the neutral style {neutral!r} is not in dataset "
                              f"{takeset.name!r} (styles {styles}); set evaluation.neutral_style")
        wanted = [s for s in (self.cfg.styles if self.cfg.styles is not None else styles) if s != neutral]
        missing = [s for s in wanted if s not in styles]
        if missing:
            raise ConfigError(f"styles: {missing} are not in dataset {takeset.name!r} (styles {styles}); "
                              "set styles=[…] to some of them, or styles=null for all")
        empty = [p for p in self.primitives if not any(counts[(p, s)] for s in styles)]
        if empty:
            raise ConfigError(f"primitives: {empty} have no clips in dataset {takeset.name!r} "
                              f"(contents {sorted({t.content for t in takeset.takes})}); choose others")
        self.data_summary = {"name": takeset.name, "takes": len(takeset), "frames": takeset.num_frames,
                             "styles": styles, "cvae_styles": wanted,
                             "clips": {p: {s: counts[(p, s)] for s in styles} for p in self.primitives},
                             "seconds": time.perf_counter() - t0}
        self.plan(wanted)
        self._line(1, f"data: {takeset.name}, {len(takeset)} takes, {takeset.num_frames} frames; CVAE styles {wanted}")
        for p in self.primitives:
            log.info("    " + p + " clips: " + ", ".join(f"{s} {counts[(p, s)]}" for s in styles))
        self._keep_or_write_data_summary()

    def _keep_or_write_data_summary(self) -> None:
        """Write ``data.json`` unless the run already holds the same summary (its ``seconds`` aside): a rerun
        into an existing run touches none of its files before its stages are accepted."""
        path = self.out / "data.json"

        def same(summary: Any) -> str:
            return json_text({k: v for k, v in summary.items() if k != "seconds"} if isinstance(summary, dict)
                             else summary)

        try:
            kept = json.loads(path.read_text()) if path.is_file() else None
        except (OSError, ValueError):
            kept = None
        if kept is None or same(kept) != same(json.loads(json_text(self.data_summary))):
            write_json(path, self.data_summary)

    def prepare_stage(self, index: int, stage: Stage) -> bool | None:
        """Hash ``stage``'s settings, refuse a folder of other settings, reuse a finished stage.

        Returns None when the stage was reused, else whether it resumes from ``last.ckpt``.
        """
        parent_hash = stage.parent.settings_hash if stage.parent else None
        stage.settings_hash = _hash({"overrides": stage.overrides, "values": stage.values,
                                     "data": data_config_key(self.data_cfg),
                                     "seed": int(self.cfg.seed), "parent": parent_hash})
        done, started = stage.folder / "done.json", stage.folder / "stage.json"
        last = stage.folder / "checkpoints" / "last.ckpt"
        has_results = done.is_file() or any((stage.folder / "checkpoints").glob("*.ckpt"))
        remedy = f"delete {stage.folder} to train the {stage.name} stage again"
        stage.config = config = config_record(self.train_config(stage, False))
        for record_path in (done, started):
            if record_path.is_file() and has_results:  # a stage that saved nothing is simply started again
                record = read_json_object(record_path, f"{stage.name} stage's record", remedy)
                if record.get("settings_hash") != stage.settings_hash:
                    raise StageConflictError(
                        f"{stage.folder} holds the {stage.name} stage of a run with other settings (hash "
                        f"{record.get('settings_hash')}, now {stage.settings_hash}: overrides, data, seed or an "
                        f"earlier stage changed). Choose another out=… or delete {stage.folder} to train it again")
                self.check_trained_config(stage, record, config, done if record_path == done else last)
        if done.is_file():
            record = read_json_object(done, f"{stage.name} stage's record", remedy)
            checkpoint, seconds = record.get("checkpoint"), record.get("seconds", 0.0)
            metrics = record.get("metrics", {})
            if not (isinstance(checkpoint, (str, type(None))) and isinstance(seconds, (int, float))
                    and not isinstance(seconds, bool) and isinstance(metrics, dict)):
                raise JsonFileError(f"{done}: the {stage.name} stage's record has a checkpoint, seconds or metrics of "
                                    f"the wrong type; {remedy}")
            checkpoint = self.located(checkpoint)
            if checkpoint and Path(checkpoint).is_file():
                stage.status, stage.checkpoint = "reused", checkpoint
                stage.seconds, stage.metrics = float(seconds), metrics
                self._line(index, f"{stage.name}: reused {stage.checkpoint}")
                return None
        resume = last.is_file()
        self._line(index, f"{stage.name}: {'resuming from ' + str(last) if resume else 'training'}")
        write_json(started, {"settings_hash": stage.settings_hash, "name": stage.name, "config": config})
        stage.folder.mkdir(parents=True, exist_ok=True)
        return resume

    def check_trained_config(self, stage: Stage, record: dict[str, Any], config: dict[str, Any],
                             source: Path) -> None:
        """Refuse ``stage`` (:class:`StageConflictError`) when what it was trained with differs from ``config``, its
        composed config now (:mod:`stylemotion.training.stage_settings`); ``record``: its ``done.json`` or
        ``stage.json``, ``source``: that file (for a record without a config, the checkpoint's settings are read)."""
        from stylemotion.models.checkpoints import checkpoint_hparams

        recorded = record.get("config")
        hparams = None
        if recorded is not None and not isinstance(recorded, dict):
            raise JsonFileError(f"{source}: the {stage.name} stage's recorded config is not an object; delete "
                                f"{stage.folder} to train it again")
        if recorded is None:
            checkpoint = self.located(record.get("checkpoint")) if source.name == "done.json" else str(source)
            if checkpoint and isinstance(checkpoint, str) and Path(checkpoint).is_file():
                hparams = checkpoint_hparams(checkpoint)
        changes = changed_settings(config, recorded, hparams)
        if changes:
            raise StageConflictError(
                f"{stage.folder} holds the {stage.name} stage trained with other settings than the config gives now "
                f"(a default in the configs changed): {changes_line(changes)}. Choose another out=… or delete "
                f"{stage.folder} to train it again")

    def finish_stage(self, stage: Stage, metrics: dict[str, Any], resume: bool, seconds: float) -> None:
        """Record a trained stage's checkpoint, metrics and time in its ``done.json``."""
        last = stage.folder / "checkpoints" / "last.ckpt"
        ckpt = metrics.get("best_checkpoint") or (str(last) if last.is_file() else None)
        if not ckpt:
            raise RuntimeError(f"stage {stage.name} finished without a checkpoint in {stage.folder / 'checkpoints'}")
        stage.status, stage.checkpoint = ("resumed" if resume else "trained"), str(Path(ckpt).resolve())
        stage.seconds = seconds
        stage.metrics = {k: v for k, v in metrics.items() if k in ("test", "best_score", "global_step", "epoch")}
        write_json(stage.folder / "done.json", {"settings_hash": stage.settings_hash,
                                                 "checkpoint": self.recorded(stage.checkpoint),
                                                 "seconds": stage.seconds, "metrics": stage.metrics,
                                                 "name": stage.name, "config": stage.config})
        test = stage.metrics.get("test", {})
        shown = ", ".join(f"{k} {v:.4g}" for k, v in test.items() if isinstance(v, float))
        log.info(f"    {stage.name} done in {stage.seconds / 60:.1f} min" + (f": {shown}" if shown else ""))

    def run_stage(self, index: int, stage: Stage, threads: Any = None) -> None:
        """Train ``stage`` in this process (or reuse/resume it), with ``threads`` torch threads (None: the run's
        ``threads``)."""
        from stylemotion.training.fit import run as train_run

        resume = self.prepare_stage(index, stage)
        if resume is None:
            return
        t0 = time.perf_counter()
        result = train_run(self.train_config(stage, resume, threads))
        self.finish_stage(stage, result["metrics"], resume, time.perf_counter() - t0)

    def run_stages_in_parallel(self, indexed: Sequence[tuple[int, Stage]], workers: int) -> None:
        """Train independent stages on the configured executor (see the module doc): fresh processes
        (``threads`` torch threads each, no progress bars) or submitit jobs. Every stage that
        finishes is recorded even if another one fails; then the first failure is raised."""
        jobs: list[tuple[Stage, bool, dict[str, Any]]] = []
        for index, stage in indexed:
            resume = self.prepare_stage(index, stage)
            if resume is not None:
                jobs.append((stage, resume, self.worker_config(stage, resume)))
        errors: list[tuple[Stage, BaseException]] = []
        engine = executor_engine(self.cfg)
        finished = _pool_results(jobs, workers) if engine == "pool" else \
            _submitit_results(jobs, self.cfg.executor, None if engine == "slurm" else workers)
        for stage, resume, outcome in finished:
            try:
                metrics, seconds = outcome()
                self.finish_stage(stage, metrics, resume, seconds)
            except Exception as exc:  # noqa: BLE001 - reported below, after the others are recorded
                log.info(f"    {stage.name} FAILED: {type(exc).__name__}: {exc}")
                errors.append((stage, exc))
            write_json(self.out / "reproduce.json", self.summary())
        if errors:
            names = ", ".join(stage.name for stage, _ in errors)
            raise RuntimeError(f"{len(errors)} training stage(s) failed ({names}); rerun to resume") from errors[0][1]

    def worker_config(self, stage: Stage, resume: bool) -> dict[str, Any]:
        """:meth:`train_config` resolved to plain values for another process, without progress bars
        (interleaved bars of several processes would be unreadable)."""
        cfg = self.train_config(stage, resume)
        with open_dict(cfg):
            cfg.trainer.enable_progress_bar = False
            if cfg.get("callbacks") and "progress_bar" in cfg.callbacks:
                cfg.callbacks.progress_bar = None
        return OmegaConf.to_container(cfg, resolve=True)

    def train_config(self, stage: Stage, resume: bool, threads: Any = None) -> DictConfig:
        """The ``train`` config of ``stage``: its overrides, this run's data, seed, threads (``threads``, else the
        run's ``threads``) and folder."""
        return stage_train_config(stage.overrides, stage.values, self.data_cfg, stage.folder, int(self.cfg.seed),
                                  threads if threads is not None else self.cfg.get("threads"),
                                  stage.parent.checkpoint if stage.parent else None)

    def evaluation_stage(self) -> dict[str, Any]:
        """Evaluate every trained model into ``<out>/<report>`` (or reuse the report of the same stages and
        evaluation settings)."""
        report, record = self.report_folder(), self.evaluation_record()
        step = self.total_steps()
        morphable = bool(self.cfg.get("morphable", False))
        evaluation = OmegaConf.to_container(self.cfg.evaluation, resolve=True)
        if evaluation.get("style_truth") == "all":
            del evaluation["style_truth"]  # the default: the hash of reports made before the key existed
        settings_hash = _hash({"stages": [s.settings_hash for s in self.stages], "seed": int(self.cfg.seed),
                               "evaluation": evaluation,
                               **({"morphable": True} if morphable else {})})  # off: the hash of earlier runs
        if report.exists():
            remedy = f"delete {report} to evaluate again"
            recorded = read_json_object(record, "evaluation record", remedy).get("settings_hash") if record.is_file() \
                else None
            if recorded != settings_hash or not (report / "report.json").is_file():
                raise StageConflictError(
                    f"{report} holds a report of other models or settings (a stage was retrained, or the evaluation "
                    f"settings changed); delete {report} to evaluate again, or choose another out=…")
            self._line(step, f"evaluation: reused {report}")
            return read_json_object(report / "report.json", "evaluation report", remedy)
        self._line(step, f"evaluation → {report}")
        models = [s.checkpoint for s in self.stages if s.kind in ("vae", "cvae")]
        ae = next(s.checkpoint for s in self.stages if s.kind == "autoencoder")
        command = "stylemotion-reproduce " + " ".join(sys.argv[1:])
        extra = self.morphable_rows() if morphable else None
        results = run_evaluation(self.cfg.data, models, self.cfg.evaluation, report, int(self.cfg.seed),
                                 autoencoder_ckpt=ae, command=command,
                                 root=self.out, extra_rows=extra)
        write_json(record, {"settings_hash": settings_hash, "report": self.recorded(report)})
        self.evaluated = True
        return results

    def report_folder(self) -> Path:
        """``<out>/<report>``: where the evaluation writes (``report``, a folder name; default ``report``)."""
        name = str(self.cfg.get("report") or "report")
        try:
            usable = safe_name(name, "report") == name
        except ValueError:
            usable = False
        if not usable or name in RUN_PARTS:
            raise ConfigError(f"report: {name!r} is not a report folder name (letters, digits and ._+- only, not one "
                              f"of the run's own {list(RUN_PARTS)}); choose e.g. report=report_test")
        try:
            return inside(self.out, name)
        except ValueError as exc:  # a link out of the run folder
            raise ConfigError(f"report: {exc}") from None

    def evaluation_record(self) -> Path:
        """``<out>/evaluation.json`` for the run's report, ``<out>/evaluation_<report>.json`` for another one."""
        name = self.report_folder().name
        return self.out / ("evaluation.json" if name == "report" else f"evaluation_{name}.json")

    def morphable_rows(self) -> dict[str, dict[str, Any]]:
        """``{primitive: {"morphable": model}}``: the Morphable Graph's neutral models of this run's data."""
        from stylemotion.morphable.rows import ROW, neutral_models

        models = neutral_models(self.data_cfg, self.primitives, str(self.cfg.evaluation.neutral_style),
                                self.out / "morphable", dict(self.cfg.evaluation.get("segment") or {}),
                                int(self.cfg.seed))
        return {p: {ROW: m} for p, m in models.items()}

    def recorded(self, path: str | Path | None) -> str | None:
        """``path`` as this run's records hold it: relative to ``out`` when inside it, else absolute."""
        return recorded_path(path, self.out.resolve())

    def located(self, path: str | None) -> str | None:
        """A recorded path as an absolute file path now: relative ones are relative to ``out``."""
        if not path:
            return None
        return str(Path(path) if Path(path).is_absolute() else (self.out / path).resolve())

    def summary(self) -> dict[str, Any]:
        """What ``reproduce.json`` holds; paths inside ``out`` are relative to it. Each stage records the
        Hydra overrides and values it was trained with (``stylemotion-style`` trains new styles with them)."""
        return {"out": str(self.out), "provenance": self.provenance, "data": self.data_summary,
                "seconds": time.perf_counter() - self.started,
                "stages": [{"name": s.name, "kind": s.kind, "status": s.status,
                            "checkpoint": self.recorded(s.checkpoint), "seconds": s.seconds, "metrics": s.metrics,
                            "folder": self.recorded(s.folder), "overrides": list(s.overrides),
                            "values": dict(s.values)} for s in self.stages]}


def stage_train_config(overrides: Sequence[str], values: dict[str, Any], data_cfg: dict[str, Any], folder: Path,
                       seed: int, threads: Any = None, autoencoder_ckpt: str | None = None) -> DictConfig:
    """The ``train`` config of a training stage: its Hydra ``overrides`` (as ``reproduce.json`` records
    them), then the run's ``data`` node, ``seed``, ``threads``, the output ``folder``, the stage's
    ``values`` (primitive, style) and the autoencoder it builds on; ``ckpt_path=auto`` (resumes from
    ``last.ckpt`` exactly when there is one). Needs Hydra's config search initialized (see :func:`reproduce`).
    """
    cfg = compose(config_name="train", overrides=list(overrides))
    with open_dict(cfg):
        cfg.data = OmegaConf.create(data_cfg)
        cfg.output_dir = str(Path(folder).resolve())
        cfg.seed = int(seed)
        if threads is not None:
            cfg.threads = positive_int(threads, "threads")
        for key, value in values.items():
            OmegaConf.update(cfg, key, value, force_add=True)
        if autoencoder_ckpt is not None:
            cfg.autoencoder_ckpt = autoencoder_ckpt
        cfg.ckpt_path = "auto"
    return cfg


def _train_in_worker(container: dict[str, Any]) -> tuple[dict[str, Any], float]:
    """A worker process's (or submitit job's) work: :func:`stylemotion.training.run` on a resolved
    ``train`` config; returns its metrics and its training seconds (not counting the wait in the queue)."""
    from stylemotion.training.fit import run as train_run

    t0 = time.perf_counter()
    metrics = train_run(OmegaConf.create(container))["metrics"]
    return metrics, time.perf_counter() - t0


#: A finished job: its stage, whether it resumed, and a call that returns ``(metrics, seconds)`` or raises.
Finished = tuple[Stage, bool, Callable[[], tuple[dict[str, Any], float]]]


def executor_engine(cfg: DictConfig) -> str:
    """``executor.engine`` of a reproduce config (``pool`` when there is no executor node), checked."""
    node = cfg.get("executor")
    engine = str(node.get("engine", "pool")) if node is not None else "pool"
    if engine not in ENGINES:
        raise ConfigError(f"reproduce config key 'executor.engine' must be one of {list(ENGINES)}, got {engine!r}")
    return engine


def _pool_results(jobs: Sequence[tuple[Stage, bool, dict[str, Any]]], workers: int) -> Iterator[Finished]:
    """Run the jobs in ``workers`` spawned processes; yield each as it finishes."""
    if not jobs:
        return
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))
    try:
        pending = {pool.submit(_train_in_worker, container): (stage, resume) for stage, resume, container in jobs}
        for future in as_completed(pending):
            yield (*pending[future], future.result)
    except BaseException:
        # Ctrl-C or SIGTERM (cli.skeleton): stop the stages still training instead of leaving them running
        # without a parent. Python < 3.14 has no public way to end a pool's workers.
        for process in list((pool._processes or {}).values()):
            process.terminate()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()


def submitit_executor(node: Any, folder: Path, engine: str, name: str = "stylemotion") -> Any:
    """A submitit ``AutoExecutor`` for one stage (job ``name``, logs in ``folder``) with the
    ``executor`` node's ``parameters`` (and ``partition`` as ``slurm_partition``).

    Raises:
        ImportError: submitit is not installed (the ``cluster`` extra).
    """
    try:
        import submitit
    except ImportError as exc:
        raise ImportError(f"executor={engine} runs the stages through submitit, which is not installed: "
                          "pip install 'stylemotion[cluster]' (or pip install submitit)") from exc
    params = OmegaConf.to_container(node.get("parameters") or {}, resolve=True) if isinstance(node, DictConfig) \
        else dict(node.get("parameters") or {})
    params.setdefault("name", name)
    if node.get("partition"):
        params["slurm_partition"] = str(node.get("partition"))
    executor = submitit.AutoExecutor(folder=str(folder), cluster=engine)
    executor.update_parameters(**params)
    return executor


def _submitit_results(jobs: Sequence[tuple[Stage, bool, dict[str, Any]]], node: Any,
                      limit: int | None) -> Iterator[Finished]:
    """Submit the jobs through submitit (at most ``limit`` running at once; None = all) and yield each
    as it finishes; a job's log folder is its stage's ``submitit/``."""
    engine = str(node.get("engine"))
    waiting, running = list(jobs), []
    while waiting or running:
        while waiting and (limit is None or len(running) < limit):
            stage, resume, container = waiting.pop(0)
            name = f"stylemotion-{stage.kind}-{stage.folder.name}"
            job = submitit_executor(node, stage.folder / "submitit", engine, name).submit(_train_in_worker, container)
            log.info("%s: submitit job %s (%s)", stage.name, job.job_id, engine)
            running.append((stage, resume, job))
        done = [item for item in running if item[2].done()]
        if not done:
            time.sleep(POLL_SECONDS)
            continue
        for item in done:
            running.remove(item)
            yield item[0], item[1], item[2].result


def choose_budget(cfg: DictConfig) -> str:
    """Fall back to ``default_budget`` when no ``budget`` was composed (no ``configs/budget/<data config
    name>.yaml``); returns a line saying which budget the training lengths come from."""
    if cfg.get("budget") is not None:
        return f"budget: budget/{cfg.budget.get('name', _data_choice() or '?')}"
    if cfg.get("default_budget") is None:
        raise ConfigError("no training budget: no configs/budget/<data config name>.yaml and no default_budget")
    with open_dict(cfg):
        cfg.budget = cfg.default_budget
    choice = _data_choice()
    missing = f"budget/{choice}.yaml" if choice else "budget named after this data config"
    return (f"budget: budget/{cfg.budget.get('name', 'default')} (there is no {missing}; scale the epochs with the "
            "number of clips through stages.autoencoder/vae/cvae if training is too short or long)")


def _data_choice() -> str | None:
    """The name of the ``data`` config Hydra composed, when Hydra's run config is known."""
    from hydra.core.hydra_config import HydraConfig

    if HydraConfig.initialized():
        choice = HydraConfig.get().runtime.choices.get("data")
        return str(choice) if choice else None
    return None


def alone_threads(value: Any) -> int:
    """Torch threads of the steps that run with nothing beside them (the autoencoder stage, every stage when
    ``workers=1``, the evaluation): ``value``, or every core this process may use when it is None
    (benchmarks/autoencoder.md: two threads train the autoencoder 2.2× faster than one on two free cores)."""
    if value is not None:
        return positive_int(value, "alone_threads")
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


def reproduce(cfg: DictConfig) -> dict[str, Any]:
    """Run (or resume) every stage; returns the summary written to ``<out>/reproduce.json``.

    Must be called with Hydra's global config search initialized (inside ``stylemotion-reproduce``,
    or within ``hydra.initialize_config_dir``), since the training stages compose the ``train`` config.
    """
    set_torch_threads(cfg.get("threads"), "threads")
    workers = positive_int(cfg.get("workers", 1), "workers")
    alone = alone_threads(cfg.get("alone_threads"))
    # a bad evaluation value is named now, not after hours of training
    settings_from_config(cfg.get("evaluation") or {}, int(cfg.get("seed") or 0))
    engine = executor_engine(cfg)
    log.info(choose_budget(cfg))
    check_out_folder(cfg.out)
    repro = Reproduction(cfg)
    repro.report_folder()  # a bad report name is named now, not after the training
    repro.out.mkdir(parents=True, exist_ok=True)
    repro.data_stage()
    indexed = list(enumerate(repro.stages, start=2))
    parallel = workers > 1 or engine != "pool"
    in_process = 1 if parallel else len(indexed)  # stage 1 is the autoencoder the others need
    for index, stage in indexed[:in_process]:
        repro.run_stage(index, stage, alone)  # nothing else runs beside it
        if stage.status != "reused":
            write_json(repro.out / "reproduce.json", repro.summary())
    if indexed[in_process:]:
        repro.run_stages_in_parallel(indexed[in_process:], workers)
    set_torch_threads(alone, "alone_threads")  # the evaluation runs alone too
    report = repro.report_folder()
    results = repro.evaluation_stage()
    summary = repro.summary()
    summary["report"] = repro.recorded(report)
    # a rerun that reused every stage and the report leaves the finished run's record as it was; so does one that
    # only adds another report (report=<name>) of the same stages
    if (repro.evaluated and report.name == "report") or any(s.status != "reused" for s in repro.stages) \
            or not (repro.out / "reproduce.json").is_file():
        write_json(repro.out / "reproduce.json", summary)
    log.info(f"done in {summary['seconds'] / 60:.1f} min: "
             + ", ".join(f"{k} {v}" for k, v in Counter(s.status for s in repro.stages).items()) + " training stages")
    for line in summary_lines(results):
        log.info(line)
    log.info(f"report: {report / 'report.md'}")
    return summary
