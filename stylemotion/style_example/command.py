"""A new style from the user's own example (what ``stylemotion-style`` runs).

    stylemotion-style example=my_walk.bvh run=runs/reproduce/synthetic name=mine
    stylemotion-style example=walk_120fps.bvh:240-960 run=runs/reproduce/bandai name=limp out=runs/style/limp
    stylemotion-style 'example=[take1.bvh,take2.bvh:0-900]' name=limp     # several examples of the style
    stylemotion-generate run=runs/style/mine style=mine      # a walk in the new style (neutral and the run's too)

Stages (one progress line each, ``[k/N]``, as ``stylemotion-reproduce`` prints them):

1. check the run (a finished reproduce run, :mod:`.base_run`), the name and the example(s), and convert
   each (:func:`.example.convert_example`);
2. cut them into the run's primitives with the run's segmentation and pool their clips
   (:func:`.example.cut_examples`: each model is conditioned on the clips of every example);
3. one model per primitive of the example's action, by ``method`` (:data:`METHODS`; ``cvae``: the run's
   StyleCVAE training, :func:`train_cvae`; ``zero_shot``: a zero-shot network per primitive bound to the
   example, :mod:`.zero_shot`);
4. evaluate them against the run (:mod:`.evaluate`) and write ``report.md`` and ``report.json``.

Everything is built in a temporary folder beside ``out`` and renamed into it at the end
(:func:`stylemotion.io.atomic.atomic_folder`): a failure leaves nothing, an existing ``out`` is refused
before any work. The folder holds ``cvae/<primitive>_<name>/`` (each model's training folder, as the
run's stages have them: checkpoints, ``config_resolved.yaml``, ``run.json``, ``metrics.json``; their
records name the temporary folder they were trained in; ``method=zero_shot``: ``network/<primitive>/``
when the networks are trained here), ``example/example.npz`` (the converted
example: ``positions`` (frames, 21, 3) metres, ``fps``, ``joint_names``; further examples in
``example/example_<i>.npz``, :func:`.example.example_file`), ``report.md`` and
``report.json`` (layout in ``docs/style.md``). Paths in ``report.json`` inside ``out`` are relative to it.
"""

from __future__ import annotations

import io
import logging
import os
import time
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from stylemotion.config import ConfigError, config_dir, positive_int, settings_from_config
from stylemotion.datasets import TakeSet, build_dataset
from stylemotion.datasets.loading import ConversionSettings
from stylemotion.datasets.user_motion import CONVERSION_KEYS, conversion_keys
from stylemotion.io.atomic import atomic_folder
from stylemotion.io.jsonfile import plain, write_json
from stylemotion.io.outputs import check_new_output, inside
from stylemotion.models.checkpoints import autoencoder_info, load_autoencoder
from stylemotion.models.loading import EvalModel, load_model
from stylemotion.primitives.actions import segment_action
from stylemotion.primitives.segmentation import Clip, parse_primitive
from stylemotion.provenance import provenance
from stylemotion.skeleton import CANONICAL_JOINTS
from stylemotion.style_example.base_run import STYLE_KIND, SourceRun, check_name, load_run, run_action, train_config
from stylemotion.style_example.evaluate import evaluate_primitive, markdown, pooled_foot_skating
from stylemotion.style_example.example import (
    ConvertedExample,
    CutExample,
    convert_example,
    cut_examples,
    example_file,
    on_run_skeleton,
    parse_examples,
)
from stylemotion.style_example.methods import Method, recorded_path
from stylemotion.style_example.settings import StyleSettings
from stylemotion.style_example.zero_shot import ZeroShotMethod

log = logging.getLogger(__name__)
_D = StyleSettings


class Progress:
    """``[k/N] text  (at x min)`` lines, as ``stylemotion-reproduce`` prints its stages."""

    def __init__(self, total: int):
        self.total, self.step, self.started = total, 0, time.perf_counter()

    def __call__(self, text: str) -> None:
        self.step += 1
        log.info(f"[{self.step}/{self.total}] {text}  (at {(time.perf_counter() - self.started) / 60:.1f} min)")


@contextmanager
def hydra_configs() -> Iterator[None]:
    """Hydra's config search over the packaged configs, unless a command already set it up (the run's
    training stages are composed from the ``train`` config)."""
    from hydra import initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    if GlobalHydra.instance().is_initialized():
        yield
        return
    with initialize_config_dir(config_dir=config_dir(), version_base="1.3"):
        yield


# -- methods: how a style's primitive models come about


def train_cvae(run: SourceRun, name: str, cut: CutExample, folder: Path, progress: Progress,
               threads: Any = None) -> dict[str, Path]:
    """A :class:`~stylemotion.models.cvae.StyleCVAE` per primitive, trained as the run's CVAE stage of that
    primitive (:func:`.base_run.train_config`) on the clips of every example (the Gram target: their mean Gram
    matrix, :func:`stylemotion.models.style.mean_gram`); returns primitive → checkpoint."""
    from stylemotion.training.fit import run as train_run

    checkpoints = {}
    for primitive, clips in cut.used.items():
        model_folder = inside(folder, "cvae", f"{primitive}_{name}")
        cfg = train_config(run, primitive, name, model_folder, threads)
        progress(f"cvae {primitive}/{name}: training ({cfg.trainer.max_epochs} epochs, style_weight "
                 f"{cfg.model.style_weight}) on {len(clips)} example clip(s)")
        t0 = time.perf_counter()
        result = train_run(cfg, datamodule_args={"example_clips": clips, "example_records": cut.records[primitive]})
        metrics = result["metrics"]
        last = model_folder / "checkpoints" / "last.ckpt"
        checkpoints[primitive] = Path(metrics.get("best_checkpoint") or last)
        test = ", ".join(f"{k} {v:.4g}" for k, v in metrics.get("test", {}).items() if isinstance(v, float))
        log.info(f"    cvae {primitive}/{name} done in {(time.perf_counter() - t0) / 60:.1f} min" + (f": {test}" if test
                                                                                                else ""))
    return checkpoints


class CVAEMethod(Method):
    """``method=cvae``: :func:`train_cvae`; the evaluation loads each StyleCVAE as the run's own."""

    def make(self, run: SourceRun, name: str, examples: Sequence[ConvertedExample], cut: CutExample, folder: Path,
             progress: Progress, threads: Any, options: Mapping[str, Any]) -> dict[str, Path]:
        return train_cvae(run, name, cut, folder, progress, threads)

    def load(self, checkpoint: Path, primitive: str, clips: Sequence[Clip], records: Sequence[Mapping[str, Any]],
             name: str, neutral_style: str, autoencoder) -> EvalModel:
        return load_model(checkpoint, neutral_style, autoencoder)


#: ``method`` → how the style's models come about (one place to add another method).
METHODS: dict[str, Method] = {"cvae": CVAEMethod(), "zero_shot": ZeroShotMethod()}


def check_method(method: Any) -> str:
    """``method`` if it names one of :data:`METHODS`; :class:`ConfigError` naming the key otherwise."""
    if method not in METHODS:
        raise ConfigError(f"method must be one of {sorted(METHODS)}, got {method!r}")
    return str(method)


def method_options(method: str, options: Mapping[str, Any] | None) -> dict[str, Any]:
    """The method's own keys of ``options``; :class:`ConfigError` for a value given to another method's key."""
    own = METHODS[method].keys
    for key, value in (options or {}).items():
        if value is not None and key not in own:
            owners = [m for m, impl in METHODS.items() if key in impl.keys]
            raise ConfigError(f"{key}={value} is a key of method={'|'.join(owners) or '?'}, not of method={method}")
    return {key: (options or {}).get(key) for key in own}


# -- the command


def add_style(example: str | Sequence[str], run: str | os.PathLike, name: str, out: str | os.PathLike,
              method: str = _D.method,
              action: str | None = _D.action, samples: int = _D.samples, seed: int | None = _D.seed,
              threads: Any = _D.threads, conversion: Mapping[str, Any] | None = None,
              command: str = "", network: Any = _D.network,
              network_epochs: int | None = _D.network_epochs) -> dict[str, Any]:
    """Make the models of a new style ``name`` from ``example`` and evaluate them (see the module doc).

    Args:
        example: ``<BVH>[:start-end]`` (frames of the file's own frame rate, 0-based, end exclusive), or a list of
            them (at most :data:`.example.MAX_EXAMPLES`): the models are conditioned on the clips of all.
        run: a finished ``stylemotion-reproduce`` folder.
        name: the new style's name (not a style or model name of the run).
        out: the new folder.
        method: how the models come about (:data:`METHODS`).
        action: the example's action; None = the one action of the run's primitives.
        samples: samples per model for the report; ``seed`` draws them (None: the run's seed).
        threads: torch threads while training (None: torch's default).
        conversion: ``joint_map``, ``unit_scale``, ``up_axis`` for the example (None: auto-detected, Y up).
        command: the command line to record.
        network: ``method=zero_shot``: the networks, a folder with ``<primitive>/checkpoints/best.ckpt`` or
            ``{primitive: checkpoint}``; None trains them into ``out/network/`` (:mod:`.zero_shot`).
        network_epochs: ``method=zero_shot`` with ``network`` None: epochs per network (None: the experiment's).

    Returns:
        What ``report.json`` holds.

    Raises:
        OutputExistsError: ``out`` exists (before any work).
        ConfigError: a bad ``method``, ``samples``, ``seed``, ``threads`` or ``network_epochs``, or a key of
            another method.
        StyleExampleError: a bad example (of a list: naming the item), frame range, run or name
            (:class:`.base_run.NameTakenError`), an example without a complete step, or a ``network`` that is not
            the run's (primitive, autoencoder, timeline); nothing is written then.
    """
    started = time.perf_counter()
    out = check_new_output(Path(out).expanduser())
    method = check_method(method)
    options = method_options(method, {"network": network, "network_epochs": network_epochs})
    samples = positive_int(samples, "samples")
    threads = None if threads is None else positive_int(threads, "threads")
    if samples < 2:
        raise ConfigError(f"samples must be at least 2 (a spread needs two), got {samples}")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
        raise ConfigError(f"seed must be a whole number ≥ 0 or null (the run's seed), got {seed!r}")
    specs = parse_examples(example)
    source = load_run(run)
    name = check_name(name, source)
    action = run_action(source, action)
    settings = conversion_settings(source, conversion)
    ours = [p for p in source.primitives if parse_primitive(p)[0] == action]
    options = METHODS[method].prepare(source, ours, options)
    progress = Progress(3 + METHODS[method].steps(ours, options))
    takeset = build_dataset(source.data_cfg)
    converted = [on_run_skeleton(convert_example(spec, settings), takeset, source.settings.neutral_style)
                 for spec in specs]
    progress("; ".join((f"{c.spec.key}={c.spec}" if len(specs) > 1 else f"example {c.name}")
                       + f": {c.end - c.start} of {c.file_frames} frames at {c.file_fps:g} fps → {len(c.positions)} "
                       f"frames at {c.fps:g} fps" for c in converted)
             + f" on the run's skeleton (bones of {converted[0].retarget.get('style') or 'all takes'})"
             + f"; run {source.folder} (data {takeset.name}, primitives {source.primitives})")
    with hydra_configs():
        node = train_config(source, ours[0], name, out, threads).datamodule.get("segment")
        segment = OmegaConf.to_container(node, resolve=True) if node is not None else {}
    cut = cut_examples(converted, name, action, source.primitives, segment)
    what = converted[0].name if len(converted) == 1 else f"{len(converted)} examples"
    progress(f"{what} cut with the run's segmentation: "
             + ", ".join(f"{p} {len(c)}" for p, c in cut.clips.items())
             + (f"; {cut.borrowed} take the example's other steps" if cut.borrowed else "")
             + (f"; no model of {cut.skipped} (another action)" if cut.skipped else ""))
    with atomic_folder(out, on_exists=lambda: check_new_output(out)) as tmp:
        with hydra_configs():
            checkpoints = METHODS[method].make(source, name, converted, cut, tmp, progress, threads, options)
        progress(f"evaluation: {samples} samples per model → {out / 'report.md'}")
        results = evaluate(source, takeset, name, method, converted, cut, checkpoints, tmp, samples, seed,
                           options)
        results["meta"].update(provenance(command or None), seconds=time.perf_counter() - started,
                               run_relative=os.path.relpath(source.folder.resolve(), out.resolve()))
        for i, one in enumerate(converted):
            write_example(one, tmp / example_file(i))
        results = plain(results)
        write_json(tmp / "report.json", results)
        (tmp / "report.md").write_text(markdown(results))
    for line in summary_lines(results):
        log.info(line)
    log.info(f"report: {out / 'report.md'}")
    return results


def conversion_settings(run: SourceRun, conversion: Mapping[str, Any] | None) -> ConversionSettings:
    """How the example is converted: the run's frame rate, and ``joint_map``/``unit_scale``/``up_axis``."""
    values = dict(conversion or {})
    unknown = sorted(set(values) - set(CONVERSION_KEYS))
    if unknown:
        raise ConfigError(f"unknown conversion key(s) {unknown}; valid: {list(CONVERSION_KEYS)}")
    fps = run.data_cfg.get("fps", 30.0)
    return ConversionSettings(fps=float(fps), **{k: v for k, v in values.items() if v is not None})


def evaluate(run: SourceRun, takeset: TakeSet, name: str, method: str, examples: Sequence[ConvertedExample],
             cut: CutExample,
             checkpoints: Mapping[str, Path], folder: Path, samples: int, seed: int | None,
             options: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The report of the new models against ``run`` and its data ``takeset`` (``report.json`` layout without
    provenance); paths inside ``folder`` relative to it; ``options``: the method's keys (see :meth:`Method.prepare`).
    ``examples``: every example, in order (``report.json``'s ``examples``; ``example`` is the one example's record
    when there is one, else what they make together)."""
    impl = METHODS[method]
    settings = run.settings
    seed = run.seed if seed is None else int(seed)
    autoencoder = load_autoencoder(run.autoencoder_ckpt)
    segmentations = {}
    per: dict[str, dict[str, Any]] = {}
    models = {}
    loaded: dict[str, EvalModel] = {}
    for primitive, ckpt in checkpoints.items():
        action = parse_primitive(primitive)[0]
        if action not in segmentations:
            segmentations[action] = segment_action(takeset.takes, action, settings.segment)
        clips = cut.used[primitive]
        new = loaded[primitive] = impl.load(ckpt, primitive, clips, cut.records[primitive], name,
                                            settings.neutral_style, autoencoder)
        per[primitive] = evaluate_primitive(primitive, run.models(primitive, autoencoder), new, cut.used[primitive],
                                            takeset, autoencoder, settings, run.data_cfg.get("split"), samples, seed,
                                            segmentations[action])
        models[primitive] = {"checkpoint": recorded_path(ckpt, folder),
                             "examples": new.examples,
                             "borrowed": primitive in cut.borrowed}
    info = autoencoder_info(autoencoder, run.autoencoder_ckpt)
    entries = [{"path": m["checkpoint"], "primitive": p, "name": name, "style": name,
                **({"path_relative": os.path.relpath(m["checkpoint"], folder.resolve())}
                   if Path(m["checkpoint"]).is_absolute() else {}),
                **impl.entry(p, cut.used[p], cut.origin[p], len(examples))} for p, m in models.items()]
    records = [example_record(e, i, cut) for i, e in enumerate(examples)]
    return {
        "name": name, "method": method,
        "example": records[0] if len(records) == 1 else {
            "count": len(records), "files": [r["file"] for r in records], "frames": sum(r["frames"] for r in records),
            "fps": records[0]["fps"], "retarget": records[0]["retarget"],
            "clips": {p: len(c) for p, c in cut.clips.items()}},
        "examples": records,
        "models": models, "skipped": cut.skipped, "samples": samples,
        "table_5_1_row": {p: r["table_5_1_row"] for p, r in per.items()},
        "table_5_1_columns": {p: r["columns"] for p, r in per.items()},
        "nearest_existing_style": {p: r["nearest_existing"] for p, r in per.items()},
        "example_range": {p: r["example_range"] for p, r in per.items()},
        "new_column_is_minimum": {p: r["new_column_is_minimum"] for p, r in per.items()},
        "variation": {p: r["variation"] for p, r in per.items()},
        "foot_skating": {p: r["foot_skating"] for p, r in per.items()},
        "foot_skating_pooled": {kind: pooled_foot_skating(per, kind) for kind in ("samples", "example")},
        "meta": {"kind": STYLE_KIND, "name": name, "run": str(run.folder.resolve()), "data": run.data_cfg,
                 "data_name": takeset.name, "train_seed": run.seed, "seed": seed, "samples": samples,
                 "checkpoints": entries,
                 "autoencoder": {"path": str(Path(info["path"]).resolve()), "fingerprint": info["fingerprint"]},
                 "paths_relative_to": ".", "settings": asdict(settings)},
        **impl.report(loaded, folder, options or {}),
    }


def example_record(example: ConvertedExample, index: int, cut: CutExample) -> dict[str, Any]:
    """What ``report.json`` records of example ``index`` (0-based): its file, sha256, frames used, conversion, the
    clips cut from it per primitive, its rejected steps and where the style folder keeps it (``saved``)."""
    segmentation = (cut.segmentations or [cut.segmentation])[index]
    return {"file": example.name, "spec": str(example.spec), "sha256": example.sha256, "file_fps": example.file_fps,
            "file_frames": example.file_frames, "file_range": [example.start, example.end],
            "frames": int(len(example.positions)), "fps": example.fps, "retarget": example.retarget,
            "clips": {p: sum(1 for c in segmentation.clips if f"{c.action}_{c.primitive}" == p) for p in cut.clips},
            "used_clips": {p: sum(1 for i in origin if i == index) for p, origin in cut.origin.items()},
            "rejected_steps": [{"reason": r.reason, "kind": r.kind, "start": r.start, "stop": r.stop}
                               for r in segmentation.rejections],
            "saved": example_file(index)}


def write_example(example: ConvertedExample, path: Path) -> None:
    """The converted example as ``positions`` (frames, 21, 3) metres, ``fps``, ``joint_names``."""
    buffer = io.BytesIO()
    np.savez(buffer, positions=example.positions, fps=np.float64(example.fps), joint_names=np.array(CANONICAL_JOINTS))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(buffer.getvalue())


def summary_lines(results: Mapping[str, Any]) -> list[str]:
    """A few lines for the terminal: each primitive's row against the new example and the nearest existing style."""
    name, lines = results["name"], []
    for p, row in results["table_5_1_row"].items():
        nearest = results["nearest_existing_style"][p]
        lines.append(f"{p}: D to {name} {row[name]:.4g}, nearest existing style {nearest} {row[nearest]:.4g} "
                     f"({'the new example is' if results['new_column_is_minimum'][p] else 'not'} the row's minimum)")
        check = results.get("example_range", {}).get(p)
        if check and check["out_of_range"]:
            lines.append(f"WARNING {p}: the example's Gram distance to the neutral column is "
                         f"{check['distance_to_neutral']:.4g}, the run's examples' at most "
                         f"{check['run_examples_max']:.4g}: it lies outside what the autoencoder knows, the new "
                         "model cannot be faithful")
    pooled = results["foot_skating_pooled"]
    lines.append(f"foot skating of samples {_percent(pooled['samples'])}, of the example's clips "
                 f"{_percent(pooled['example'])}")
    return lines


def _percent(value: Any) -> str:
    return "–" if value is None else f"{100 * value:.1f} %"


def add_style_from_config(cfg: DictConfig | Mapping[str, Any], command: str = "") -> dict[str, Any]:
    """:func:`add_style` with the keys of ``configs/style.yaml`` (:class:`StyleSettings`); missing mandatory keys
    are named."""
    if isinstance(cfg, DictConfig):
        for key, form in (("example", "example=<BVH>[:start-end]"), ("name", "name=<the new style's name>")):
            if OmegaConf.is_missing(cfg, key):
                raise ConfigError(f"{key} is missing: give {form}")
    _, s = settings_from_config(cfg, StyleSettings, "style")
    return add_style(s.example, s.run, s.name, s.out, method=s.method, action=s.action, samples=s.samples,
                     seed=s.seed, threads=s.threads, conversion=conversion_keys(vars(s)), command=command,
                     network=s.network, network_epochs=s.network_epochs)

