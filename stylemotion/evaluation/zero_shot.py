"""Leave-one-style-out evaluation of the zero-shot style network, without leakage, against a reproduce run's CVAEs.

    python scripts/benchmarks.py run zero_shot --run <finished reproduce run>      # the suite (3 seeds)

For each primitive ``p`` of a finished ``stylemotion-reproduce`` run and each of its CVAE styles ``s``
(or ``styles``), with one ``seed`` (of the autoencoder, the network and the samples):

1. **a generator that never saw s**: an autoencoder trained without any take of ``s`` (the run's autoencoder
   stage settings on the run's data and split, ``datamodule.exclude_styles=[s]``) into
   ``<out>/autoencoders/without_<s>/``, and on its features a
   :class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE` trained without any clip of ``s``
   (``experiment=zero_shot``, ``datamodule.exclude_styles=[s]``) into ``<out>/models/<p>_without_<s>/``;
2. conditioned on s's example: the clip(s) the run's CVAE of ``(p, s)`` was trained with (its recorded
   ``spec.style_examples``), encoded by the generator's autoencoder at the canonical length, as the network's
   training examples were;
3. ``samples`` samples of it, decoded to motion by **its own** autoencoder (its feature statistics and its frame
   normalization), and ``samples`` samples of the run's CVAE of s (the supervised baseline: it was trained on
   s's example), and for each, measured in **one judge space**, the run's autoencoder and style classifier
   (trained on every style, s included, as an FID network is: a fixed measuring instrument that never
   generates; the decoded frames are re-encoded there with the judge's own normalization):

   * **recognition**: the share the run's style classifier assigns to ``s``
     (:func:`stylemotion.evaluation.pipeline.real_side`, fitted on the train split of every style);
   * **Table 5.1 row**: the mean Gram distance, in the judge autoencoder's features, of the samples to every
     column of the run's Table 5.1 (the neutral mean motion and each CVAE style's example;
     :func:`stylemotion.evaluation.tables.distance_table`) and whether s's own column is the row's minimum;
   * ``pose_across_sd`` (cm): the spread across samples at aligned frames (a model that copies the example
     scores near 0);

   and the same figures of s's real clips (all but the example) in place of samples (row ``real``), and of
   those clips encoded and decoded by the generator's autoencoder (row ``reconstructed``: how much of the style
   its features keep, a ceiling of what a network on them can show);

4. ``<out>/zero_shot.json`` and ``<out>/zero_shot.md``.

``groups`` leaves styles out together (e.g. every style of one actor: one autoencoder and one network per group,
``without_<s1>+<s2>…``, serve each of its styles), so the generator never saw the style's actor either. ``report``
names the run's report whose evaluation settings the judge takes (``report_test``: every ``real`` row holds the
style's test clips only). Every row also carries the raw foot skating of its motions (``foot_skating``).

``shared_autoencoder=True`` keeps the earlier protocol: the network is trained on the run's autoencoder, which
saw s. Its output is labelled **leaky** (``meta.leaky``) and is no evidence that the network generalizes to an
unseen style. ``out`` must not exist unless ``force`` (replace it) or ``resume`` (reuse the finished trainings in
it, resume interrupted ones). ``stages`` keeps the autoencoders and the ``cvae_unseen`` CVAEs in another folder,
which arms that differ only in their networks (e.g. the networks' epochs) share.
"""

from __future__ import annotations

import hashlib
import json
import logging
import math
import shutil
import time
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import torch
from omegaconf import DictConfig, OmegaConf, open_dict

from stylemotion.config import config_dir, positive_int, set_torch_threads
from stylemotion.datasets import TakeSet, build_dataset
from stylemotion.evaluation.metrics import diversity, foot_skating
from stylemotion.evaluation.pipeline import example_column_gram, real_side, recognition
from stylemotion.evaluation.settings import EvalSettings
from stylemotion.evaluation.sources import MixedAutoencodersError, check_one_autoencoder
from stylemotion.evaluation.tables import across_sample_sd, distance_table, variance_stats
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.io.errors import UserInputError
from stylemotion.io.jsonfile import read_json_object as read_record
from stylemotion.io.jsonfile import write_json
from stylemotion.io.outputs import check_new_output, inside, safe_name
from stylemotion.models.checkpoints import fingerprint, load_autoencoder, read_checkpoint
from stylemotion.models.loading import NEUTRAL, EvalModel, load_generative, load_model, zero_shot_model
from stylemotion.models.sampling import decode_features, motions_from_normalized
from stylemotion.models.zero_shot import ZeroShotStyleVAE, checked_temperature
from stylemotion.primitives.segmentation import parse_primitive
from stylemotion.provenance import provenance
from stylemotion.training.reproduction import stage_train_config
from stylemotion.training.run_folder import FinishedRun, read_json_object

log = logging.getLogger(__name__)

log = logging.getLogger(__name__)
#: The rows of each left-out style: the two models, the style's real clips, and those clips through the
#: generator's autoencoder.
ROWS = ("zero_shot", "cvae", "real", "reconstructed")
#: The row ``cvae_unseen=True`` adds: a CVAE of the style trained as the run's, on the generator's autoencoder.
UNSEEN_ROW = "cvae_unseen"
#: What ``meta.leaky`` says of an output of the shared-autoencoder protocol.
LEAKY = ("the networks were trained on the run's autoencoder, which was trained on every style, the left-out one "
         "included: the left-out style leaked into the generator (not evidence of generalization to an unseen style)")


class ZeroShotRunError(UserInputError, ValueError):
    """The reproduce run (or a given checkpoint) cannot serve the leave-one-style-out evaluation."""


# -- the reproduce run


@dataclass
class ReproduceRun(FinishedRun):
    """What the evaluation reads of a finished ``stylemotion-reproduce`` run (see :func:`read_run` and
    :class:`stylemotion.training.run_folder.FinishedRun`): its CVAEs by primitive and style, and the name of the
    report whose settings it carries (``report_name``)."""

    report_name: str = "report"

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


def read_run(folder: str | Path, report: str = "report") -> ReproduceRun:
    """The finished reproduce run in ``folder``, with the evaluation settings of its report ``report`` (the run's
    own, or a second report ``stylemotion-reproduce ... report=<name>`` made, e.g. ``report_test``: the
    leave-one-style-out then reads the held-out splits and ground truth that report was made with).

    Raises:
        ZeroShotRunError: no such folder, no ``reproduce.json`` or report, no autoencoder or CVAE stage, or
            a stage checkpoint that is gone (each message says which).
    """
    folder = Path(folder).expanduser()
    name = str(report)
    if not name or name != safe_name(name, "report"):
        raise ZeroShotRunError(f"report={report!r} is not the name of a report folder in the run (e.g. report, "
                               "report_test)")
    summary_path, report_path = folder / "reproduce.json", folder / name / "report.json"
    for path, what in ((summary_path, "reproduce.json"), (report_path, f"report ({name}/report.json)")):
        if not path.is_file():
            raise ZeroShotRunError(f"run={folder} is not a finished stylemotion-reproduce run: it has no {what}")
    run = ReproduceRun(folder, read_json_object(summary_path, "summary", ZeroShotRunError),
                       read_json_object(report_path, "report", ZeroShotRunError), name)
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


def _quiet(cfg: DictConfig) -> DictConfig:
    """``cfg`` without a progress bar (several trainings in a row would fill the log)."""
    with open_dict(cfg):
        cfg.trainer.enable_progress_bar = False
        if cfg.get("callbacks") and "progress_bar" in cfg.callbacks:
            cfg.callbacks.progress_bar = None
    return cfg


def network_train_config(run: FinishedRun, primitive: str, folder: Path, epochs: int | None = None,
                         overrides: Sequence[str] = (), threads: Any = None, exclude: Sequence[str] = (),
                         epochs_key: str = "epochs", autoencoder_ckpt: str | Path | None = None,
                         seed: int | None = None) -> DictConfig:
    """The ``train`` config of a zero-shot network of ``primitive`` on ``run``'s data, started afresh in
    ``folder``: ``experiment=zero_shot``, ``trainer.max_epochs=epochs`` (None: the experiment's; ``epochs_key``
    names it in errors), the ``overrides``, then the run's data and neutral style, ``seed`` (None: the run's),
    ``autoencoder_ckpt`` (None: the run's autoencoder), and ``exclude`` left out. Composes inside Hydra's config
    search (:func:`hydra_configs`)."""
    from hydra import compose

    listed = ["experiment=zero_shot"] + ([f"trainer.max_epochs={positive_int(epochs, epochs_key)}"] if epochs else [])
    with hydra_configs():
        cfg = compose(config_name="train", overrides=listed + list(overrides))
    with open_dict(cfg):
        cfg.data = OmegaConf.create(run.data_cfg)
        cfg.output_dir = str(Path(folder).resolve())
        cfg.seed = run.seed if seed is None else int(seed)
        if threads is not None:
            cfg.threads = positive_int(threads, "threads")
        cfg.primitive = primitive
        cfg.autoencoder_ckpt = str(run.autoencoder_ckpt if autoencoder_ckpt is None else autoencoder_ckpt)
        cfg.datamodule.neutral_style = run.settings.neutral_style
        cfg.datamodule.exclude_styles = list(exclude)
    return cfg


def left_out(style: str | Sequence[str]) -> list[str]:
    """The styles a leave-out removes: one style, or a group (e.g. an actor's styles), sorted."""
    return [style] if isinstance(style, str) else sorted(style)


def train_config(run: ReproduceRun, primitive: str, style: str | Sequence[str], folder: Path,
                 epochs: int | None = None, overrides: Sequence[str] = (), threads: Any = None,
                 autoencoder_ckpt: str | Path | None = None, seed: int | None = None) -> DictConfig:
    """The ``train`` config of the zero-shot network of ``primitive`` without ``style`` (a style or a group of
    styles, :func:`left_out`; :func:`network_train_config`: on ``autoencoder_ckpt``, None the run's), without a
    progress bar."""
    return _quiet(network_train_config(run, primitive, folder, epochs, overrides, threads, exclude=left_out(style),
                                       autoencoder_ckpt=autoencoder_ckpt, seed=seed))


def autoencoder_train_config(run: FinishedRun, style: str | Sequence[str], folder: Path, seed: int | None = None,
                             threads: Any = None) -> DictConfig:
    """The ``train`` config of an autoencoder that never sees ``style`` (a style or a group, :func:`left_out`): the
    run's autoencoder stage (its Hydra overrides as ``reproduce.json`` records them, its data and split), ``seed``
    (None: the run's) and ``datamodule.exclude_styles`` (every take of those styles left out of every split, after
    splitting: the other takes keep their parts), into ``folder``, without a progress bar."""
    stage = run.stages("autoencoder")[0]
    with hydra_configs():
        cfg = stage_train_config(list(stage.get("overrides") or []), dict(stage.get("values") or {}), run.data_cfg,
                                 folder, run.seed if seed is None else int(seed), threads)
    with open_dict(cfg):
        cfg.datamodule.exclude_styles = left_out(style)
    return _quiet(cfg)


#: The networks' ``model.*`` keys that change only how a trained network samples (left out of a training's hash).
SAMPLING_ONLY = ("sample_temperature", "sample_centred", "sample_pooling")


def _settings_hash(cfg: DictConfig) -> str:
    """A hash of what a training computes from (``threads``, ``ckpt_path``, the fresh ``run_id`` and the network's
    :data:`SAMPLING_ONLY` keys left out: they change no trained weight)."""
    values = {k: v for k, v in OmegaConf.to_container(cfg, resolve=True).items()
              if k not in ("threads", "ckpt_path", "run_id")}
    if isinstance(values.get("model"), dict):
        values["model"] = {k: v for k, v in values["model"].items() if k not in SAMPLING_ONLY}
    return hashlib.sha256(json.dumps(values, sort_keys=True, default=str).encode()).hexdigest()[:16]


def train_once(cfg: DictConfig, what: str) -> tuple[Path, float | None]:
    """Train ``cfg`` into its ``output_dir``, or reuse the training that finished there with the same settings
    (its ``done.json``); an interrupted one resumes from ``last.ckpt``. Returns the best checkpoint and the
    training seconds (None when reused).

    Raises:
        ZeroShotRunError: the folder holds a finished training of other settings (delete it or choose another
            output folder).
    """
    from stylemotion.training.fit import run as train_run

    folder = Path(cfg.output_dir)
    done, settings = folder / "done.json", _settings_hash(cfg)
    if done.is_file():
        record = read_record(done, f"the record of {what}", f"delete {folder} to train it again")
        checkpoint = folder / str(record.get("checkpoint"))
        if record.get("settings_hash") != settings:
            raise ZeroShotRunError(f"{folder} holds {what} trained with other settings (hash "
                                   f"{record.get('settings_hash')}, now {settings}); delete it or choose another out")
        if checkpoint.is_file():
            log.info(f"{what}: reused {checkpoint}")
            return checkpoint, None
    with open_dict(cfg):
        cfg.ckpt_path = "auto"
    log.info(f"{what}: training")
    t0 = time.perf_counter()
    metrics = train_run(cfg)["metrics"]
    seconds = time.perf_counter() - t0
    best = Path(metrics.get("best_checkpoint") or folder / "checkpoints" / "last.ckpt").resolve()
    write_json(done, {"settings_hash": settings, "checkpoint": str(best.relative_to(folder.resolve())),
                      "seconds": seconds, "what": what})
    log.info(f"    trained in {seconds / 60:.1f} min")
    return best, seconds


def autoencoder_excluded_styles(path: str | Path) -> list[str]:
    """The styles an autoencoder checkpoint's training data left out (``datamodule.exclude_styles`` as Lightning
    saved it; ``[]`` for one trained on every style)."""
    saved = read_checkpoint(path, "autoencoder checkpoint").get("datamodule_hyper_parameters") or {}
    return [str(s) for s in saved.get("exclude_styles") or []]


def _without(style: str | Sequence[str]) -> str:
    """``without_<s>``, or ``without_<s1>+<s2>…`` for a group (:func:`left_out`)."""
    return "without_" + "+".join(safe_name(s, "style label") for s in left_out(style))


def model_folder(out: Path, primitive: str, style: str | Sequence[str]) -> Path:
    """Where the network of ``primitive`` without ``style`` (a style or a group) is trained:
    ``<out>/models/<p>_without_<s>`` (``<p>_without_<s1>+<s2>…``)."""
    return inside(out, "models", f"{primitive}_{_without(style)}")


def autoencoder_folder(out: Path, style: str | Sequence[str]) -> Path:
    """Where the autoencoder without ``style`` (a style or a group) is trained: ``<out>/autoencoders/without_<s>``
    (``without_<s1>+<s2>…``)."""
    return inside(out, "autoencoders", _without(style))


def load_left_out(path: Path, primitive: str, style: str | Sequence[str], fingerprint: str) -> ZeroShotStyleVAE:
    """A zero-shot checkpoint, checked to be of ``primitive``, trained without ``style`` (a style or a group) and on
    the autoencoder of weights ``fingerprint``.

    Raises:
        ZeroShotRunError: another kind of model, primitive, exclusion or autoencoder.
    """
    model = load_generative(path)
    if not isinstance(model, ZeroShotStyleVAE):
        raise ZeroShotRunError(f"{path} is a {type(model).__name__}, not a ZeroShotStyleVAE")
    spec = model.spec
    bad = [f"{key} {got!r} (want {want!r})" for key, got, want in (
        ("primitive", spec["primitive"], primitive), ("excluded_styles", sorted(model.excluded_styles),
                                                      left_out(style)),
        ("autoencoder", spec["autoencoder"]["fingerprint"], fingerprint)) if got != want]
    if bad:
        raise ZeroShotRunError(f"{path} is not the leave-{'+'.join(left_out(style))}-out network of {primitive} on "
                               "this autoencoder: "
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


def _skating(real, motions, settings: EvalSettings) -> dict[str, float | int]:
    """Raw foot skating of motions (:func:`~stylemotion.primitives.skating.foot_skating`: the share of contact
    foot-frames whose planted point moves faster than ``settings.skate_speed_mps``), as the report measures it."""
    data = real.data
    return foot_skating(motions.positions.numpy(), motions.num_frames.numpy(), motions.fps, data.rest_heights,
                        data.stance_foot, settings.skate_speed_mps).as_dict()


def _variation(real, motions, settings: EvalSettings) -> dict[str, float]:
    """pose_SD (cm), V_SD, step_SD (cm) (:func:`~stylemotion.evaluation.tables.variance_stats`) and diversity (mean
    pairwise distance in the classifier's features, :func:`~stylemotion.evaluation.metrics.diversity`) of motions."""
    stats = variance_stats(motions.frames.numpy(), motions.positions.numpy(), motions.num_frames.numpy())
    return {**{k: float(stats[k]) for k in ("pose_sd", "v_sd", "step_sd")},
            "diversity": float(diversity(real.features(motions), settings.diversity_items))}


def _model_row(real, autoencoder, model: EvalModel, columns: list[str], grams: torch.Tensor, samples: int,
               seed: int, settings: EvalSettings) -> dict[str, Any]:
    """Recognition, Table 5.1 row, spread and variation of ``samples`` samples of one model of a left-out style."""
    drawn = model.source.sample(samples, seed=seed)
    judged = recognition(real, model, real.features(drawn), real.features(real.truth[model.style]))
    return {"checkpoint": model.checkpoint, "recognition": judged.share, "predicted": judged.predicted,
            **_table_row(autoencoder, drawn.normalized_frames, model.style, columns, grams, settings),
            "variation": _variation(real, drawn, settings), "foot_skating": _skating(real, drawn, settings),
            "samples": int(samples)}


def _real_row(real, autoencoder, style: str, columns: list[str], grams: torch.Tensor,
              settings: EvalSettings) -> dict[str, Any]:
    """The same figures of the style's real clips (all but its example): the reference of both models."""
    truth = real.truth[style]
    predicted = real.classifier.predict_features(real.features(truth))
    return {"recognition": float((predicted == style).mean()),
            **_table_row(autoencoder, truth.normalized_frames, style, columns, grams, settings),
            "variation": _variation(real, truth, settings), "foot_skating": _skating(real, truth, settings),
            "clips": len(truth)}


@torch.no_grad()
def _reconstructed_row(real, autoencoder, generator_ae, style: str, columns: list[str], grams: torch.Tensor,
                       settings: EvalSettings) -> dict[str, Any]:
    """The figures of the style's real clips (those of :func:`_real_row`) encoded and decoded by the generator's
    autoencoder ``generator_ae``, measured by the judge: what its feature space keeps of the style, and their raw
    foot skating at their recorded durations (what a model decoding through it starts from); beside it
    (``foot_skating_timeline``) the skating of the same clips only resampled to the canonical timeline and back, no
    autoencoder (what the representation alone costs), and (``foot_skating_judge``) through the judge's
    ``autoencoder``, which saw the style (what an autoencoder costs a style it was trained on)."""
    truth = real.truth[style]
    rebuilt = _through(generator_ae, truth, real.length)
    frames = rebuilt.normalized_frames  # (n, T, 66) frames on the canonical timeline
    predicted = real.classifier.predict(frames.numpy(), truth.duration_s.numpy())
    timeline = motions_from_normalized(truth.normalized_frames, truth.duration_s, truth.fps)
    return {"recognition": float((predicted == style).mean()),
            **_table_row(autoencoder, frames, style, columns, grams, settings),
            "foot_skating": _skating(real, rebuilt, settings),
            "foot_skating_timeline": _skating(real, timeline, settings),
            "foot_skating_judge": _skating(real, _through(autoencoder, truth, real.length), settings),
            "clips": len(truth)}


def _through(autoencoder, motions, length: int):
    """Motions' time-normalized frames encoded and decoded by ``autoencoder``, played back at their durations."""
    features = autoencoder.encode(motions.normalized_frames.float())
    return decode_features(autoencoder, features, motions.duration_s, length, motions.fps)


def generator_autoencoder(network: ZeroShotStyleVAE) -> dict[str, Any]:
    """``path``/``fingerprint`` of the autoencoder ``network`` decodes with, checked to be the one it was trained
    on: its feature statistics (``feature_mean``/``feature_std``) and its decoder's frame normalization belong to
    that autoencoder, so its samples are de-normalized there and only their decoded frames reach the judge.

    Raises:
        MixedAutoencodersError: the network decodes with another autoencoder than its features came from.
    """
    info = dict(network.spec["autoencoder"])
    got = fingerprint(network.autoencoder)
    if got != info["fingerprint"]:
        raise MixedAutoencodersError(f"{network.checkpoint_file or 'the network'} decodes with an autoencoder of "
                                     f"weights {got}, not the one it was trained on ({info['fingerprint']}, "
                                     f"{info.get('path')}): load it again without attaching another autoencoder")
    return {"path": info.get("path"), "fingerprint": got}


def evaluate_primitive(primitive: str, left_out: Mapping[str, ZeroShotStyleVAE], cvaes: Sequence[EvalModel],
                       takeset: TakeSet, autoencoder, settings: EvalSettings, split: Mapping[str, Any] | None,
                       samples: int, seed: int, shared_autoencoder: bool = False,
                       unseen_cvaes: Mapping[str, EvalModel] | None = None) -> dict[str, Any]:
    """Each left-out network of ``primitive`` against the CVAE of its style, in one judge space (module doc).

    Args:
        left_out: style → the network trained without it, decoding with the autoencoder it was trained on
            (:func:`generator_autoencoder`; for ``shared_autoencoder``, the judge ``autoencoder``).
        cvaes: the run's CVAEs of ``primitive`` (every style: each gives a Table 5.1 column), one per style
            of ``left_out`` at least.
        takeset, split, settings: the run's data, split and evaluation settings.
        autoencoder: the judge: the run's autoencoder (its CVAEs' features, the Table 5.1 space). Samples
            reach it as decoded frames and are re-encoded with its own frame normalization.
        samples, seed: samples per model and their seed.
        shared_autoencoder: the networks must decode with the judge autoencoder itself (the leaky protocol).
        unseen_cvaes: style → a CVAE of it trained on the network's autoencoder (row ``cvae_unseen``), or None.

    Raises:
        ZeroShotRunError: a left-out style without a CVAE, or a network on another timeline.
        MixedAutoencodersError: a network decoding with another autoencoder than its own (or, with
            ``shared_autoencoder``, than the judge).
    """
    by_style = {m.style: m for m in cvaes}
    missing = [s for s in left_out if s not in by_style]
    if missing:
        raise ZeroShotRunError(f"{primitive}: no CVAE of style(s) {missing} in the run to compare with (CVAE styles "
                               f"{sorted(by_style)})")
    real = real_side(primitive, list(cvaes), takeset, settings, split)
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
        generator = generator_autoencoder(network)
        # the CVAE's example clip(s) (frames), encoded by the network's own autoencoder as its training examples
        # were (canonical length); its samples come back as frames decoded by that autoencoder
        model = zero_shot_model(network, style, cvae.examples, real.examples[cvae.name])
        if shared_autoencoder:
            check_one_autoencoder([cvae, model], fingerprint(autoencoder))
        log.info(f"{primitive}/{style}: {samples} samples of the network without {style} and of the {style} CVAE")
        out["styles"][style] = {
            "example": [dict(e) for e in cvae.examples], "trained_styles": network.styles,
            "generator_autoencoder": generator,
            "zero_shot": _model_row(real, autoencoder, model, columns, grams, samples, seed, settings),
            "cvae": _model_row(real, autoencoder, cvae, columns, grams, samples, seed, settings),
            "real": _real_row(real, autoencoder, style, columns, grams, settings),
            "reconstructed": _reconstructed_row(real, autoencoder, network.autoencoder, style, columns, grams,
                                                settings)}
        if unseen_cvaes and style in unseen_cvaes:
            out["styles"][style][UNSEEN_ROW] = _model_row(real, autoencoder, unseen_cvaes[style], columns, grams,
                                                          samples, seed, settings)
    return out


# -- the whole evaluation


def _summary(per_primitive: Mapping[str, Any]) -> dict[str, Any]:
    """Per row kind: the mean recognition and how many rows have their own column as minimum."""
    out = {}
    for kind in (*ROWS, UNSEEN_ROW):
        rows = [s[kind] for p in per_primitive.values() for s in p["styles"].values() if kind in s]
        if not rows and kind == UNSEEN_ROW:
            continue
        out[kind] = {"mean_recognition": sum(r["recognition"] for r in rows) / len(rows) if rows else math.nan,
                     "own_column_is_minimum": sum(r["own_column_is_minimum"] for r in rows), "rows": len(rows)}
    return out


def left_out_groups(groups: Mapping[str, Sequence[str]] | None, styles: Sequence[str],
                    neutral_style: str) -> dict[str, list[str]]:
    """Each left-out style → the sorted styles left out with it (:func:`leave_one_style_out`'s ``groups``).

    Raises:
        ZeroShotRunError: a group without its own style, or one holding the neutral style.
    """
    out = {}
    for s in styles:
        group = left_out(list((groups or {}).get(s) or [s]))
        if s not in group:
            raise ZeroShotRunError(f"groups: the group of left-out style {s!r} is {group}, which does not hold it")
        if neutral_style in group:
            raise ZeroShotRunError(f"groups: the group of {s!r} holds the neutral style {neutral_style!r}, which every "
                                   "network needs: leave that style out alone")
        out[s] = group
    return out


def splits_record(source: ReproduceRun, shared_autoencoder: bool) -> dict[str, Any]:
    """What each model and the judge saw (the ``splits`` entry of ``zero_shot.json``)."""
    return {
        "data": {"kind": "by take", **dict(source.data_cfg.get("split") or {}), "group_by": ["content", "style"]},
        "judge": "the run's autoencoder (Table 5.1 features) and style classifier (fitted on the train-split clips "
                 "of every style, the left-out one included): a fixed measuring instrument that never generates",
        "generator_autoencoder": (LEAKY if shared_autoencoder else
                                  "the run's autoencoder stage settings on the run's split minus every take of the "
                                  "left-out style, or of every style of its group (meta.left_out_groups; train, val "
                                  "and test): it never saw the style"),
        "network": "the train-split clips of every style but the left-out one(s) (val: its val-split clips), "
                   "features of the generator's autoencoder",
        "condition": "the example clip(s) of the run's CVAE of the left-out style",
        "cvae": "the run's CVAE of the style: its neutral train clips plus the style's example clip (supervised "
                "baseline; the run's autoencoder)",
        "real": real_clips(source.settings),
        "report": source.report_name,
    }


def real_clips(settings: EvalSettings) -> str:
    """Which clips of a left-out style its ``real`` row (the variation's and skating's reference) holds."""
    if settings.style_truth == "heldout":
        return (f"the left-out style's clips of the {' and '.join(settings.heldout_splits)} split(s) only, but its "
                "example")
    return "the left-out style's clips of every split but its example"


def leave_one_style_out(run: str | Path, out: str | Path, styles: Sequence[str] | None = None,
                        primitives: Sequence[str] | None = None, epochs: int | None = None, samples: int = 1000,
                        seed: int | None = None, overrides: Sequence[str] = (), threads: Any = None,
                        force: bool = False, resume: bool = False, shared_autoencoder: bool = False,
                        cvae_unseen: bool = False, stages: str | Path | None = None,
                        networks: str | Path | None = None, temperature: float | None = None,
                        centred: bool | None = None, report: str = "report",
                        groups: Mapping[str, Sequence[str]] | None = None) -> dict[str, Any]:
    """The leave-one-style-out evaluation (see the module doc); returns what ``zero_shot.json`` holds.

    Args:
        run: a finished ``stylemotion-reproduce`` run folder (the judge and the CVAE baseline).
        groups: left-out style → the styles left out with it (it included), e.g. every style of its actor: the
            autoencoder and the network then never saw that actor (one of each per group serves each of its
            styles); None or a style not in it: the style alone. The neutral style cannot be left out.
        report: the run's report whose evaluation settings the judge takes (:func:`read_run`): ``report``, or a
            second report such as ``report_test`` (``evaluation.heldout_splits=[test]
            evaluation.style_truth=heldout``: the real clips and the classifier's held-out clips are test clips).
        out: the output folder (must not exist unless ``force``, which replaces it, or ``resume``).
        styles: left-out styles (default: every CVAE style of the run).
        primitives: default every primitive with CVAEs.
        epochs: training epochs of each network (None: the experiment's); the autoencoders train as the run's.
        samples: samples per model.
        seed: the seed of the autoencoders, the networks and the samples (default the run's seed).
        overrides: further Hydra overrides of the networks' ``train`` config (e.g. ``model.style_weight=5``).
        threads: torch threads.
        resume: keep ``out`` and reuse the trainings that finished there (same settings), resume interrupted ones.
        shared_autoencoder: the earlier, **leaky** protocol: networks on the run's autoencoder (``meta.leaky``).
        cvae_unseen: also train, per left-out style and primitive, a CVAE exactly as the run's CVAE stage but on
            the generator's autoencoder (which never saw the style; the same example clips) into
            ``<out>/models/<p>_cvae_on_without_<s>``: row ``cvae_unseen``, what ``stylemotion-style method=cvae``
            gives a user whose style the run's autoencoder never saw.
        stages: the folder of the autoencoders without each style and of the ``cvae_unseen`` CVAEs (default
            ``out``; created when missing, its finished trainings reused): arms that differ only in the networks
            (e.g. their epochs) share them, so every arm is judged on the same generators and CVAEs.
        networks: the folder the networks are trained in (default ``out``; its finished trainings reused): arms that
            differ only in how the networks sample (``temperature``) share them.
        temperature: sample every network with ``z ~ N(0, τ² I)``
            (:meth:`~stylemotion.models.zero_shot.ZeroShotStyleVAE.set_sample_temperature`; None: the network's
            own, ``model.sample_temperature``).
        centred: sample every network with its variation centred on the example
            (:meth:`~stylemotion.models.zero_shot.ZeroShotStyleVAE.set_sample_centred`; None: the network's own).

    Raises:
        OutputExistsError: ``out`` exists and neither ``force`` nor ``resume`` is on (before any work).
        ZeroShotRunError: see :func:`read_run`, :func:`load_left_out`, :func:`evaluate_primitive`,
            :func:`train_once`; a style or primitive without a CVAE in the run; an autoencoder that saw its
            left-out style.
    """
    started = time.perf_counter()
    out = Path(out).expanduser()
    if not (resume and out.is_dir()):
        out = check_new_output(out, force)
    stages = out if stages is None else Path(stages).expanduser()
    networks_out = out if networks is None else Path(networks).expanduser()
    for name, folder in (("stages", stages), ("networks", networks_out)):
        if folder.exists() and not folder.is_dir():
            raise ZeroShotRunError(f"{name}={folder} is a file, not a folder of trainings")
    if temperature is not None:
        temperature = checked_temperature(temperature)
    source = read_run(run, report)
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
    excluded = left_out_groups(groups, [s for wanted in plan.values() for s in wanted],
                               source.settings.neutral_style)
    if out.exists() and not resume:
        shutil.rmtree(out)
    out.mkdir(parents=True, exist_ok=True)
    stages.mkdir(parents=True, exist_ok=True)
    networks_out.mkdir(parents=True, exist_ok=True)
    judge = load_autoencoder(source.autoencoder_ckpt)
    judge_info = {"path": str(source.autoencoder_ckpt.resolve()), "fingerprint": fingerprint(judge)}
    takeset = build_dataset(source.data_cfg)
    generators: dict[tuple[str, ...], dict[str, Any]] = {}  # left-out styles → their autoencoder
    results: dict[str, Any] = {}
    for p, wanted in plan.items():
        networks, trained, by_group = {}, {}, {}
        for s in wanted:
            group = tuple(excluded[s])
            if group not in generators:
                generators[group] = _generator_autoencoder(source, group, stages, seed, threads, shared_autoencoder)
            gen = generators[group]
            if group not in by_group:  # one network per left-out group serves each of its styles
                cfg = train_config(source, p, group, model_folder(networks_out, p, group), epochs, overrides,
                                   threads, gen["path"], seed)
                path, seconds = train_once(cfg, f"{p} network without {'+'.join(group)}")
                network = load_left_out(path, p, group, gen["fingerprint"])
                if temperature is not None:
                    network.set_sample_temperature(temperature)
                if centred is not None:
                    network.set_sample_centred(centred)
                if shared_autoencoder:
                    network.attach_autoencoder(judge)  # one module for all (the same weights)
                by_group[group] = (network, path, seconds)
            network, path, seconds = by_group[group]
            networks[s] = network
            trained[s] = {"checkpoint": str(path), "train_seconds": seconds,
                          "sample_temperature": network.sample_temperature,
                          "sample_centred": network.sample_centred, "left_out": list(group)}
        cvaes = [load_model(source.cvaes[(q, s)], source.settings.neutral_style, judge)
                 for q, s in source.cvaes if q == p]
        unseen_trained = ({s: _unseen_cvae(source, p, s, stages, seed, threads, generators[tuple(excluded[s])], cvaes,
                                           excluded[s]) for s in wanted}
                          if cvae_unseen and not shared_autoencoder else {})
        unseen = {s: model for s, (model, _) in unseen_trained.items()} or None
        results[p] = evaluate_primitive(p, networks, cvaes, takeset, judge, source.settings,
                                        source.data_cfg.get("split"), samples, seed, shared_autoencoder, unseen)
        for s, record in trained.items():
            row = results[p]["styles"][s]
            row["zero_shot"]["train_seconds"] = record["train_seconds"]
            row["zero_shot"]["sample_temperature"] = record["sample_temperature"]
            row["zero_shot"]["sample_centred"] = record["sample_centred"]
            row["left_out"] = record["left_out"]
            if s in unseen_trained:
                row[UNSEEN_ROW]["train_seconds"] = unseen_trained[s][1]
            generator = generators[tuple(excluded[s])]
            row["generator_autoencoder"].update({k: v for k, v in generator.items() if k != "path"},
                                                path=str(generator["path"]))
    payload = {"primitives": results, "summary": _summary(results), "splits": splits_record(source, shared_autoencoder),
               "meta": {"run": str(source.folder.resolve()), "data": source.data_cfg, "seed": seed,
                        "samples": samples, "epochs": epochs, "overrides": list(overrides),
                        "leaky": LEAKY if shared_autoencoder else False, "cvae_unseen": bool(unseen),
                        "autoencoders": "shared (the run's)" if shared_autoencoder else "one per left-out style",
                        "stages": str(stages.resolve()), "networks": str(networks_out.resolve()),
                        "temperature": temperature, "centred": centred, "report": source.report_name,
                        "left_out_groups": {s: list(g) for s, g in excluded.items()},
                        "judge_autoencoder": judge_info,
                        "settings": asdict(source.settings), **provenance(),
                        "seconds": time.perf_counter() - started}}
    write_json(out / "zero_shot.json", payload)
    atomic_write_bytes(out / "zero_shot.md", markdown(payload).encode())
    return payload


def unseen_cvae_folder(out: Path, primitive: str, style: str, group: Sequence[str] | None = None) -> Path:
    """Where the CVAE of ``style`` on the autoencoder without it is trained: ``<out>/models/<p>_cvae_on_without_<s>``
    (on the autoencoder without a ``group`` holding more styles: ``<p>_cvae_<s>_on_without_<s1>+<s2>…``)."""
    if group is None or left_out(group) == [style]:
        return inside(out, "models", f"{primitive}_cvae_on_{_without(style)}")
    return inside(out, "models", f"{primitive}_cvae_{safe_name(style, 'style label')}_on_{_without(group)}")


def _unseen_cvae(source: ReproduceRun, primitive: str, style: str, out: Path, seed: int, threads: Any,
                 generator: Mapping[str, Any], run_cvaes: Sequence[EvalModel],
                 group: Sequence[str] | None = None) -> tuple[EvalModel, float | None]:
    """The CVAE of ``style`` trained as the run's CVAE stage of ``(primitive, style)`` (its overrides and values) but
    on the ``generator`` autoencoder (trained without the style), loaded with that autoencoder, and its training
    seconds (None when reused).

    Raises:
        ZeroShotRunError: its example clips differ from the run's CVAE's (the comparison would not be like for like).
    """
    stage = next(st for st in source.stages("cvae")
                 if (st["values"]["primitive"], st["values"]["style"]) == (primitive, style))
    folder = unseen_cvae_folder(out, primitive, style, group)
    with hydra_configs():
        cfg = stage_train_config(list(stage.get("overrides") or []), dict(stage.get("values") or {}), source.data_cfg,
                                 folder, seed, threads, autoencoder_ckpt=str(generator["path"]))
    path, seconds = train_once(_quiet(cfg), f"{primitive} CVAE of {style} on the autoencoder without it")
    model = load_model(path, source.settings.neutral_style)
    run_examples = next(m.examples for m in run_cvaes if m.style == style)
    clip = ("take", "start", "stop", "primitive")
    if [tuple(e.get(k) for k in clip) for e in model.examples] != [tuple(e.get(k) for k in clip) for e in run_examples]:
        raise ZeroShotRunError(f"{path}: its example clips {model.examples} are not the run's CVAE's {run_examples}; "
                               "delete it and check the run's CVAE stage settings")
    return model, seconds


def _generator_autoencoder(source: ReproduceRun, style: str | Sequence[str], out: Path, seed: int, threads: Any,
                           shared: bool) -> dict[str, Any]:
    """The autoencoder the networks without ``style`` (a style or a group) are trained on: trained here without
    those styles (or, when ``shared``, the run's); its ``path``, ``fingerprint``, ``excluded_styles`` and
    ``train_seconds``.

    Raises:
        ZeroShotRunError: the trained checkpoint records data that did not leave the style out.
    """
    if shared:
        path, seconds = source.autoencoder_ckpt, None
    else:
        cfg = autoencoder_train_config(source, style, autoencoder_folder(out, style), seed, threads)
        path, seconds = train_once(cfg, f"autoencoder without {'+'.join(left_out(style))}")
    excluded = autoencoder_excluded_styles(path)
    seen = [s for s in left_out(style) if s not in excluded]
    if not shared and seen:
        raise ZeroShotRunError(f"{path} was trained on data with style(s) {seen} (its excluded styles: {excluded}); "
                               f"delete {autoencoder_folder(out, style)} and run again")
    return {"path": Path(path), "fingerprint": fingerprint(load_autoencoder(path)), "excluded_styles": excluded,
            "train_seconds": seconds}


# -- the markdown table


def _table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(r) + " |" for r in rows])


def _pct(value: float) -> str:
    return "–" if value is None or not math.isfinite(value) else f"{100 * value:.0f} %"


def markdown(results: Mapping[str, Any]) -> str:
    """``zero_shot.md``: recognition of each left-out style and the Table 5.1 rows, zero-shot next to CVAE."""
    meta = results["meta"]
    leaky = meta.get("leaky")
    generator = (f"**LEAKY: {leaky}.**" if leaky else
                 "Each network and the autoencoder under it were trained without any clip of the style it is "
                 "conditioned on; every row is measured with the run's autoencoder and style classifier (the judge).")
    lines = ["# One network for every style: leave one style out" + (" (LEAKY: shared autoencoder)" if leaky else ""),
             "", f"Run `{meta['run']}`, {meta['samples']:,} samples per model (seed {meta['seed']}). {generator} "
             f"The CVAE was trained on the neutral clips and that style's example. Git commit "
             f"`{meta.get('git_commit', '?')}`; {meta['seconds'] / 60:.1f} min.", "",
             "## Recognition of the left-out style", "",
             "Share of samples the style classifier (fitted on real train clips of every style) assigns to the "
             "style; `real`: the style's real clips (all but its example; the classifier was fitted on its "
             "train-split ones). Spread: pose_across_SD of the samples / of those real clips.", ""]
    rows = []
    unseen = bool(meta.get("cvae_unseen"))
    for p, res in results["primitives"].items():
        for s, r in res["styles"].items():
            zs, cv, real = r["zero_shot"], r["cvae"], r["real"]
            extra = [_pct(r[UNSEEN_ROW]["recognition"])] if unseen else []
            rows.append([p, s, _pct(zs["recognition"]), _pct(cv["recognition"]), *extra, _pct(real["recognition"]),
                         _pct(r["reconstructed"]["recognition"]), _pct(zs["pose_across_sd"] / real["pose_across_sd"]),
                         _pct(cv["pose_across_sd"] / real["pose_across_sd"])])
    lines += [_table(["primitive", "left-out style", "zero-shot", "CVAE",
                      *(["CVAE on the AE without the style"] if unseen else []), "real",
                      "real through the generator's AE", "zero-shot spread", "CVAE spread"], rows), ""]
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
