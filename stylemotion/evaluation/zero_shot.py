"""Leave-one-style-out evaluation of the zero-shot style network against a reproduce run's style CVAEs.

    python scripts/zero_shot_loso.py --run runs/reproduce/synthetic --out runs/zero_shot/synthetic

For each primitive ``p`` of a finished ``stylemotion-reproduce`` run and each of its CVAE styles ``s``
(or ``styles``):

1. a :class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE` trained **without any clip of s**
   (``experiment=zero_shot``, ``datamodule.exclude_styles=[s]``; the run's data, seed and autoencoder) into
   ``<out>/models/<p>_without_<s>/``, or the checkpoint of an earlier output (``checkpoints``);
2. conditioned on s's example: the clip(s) the run's CVAE of ``(p, s)`` was trained with (its recorded
   ``spec.style_examples``), encoded at the canonical length as the network's training examples were;
3. ``samples`` samples of it and of that CVAE (same seed), and for each:

   * **recognition**: the share the run's style classifier assigns to ``s``
     (:func:`stylemotion.evaluation.pipeline.real_side`, fitted on the train split of every style, s
     included: an outside judge, never a generator);
   * **Table 5.1 row**: the mean Gram distance of the samples to every column of the run's Table 5.1
     (the neutral mean motion and each CVAE style's example; :func:`stylemotion.evaluation.tables.distance_table`)
     and whether s's own column is the row's minimum;
   * ``pose_across_sd`` (cm): the spread across samples at aligned frames (a model that copies the example
     scores near 0);

   and the same figures of s's real clips (all but the example) in place of samples (row ``real``);

4. ``<out>/zero_shot.json`` and ``<out>/zero_shot.md``.

``out`` must not exist (``force`` replaces it).
"""

from __future__ import annotations

import logging
import math
import shutil
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import asdict
from pathlib import Path
from typing import Any

import torch
from omegaconf import DictConfig, OmegaConf, open_dict

from stylemotion.config import config_dir, positive_int, set_torch_threads
from stylemotion.datasets import TakeSet, build_dataset
from stylemotion.evaluation.pipeline import example_column_gram, real_side, recognition
from stylemotion.evaluation.settings import EvalSettings
from stylemotion.evaluation.sources import check_one_autoencoder
from stylemotion.evaluation.tables import across_sample_sd, distance_table
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.errors import UserInputError
from stylemotion.io.jsonfile import write_json
from stylemotion.io.outputs import check_new_output, inside
from stylemotion.models.checkpoints import fingerprint, load_autoencoder
from stylemotion.models.loading import NEUTRAL, EvalModel, load_generative, load_model
from stylemotion.models.zero_shot import ZeroShotStyleVAE
from stylemotion.primitives.segmentation import parse_primitive
from stylemotion.provenance import provenance
from stylemotion.training.run_folder import FinishedRun, read_json_object

log = logging.getLogger(__name__)

Say = Callable[[str], None]
#: The rows of each left-out style: the two models, and the style's real clips.
ROWS = ("zero_shot", "cvae", "real")


class ZeroShotRunError(UserInputError, ValueError):
    """The reproduce run (or a given checkpoint) cannot serve the leave-one-style-out evaluation."""


# -- the reproduce run


class ReproduceRun(FinishedRun):
    """What the evaluation reads of a finished ``stylemotion-reproduce`` run (see :func:`read_run` and
    :class:`stylemotion.training.run_folder.FinishedRun`): its CVAEs by primitive and style."""

    @property
    def cvaes(self) -> dict[tuple[str, str], Path]:
        """``(primitive, style)`` → the CVAE checkpoint."""
        return {(str(s["values"]["primitive"]), str(s["values"]["style"])): self.located(s["checkpoint"])
                for s in self.stages("cvae")}

    @property
    def primitives(self) -> list[str]:
        """The primitives with CVAEs, in the run's order."""
        return list(dict.fromkeys(p for p, _ in self.cvaes))

    def styles(self, primitive: str) -> list[str]:
        """The CVAE styles of ``primitive``, in the run's order."""
        return [s for p, s in self.cvaes if p == primitive]


def read_run(folder: str | Path) -> ReproduceRun:
    """The finished reproduce run in ``folder``.

    Raises:
        ZeroShotRunError: no such folder, no ``reproduce.json`` or report, no autoencoder or CVAE stage, or
            a stage checkpoint that is gone (each message says which).
    """
    folder = Path(folder).expanduser()
    summary_path, report_path = folder / "reproduce.json", folder / "report" / "report.json"
    for path, what in ((summary_path, "reproduce.json"), (report_path, "report (report/report.json)")):
        if not path.is_file():
            raise ZeroShotRunError(f"run={folder} is not a finished stylemotion-reproduce run: it has no {what}")
    run = ReproduceRun(folder, read_json_object(summary_path, "summary", ZeroShotRunError),
                       read_json_object(report_path, "report", ZeroShotRunError))
    if not run.meta.get("data"):
        raise ZeroShotRunError(f"run={folder}: {report_path} records no data config (meta.data)")
    if not run.stages("autoencoder") or not run.stages("cvae"):
        raise ZeroShotRunError(f"run={folder} has no finished autoencoder or no style CVAE stage to compare with")
    missing = [str(p) for p in [run.autoencoder_ckpt, *run.cvaes.values()] if not p.is_file()]
    if missing:
        raise ZeroShotRunError(f"run={folder}: checkpoint(s) {missing} are gone; run its command again")
    return run


# -- training the left-out models


@contextmanager
def hydra_configs() -> Iterator[None]:
    """Hydra's config search over the packaged configs, unless a command already set one up."""
    from hydra import initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    if GlobalHydra.instance().is_initialized():
        yield
        return
    with initialize_config_dir(config_dir=config_dir(), version_base="1.3"):
        yield


def network_train_config(run: FinishedRun, primitive: str, folder: Path, epochs: int | None = None,
                         overrides: Sequence[str] = (), threads: Any = None, exclude: Sequence[str] = (),
                         epochs_key: str = "epochs") -> DictConfig:
    """The ``train`` config of a zero-shot network of ``primitive`` on ``run``'s data, started afresh in
    ``folder``: ``experiment=zero_shot``, ``trainer.max_epochs=epochs`` (None: the experiment's; ``epochs_key``
    names it in errors), the ``overrides``, then the run's data, seed, autoencoder and neutral style, and
    ``exclude`` left out. Composes inside Hydra's config search (:func:`hydra_configs`)."""
    from hydra import compose

    listed = ["experiment=zero_shot"] + ([f"trainer.max_epochs={positive_int(epochs, epochs_key)}"] if epochs else [])
    with hydra_configs():
        cfg = compose(config_name="train", overrides=listed + list(overrides))
    with open_dict(cfg):
        cfg.data = OmegaConf.create(run.data_cfg)
        cfg.output_dir = str(Path(folder).resolve())
        cfg.seed = run.seed
        if threads is not None:
            cfg.threads = positive_int(threads, "threads")
        cfg.primitive = primitive
        cfg.autoencoder_ckpt = str(run.autoencoder_ckpt)
        cfg.datamodule.neutral_style = run.settings.neutral_style
        cfg.datamodule.exclude_styles = list(exclude)
    return cfg


def train_config(run: ReproduceRun, primitive: str, style: str, folder: Path, epochs: int | None = None,
                 overrides: Sequence[str] = (), threads: Any = None) -> DictConfig:
    """The ``train`` config of the zero-shot network of ``primitive`` without ``style``
    (:func:`network_train_config`), without a progress bar."""
    cfg = network_train_config(run, primitive, folder, epochs, overrides, threads, exclude=[style])
    with open_dict(cfg):
        cfg.trainer.enable_progress_bar = False
        if cfg.get("callbacks") and "progress_bar" in cfg.callbacks:
            cfg.callbacks.progress_bar = None
    return cfg


def train_left_out(run: ReproduceRun, primitive: str, style: str, folder: Path, epochs: int | None = None,
                   overrides: Sequence[str] = (), threads: Any = None) -> tuple[Path, float]:
    """Train the zero-shot network of ``primitive`` without ``style`` into ``folder``; its best checkpoint
    and the training seconds."""
    from stylemotion.training.fit import run as train_run

    t0 = time.perf_counter()
    metrics = train_run(train_config(run, primitive, style, folder, epochs, overrides, threads))["metrics"]
    seconds = time.perf_counter() - t0
    return Path(metrics.get("best_checkpoint") or folder / "checkpoints" / "last.ckpt"), seconds


def model_folder(out: Path, primitive: str, style: str) -> Path:
    """Where the network of ``primitive`` without ``style`` is trained: ``<out>/models/<p>_without_<s>``."""
    return inside(out, "models", f"{primitive}_without_{style}")


def load_left_out(path: Path, primitive: str, style: str, fingerprint: str) -> ZeroShotStyleVAE:
    """A zero-shot checkpoint, checked to be of ``primitive``, trained without ``style`` and on the run's
    autoencoder (``fingerprint``).

    Raises:
        ZeroShotRunError: another kind of model, primitive, exclusion or autoencoder.
    """
    model = load_generative(path)
    if not isinstance(model, ZeroShotStyleVAE):
        raise ZeroShotRunError(f"{path} is a {type(model).__name__}, not a ZeroShotStyleVAE")
    spec = model.spec
    bad = [f"{key} {got!r} (want {want!r})" for key, got, want in (
        ("primitive", spec["primitive"], primitive), ("excluded_styles", model.excluded_styles, [style]),
        ("autoencoder", spec["autoencoder"]["fingerprint"], fingerprint)) if got != want]
    if bad:
        raise ZeroShotRunError(f"{path} is not the leave-{style}-out network of {primitive} on this run: "
                               + "; ".join(bad))
    return model


# -- one primitive


def _table_row(autoencoder, frames, style: str, columns: list[str], grams: torch.Tensor,
               settings: EvalSettings) -> dict[str, Any]:
    """Table 5.1 row of motions ``(n, T, 66)`` on the canonical timeline, its nearest column, its spread."""
    row = distance_table(autoencoder, [frames.numpy()], grams, settings.gram_chunk)[0]
    table_row = {c: float(d) for c, d in zip(columns, row)}
    nearest = min(table_row, key=table_row.get)
    return {"table_5_1_row": table_row, "nearest_column": nearest, "own_column_is_minimum": nearest == style,
            "pose_across_sd": across_sample_sd(frames.numpy())}


def _model_row(real, autoencoder, model: EvalModel, columns: list[str], grams: torch.Tensor, samples: int,
               seed: int, settings: EvalSettings) -> dict[str, Any]:
    """Recognition, Table 5.1 row and spread of ``samples`` samples of one model of a left-out style."""
    drawn = model.source.sample(samples, seed=seed)
    judged = recognition(real, model, real.features(drawn), real.features(real.truth[model.style]))
    return {"checkpoint": model.checkpoint, "recognition": judged.share, "predicted": judged.predicted,
            **_table_row(autoencoder, drawn.normalized_frames, model.style, columns, grams, settings),
            "samples": int(samples)}


def _real_row(real, autoencoder, style: str, columns: list[str], grams: torch.Tensor,
              settings: EvalSettings) -> dict[str, Any]:
    """The same figures of the style's real clips (all but its example): the reference of both models."""
    truth = real.truth[style]
    predicted = real.classifier.predict_features(real.features(truth))
    return {"recognition": float((predicted == style).mean()),
            **_table_row(autoencoder, truth.normalized_frames, style, columns, grams, settings),
            "clips": len(truth)}


def evaluate_primitive(primitive: str, left_out: Mapping[str, ZeroShotStyleVAE], cvaes: Sequence[EvalModel],
                       takeset: TakeSet, autoencoder, settings: EvalSettings, split: Mapping[str, Any] | None,
                       samples: int, seed: int, say: Say = print) -> dict[str, Any]:
    """Each left-out network of ``primitive`` against the CVAE of its style (see the module doc).

    Args:
        left_out: style → the network trained without it.
        cvaes: the run's CVAEs of ``primitive`` (every style: each gives a Table 5.1 column), one per style
            of ``left_out`` at least.
        takeset, split, settings: the run's data, split and evaluation settings.
        autoencoder: the run's autoencoder.
        samples, seed: samples per model and their seed.

    Raises:
        ZeroShotRunError: a left-out style without a CVAE, or a network on another timeline.
        MixedAutoencodersError: models of different autoencoders.
    """
    by_style = {m.style: m for m in cvaes}
    missing = [s for s in left_out if s not in by_style]
    if missing:
        raise ZeroShotRunError(f"{primitive}: no CVAE of style(s) {missing} in the run to compare with (CVAE styles "
                               f"{sorted(by_style)})")
    real = real_side(primitive, list(cvaes), takeset, settings, split, say)
    columns = [NEUTRAL] + [m.name for m in real.models]
    neutral = EvalModel(NEUTRAL, primitive, settings.neutral_style, source=None)  # its column: the mean motion
    grams = torch.stack([example_column_gram(autoencoder, real, m) for m in [neutral, *real.models]])
    out: dict[str, Any] = {"timeline_frames": real.length, "columns": columns,
                           "column_examples": {NEUTRAL: "mean motion of the neutral training clips",
                                               **{m.name: [c.describe() for c in real.examples[m.name]]
                                                  for m in real.models}},
                           "classifier": {k: real.classifier_result[k] for k in ("heldout_accuracy", "chance",
                                                                                  "styles")},
                           "styles": {}}
    for style, network in left_out.items():
        cvae = by_style[style]
        if network.timeline_frames != real.length:
            raise ZeroShotRunError(f"the {primitive} network without {style} uses a timeline of "
                                   f"{network.timeline_frames} frames, the run's models {real.length}: it was "
                                   "trained on other data (or datamodule.timeline)")
        # the CVAE's example clip(s), encoded as the network's training examples were (canonical length)
        bound = network.bind_example(real.examples[cvae.name], style, cvae.examples)
        model = EvalModel(f"zero_shot:{style}", primitive, style, bound, list(cvae.examples),
                          dict(network.spec["autoencoder"]), network.checkpoint_file, network.timeline_frames,
                          bound.target_gram, network.spec.get("dataset"), "canonical")
        check_one_autoencoder([cvae, model])
        say(f"{primitive}/{style}: {samples} samples of the network without {style} and of the {style} CVAE")
        out["styles"][style] = {
            "example": [dict(e) for e in cvae.examples], "trained_styles": network.styles,
            "zero_shot": _model_row(real, autoencoder, model, columns, grams, samples, seed, settings),
            "cvae": _model_row(real, autoencoder, cvae, columns, grams, samples, seed, settings),
            "real": _real_row(real, autoencoder, style, columns, grams, settings)}
    return out


# -- the whole evaluation


def _summary(per_primitive: Mapping[str, Any]) -> dict[str, Any]:
    """Per row kind: the mean recognition and how many rows have their own column as minimum."""
    out = {}
    for kind in ROWS:
        rows = [s[kind] for p in per_primitive.values() for s in p["styles"].values()]
        out[kind] = {"mean_recognition": sum(r["recognition"] for r in rows) / len(rows) if rows else math.nan,
                     "own_column_is_minimum": sum(r["own_column_is_minimum"] for r in rows), "rows": len(rows)}
    return out


def leave_one_style_out(run: str | Path, out: str | Path, styles: Sequence[str] | None = None,
                        primitives: Sequence[str] | None = None, epochs: int | None = None, samples: int = 1000,
                        seed: int | None = None, checkpoints: str | Path | None = None,
                        overrides: Sequence[str] = (), threads: Any = None, force: bool = False,
                        say: Say = print) -> dict[str, Any]:
    """The leave-one-style-out evaluation (see the module doc); returns what ``zero_shot.json`` holds.

    Args:
        run: a finished ``stylemotion-reproduce`` run folder.
        out: the output folder (must not exist unless ``force``, which replaces it).
        styles: left-out styles (default: every CVAE style of the run).
        primitives: default every primitive with CVAEs.
        epochs: training epochs of each network (None: the experiment's).
        samples, seed: samples per model and their seed (default the run's seed).
        checkpoints: an earlier output folder whose ``models/<p>_without_<s>/checkpoints/best.ckpt`` are taken
            instead of training (each checked: primitive, exclusion, autoencoder).
        overrides: further Hydra overrides of the networks' ``train`` config (e.g. ``model.style_weight=5``).
        threads: torch threads.

    Raises:
        OutputExistsError: ``out`` exists and ``force`` is off (before any work).
        ZeroShotRunError: see :func:`read_run`, :func:`load_left_out`, :func:`evaluate_primitive`; a style or
            primitive without a CVAE in the run.
    """
    started = time.perf_counter()
    out = check_new_output(Path(out).expanduser(), force)
    source = read_run(run)
    samples = positive_int(samples, "samples")
    seed = source.seed if seed is None else int(seed)
    set_torch_threads(threads)
    primitives = list(primitives or source.primitives)
    plan = {p: list(styles or source.styles(p)) for p in primitives}
    for p, wanted in plan.items():
        parse_primitive(p)
        absent = [s for s in wanted if (p, s) not in source.cvaes]
        if absent:
            raise ZeroShotRunError(f"run={source.folder} has no CVAE of {p} for style(s) {absent} (its CVAEs: "
                                   f"{sorted(f'{a}/{b}' for a, b in source.cvaes)})")
    if out.exists():
        shutil.rmtree(out)
    out.mkdir(parents=True)
    autoencoder = load_autoencoder(source.autoencoder_ckpt)
    weights = fingerprint(autoencoder)
    takeset = build_dataset(source.data_cfg)
    trained: dict[str, dict[str, Any]] = {}
    results: dict[str, Any] = {}
    for p, wanted in plan.items():
        networks = {}
        for s in wanted:
            if checkpoints is not None:
                path, seconds = model_folder(Path(checkpoints).expanduser(), p, s) / "checkpoints" / "best.ckpt", None
                say(f"{p} without {s}: taken from {path}")
            else:
                say(f"{p} without {s}: training")
                path, seconds = train_left_out(source, p, s, model_folder(out, p, s), epochs, overrides, threads)
                say(f"    trained in {seconds / 60:.1f} min")
            networks[s] = load_left_out(path, p, s, weights)
            networks[s].attach_autoencoder(autoencoder)
            trained.setdefault(p, {})[s] = {"checkpoint": str(path), "train_seconds": seconds}
        cvaes = [load_model(source.cvaes[(q, s)], source.settings.neutral_style, autoencoder)
                 for q, s in source.cvaes if q == p]
        results[p] = evaluate_primitive(p, networks, cvaes, takeset, autoencoder, source.settings,
                                        source.data_cfg.get("split"), samples, seed, say)
        for s, record in trained[p].items():
            results[p]["styles"][s]["zero_shot"]["train_seconds"] = record["train_seconds"]
    payload = {"primitives": results, "summary": _summary(results),
               "meta": {"run": str(source.folder.resolve()), "data": source.data_cfg, "seed": seed,
                        "samples": samples, "epochs": epochs, "overrides": list(overrides),
                        "checkpoints_from": None if checkpoints is None else str(checkpoints),
                        "settings": asdict(source.settings), **provenance(),
                        "seconds": time.perf_counter() - started}}
    write_json(out / "zero_shot.json", payload)
    atomic_write_bytes(out / "zero_shot.md", markdown(payload).encode())
    return payload


# -- the markdown table


def _table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(r) + " |" for r in rows])


def _pct(value: float) -> str:
    return "–" if value is None or not math.isfinite(value) else f"{100 * value:.0f} %"


def markdown(results: Mapping[str, Any]) -> str:
    """``zero_shot.md``: recognition of each left-out style and the Table 5.1 rows, zero-shot next to CVAE."""
    meta = results["meta"]
    lines = ["# One network for every style: leave one style out", "",
             f"Run `{meta['run']}`, {meta['samples']:,} samples per model (seed {meta['seed']}); each zero-shot "
             f"network was trained without any clip of the style it is conditioned on, the CVAE on the neutral "
             f"clips and that style's example. Git commit `{meta.get('git_commit', '?')}`; "
             f"{meta['seconds'] / 60:.1f} min.", "",
             "## Recognition of the left-out style", "",
             "Share of samples the style classifier (fitted on real train clips of every style) assigns to the "
             "style; `real`: the style's real clips (all but its example; the classifier was fitted on its "
             "train-split ones). Spread: pose_across_SD of the samples / of those real clips.", ""]
    rows = []
    for p, res in results["primitives"].items():
        for s, r in res["styles"].items():
            zs, cv, real = r["zero_shot"], r["cvae"], r["real"]
            rows.append([p, s, _pct(zs["recognition"]), _pct(cv["recognition"]), _pct(real["recognition"]),
                         _pct(zs["pose_across_sd"] / real["pose_across_sd"]),
                         _pct(cv["pose_across_sd"] / real["pose_across_sd"])])
    lines += [_table(["primitive", "left-out style", "zero-shot", "CVAE", "real", "zero-shot spread",
                      "CVAE spread"], rows), ""]
    summary = results["summary"]
    nearest = ", ".join(f"{label} {summary[kind]['own_column_is_minimum']}/{summary[kind]['rows']}"
                        for kind, label in (("zero_shot", "zero-shot"), ("cvae", "CVAE"), ("real", "real clips")))
    lines += [f"Mean recognition: zero-shot {_pct(summary['zero_shot']['mean_recognition'])}, CVAE "
              f"{_pct(summary['cvae']['mean_recognition'])}, real clips {_pct(summary['real']['mean_recognition'])}. "
              f"Rows whose minimum is the style's own example: {nearest}.", "",
              "## Table 5.1 rows", "",
              "D(model, example) = mean over the samples of ‖Gram(Φ(x)) − Gram(Φ(example))‖_F (eq. 5.12); columns: "
              "the neutral mean motion and each style's example; the row's minimum in bold; `real`: the style's "
              "real clips in place of samples.", ""]
    for p, res in results["primitives"].items():
        body = []
        for s, r in res["styles"].items():
            for kind, label in (("zero_shot", f"zero-shot without {s}"), ("cvae", f"CVAE {s}"),
                                ("real", f"real {s} clips")):
                row = r[kind]["table_5_1_row"]
                low = min(row.values())
                body.append([f"{label} → {s}"] + [f"**{v:.4g}**" if v == low else f"{v:.4g}" for v in row.values()])
        lines += [f"**{p}**", "", _table(["model → style", *res["columns"]], body), ""]
    return "\n".join(lines)
