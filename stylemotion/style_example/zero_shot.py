"""``method=zero_shot`` of ``stylemotion-style``: a new style without training a model for it.

Per primitive of the example's action, one :class:`~stylemotion.models.zero_shot.ZeroShotStyleVAE`
(docs/zero_shot.md) is bound to the example's clips (``bind_example``, encoded at the canonical length as
the network's training examples were); the bound network samples the new style. The networks come
from the key ``network``:

* null: trained here, one per primitive, on the clips of every style of the run's data (none left out)
  into ``<out>/network/<primitive>/`` (:func:`network_config`), with ``network_epochs`` epochs (null: the
  ``zero_shot`` experiment's). That folder can be given as ``network=`` to later calls: a new style then
  costs no training at all;
* a folder holding ``<primitive>/checkpoints/best.ckpt`` (such a ``network`` folder), or a mapping
  ``{primitive: checkpoint}``.

Every network samples as ``configs/model/zero_shot.yaml`` says today (:func:`sampling_defaults`:
``sample_temperature``, ``sample_centred``, ``sample_pooling``; chosen on validation clips, docs/style.md), also one
trained before those keys changed or existed; the report records how (``network.sampling``).

Each network is checked before any work (:func:`check_network`): a zero-shot network, of the primitive,
trained on the run's autoencoder (weight fingerprint) and on the run's canonical timeline.

The style folder records, in each ``meta.checkpoints`` entry, the network's checkpoint, the example's
file (``example/example.npz``) and the clips' frames in it (``clips``: ``[start, stop)`` at the run's frame
rate); with several examples, ``example`` lists their files and each clip is ``[start, stop, example]``
(0-based place in that list): ``stylemotion-generate`` binds the same clips again
(:func:`stylemotion.synthesis.graph.load_bound_style`).
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from omegaconf import Container, DictConfig, OmegaConf, open_dict

from stylemotion.config import ConfigError, positive_int
from stylemotion.datamodules.features import describe_clip
from stylemotion.evaluation.zero_shot import network_train_config
from stylemotion.io.outputs import inside
from stylemotion.models.autoencoder import IncompatibleModelError
from stylemotion.models.checkpoints import checkpoint_hparams, fingerprint, load_autoencoder
from stylemotion.models.loading import EvalModel, load_generative
from stylemotion.models.zero_shot import ZeroShotStyleVAE
from stylemotion.primitives.segmentation import Clip
from stylemotion.style_example.base_run import SourceRun, train_config
from stylemotion.style_example.example import EXAMPLE_FILE, StyleExampleError, example_file
from stylemotion.style_example.methods import Method, ProgressLine, recorded_path

log = logging.getLogger(__name__)

#: The networks' folder inside ``out`` (one training folder per primitive).
NETWORK_FOLDER = "network"
#: Keys of the run's CVAE stage config the networks' training takes over: where and how training runs and
#: what it shows (not how long, nor what it models), and the segmentation of the clips.
CARRIED = ("trainer.accelerator", "trainer.devices", "trainer.num_nodes", "trainer.strategy", "trainer.precision",
           "trainer.enable_progress_bar", "trainer.enable_model_summary", "callbacks.progress_bar", "logger",
           "datamodule.segment")


# -- training the networks


def network_config(run: SourceRun, primitive: str, folder: Path, epochs: int | None = None,
                   threads: Any = None) -> DictConfig:
    """The ``train`` config of the network of ``primitive``, started afresh in ``folder``: ``experiment=zero_shot``
    (``trainer.max_epochs=epochs`` unless None), the :data:`CARRIED` keys and the timeline of the run's CVAE
    stage of ``primitive``, the run's data, seed, autoencoder and neutral style; every style of the data.
    Needs Hydra's config search initialized."""
    stage = train_config(run, primitive, str(run.cvae_stage(primitive)["values"]["style"]), folder, threads)
    cfg = network_train_config(run, primitive, folder, epochs, threads=threads, epochs_key="network_epochs")
    with open_dict(cfg):
        for key in CARRIED:
            value = OmegaConf.select(stage, key, default=None)
            value = OmegaConf.to_container(value, resolve=False) if isinstance(value, Container) else value
            OmegaConf.update(cfg, key, value, merge=False, force_add=True)
        timeline = stage.datamodule.get("timeline", "median")  # the CVAE's "median" of neutral clips is "neutral"
        cfg.datamodule.timeline = "neutral" if timeline == "median" else timeline
        cfg.datamodule.styles = None
        cfg.ckpt_path = None
    return cfg


def train_networks(run: SourceRun, primitives: Sequence[str], folder: Path, epochs: int | None, progress: ProgressLine,
                   threads: Any = None) -> dict[str, Path]:
    """Train the network of each primitive into ``folder/network/<primitive>/``; primitive → best checkpoint."""
    from stylemotion.training.fit import run as train_run

    checkpoints = {}
    for primitive in primitives:
        network_folder = inside(folder, NETWORK_FOLDER, primitive)
        cfg = network_config(run, primitive, network_folder, epochs, threads)
        progress(f"network {primitive}: training ({cfg.trainer.max_epochs} epochs) on the clips of every style of "
                 f"the run {run.data_styles} → {NETWORK_FOLDER}/{primitive}")
        t0 = time.perf_counter()
        metrics = train_run(cfg)["metrics"]
        checkpoints[primitive] = Path(metrics.get("best_checkpoint") or network_folder / "checkpoints" / "last.ckpt")
        test = ", ".join(f"{k} {v:.4g}" for k, v in metrics.get("test", {}).items() if isinstance(v, float))
        log.info(f"    network {primitive} done in {(time.perf_counter() - t0) / 60:.1f} min"
                 + (f": {test}" if test else ""))
    return checkpoints


def trained_epochs(folder: Path, primitives: Sequence[str]) -> int | None:
    """``trainer.max_epochs`` the networks trained in ``folder`` were configured with (their
    ``config_resolved.yaml``; None if they differ)."""
    epochs = {OmegaConf.load(folder / NETWORK_FOLDER / p / "config_resolved.yaml").trainer.max_epochs
              for p in primitives}
    return int(epochs.pop()) if len(epochs) == 1 else None


# -- networks made earlier


def network_checkpoints(network: Any, primitives: Sequence[str]) -> dict[str, Path]:
    """The checkpoint of each primitive that ``network`` names (a folder or a mapping, see the module doc).

    Raises:
        StyleExampleError: not a folder nor a mapping, a mapping that lacks a primitive or names another, or a
            checkpoint that does not exist.
    """
    hint = ("give the network folder of an earlier stylemotion-style method=zero_shot (<its out>/network), "
            "{primitive: checkpoint}, or network=null to train one here")
    if isinstance(network, Mapping):
        given = {str(k): Path(str(v)).expanduser() for k, v in network.items()}
        missing = [p for p in primitives if p not in given]
        unknown = sorted(set(given) - set(primitives))
        if missing or unknown:
            raise StyleExampleError(f"network={dict(network)} must give one checkpoint per primitive of the example's "
                                    f"action {list(primitives)}" + (f"; missing {missing}" if missing else "")
                                    + (f"; not one of them: {unknown}" if unknown else ""))
        paths = {p: given[p] for p in primitives}
    elif isinstance(network, (str, os.PathLike)) and Path(network).expanduser().is_dir():
        folder = Path(network).expanduser()
        paths = {p: folder / p / "checkpoints" / "best.ckpt" for p in primitives}
        if not any(p.is_file() for p in paths.values()) and (folder / NETWORK_FOLDER).is_dir():
            hint = f"its networks are in {folder / NETWORK_FOLDER}: give network={folder / NETWORK_FOLDER}"
    else:
        raise StyleExampleError(f"network={network} is no folder: {hint}")
    gone = [str(p) for p in paths.values() if not p.is_file()]
    if gone:
        raise StyleExampleError(f"network={network}: no checkpoint {gone}; {hint}")
    return paths


def run_timeline(run: SourceRun, primitive: str) -> int:
    """The canonical length (frames) of the run's models of ``primitive`` (its neutral VAE's)."""
    stage = next(s for s in run.summary["stages"] if s["kind"] == "vae" and s["values"].get("primitive") == primitive)
    return int(checkpoint_hparams(run.located(stage["checkpoint"]))["spec"]["timeline_frames"])


def check_network(path: Path, primitive: str, weights: str, timeline_frames: int, run: SourceRun) -> ZeroShotStyleVAE:
    """The network at ``path``, checked to be a zero-shot network of ``primitive`` trained on the run's autoencoder
    (fingerprint ``weights``) and timeline.

    Raises:
        StyleExampleError: not a readable model, another kind of model, primitive, autoencoder or timeline.
    """
    try:
        model = load_generative(path)
    except (OSError, IncompatibleModelError) as exc:
        raise StyleExampleError(f"network: {exc}") from None
    if not isinstance(model, ZeroShotStyleVAE):
        raise StyleExampleError(f"network: {path} is a {type(model).__name__}, not a zero-shot style network "
                                "(stylemotion-train experiment=zero_shot; or network=null trains one here)")
    spec = model.spec
    if spec["primitive"] != primitive:
        raise StyleExampleError(f"network: {path} is the network of {spec['primitive']}, not of {primitive}")
    ours = spec["autoencoder"]
    if ours["fingerprint"] != weights:
        raise StyleExampleError(f"network: {path} was trained on another autoencoder (weights "
                                f"{ours['fingerprint']}, {ours.get('path')}) than run={run.folder} (weights {weights}, "
                                f"{run.autoencoder_ckpt}); give a network trained on this run (network=null trains "
                                "one)")
    if model.timeline_frames != timeline_frames:
        raise StyleExampleError(f"network: {path} uses a timeline of {model.timeline_frames} frames, "
                                f"run={run.folder}'s {primitive} models {timeline_frames}: it was trained on other "
                                "data or segmentation")
    return model


# -- the method


class ZeroShotMethod(Method):
    """``method=zero_shot`` (see the module doc); keys ``network`` and ``network_epochs``."""

    keys = ("network", "network_epochs")

    def prepare(self, run: SourceRun, primitives: Sequence[str], options: Mapping[str, Any]) -> dict[str, Any]:
        network, epochs = options.get("network"), options.get("network_epochs")
        epochs = None if epochs is None else positive_int(epochs, "network_epochs")
        if network is None:
            return {"network": None, "network_epochs": epochs, "checkpoints": None}
        if epochs is not None:
            raise ConfigError(f"network_epochs={epochs} sets the training of a network made here (network=null); "
                              f"network={network} is already trained")
        paths = network_checkpoints(network, primitives)
        weights = fingerprint(load_autoencoder(run.autoencoder_ckpt))
        for primitive, path in paths.items():
            check_network(path, primitive, weights, run_timeline(run, primitive), run)
        given = {p: str(v) for p, v in network.items()} if isinstance(network, Mapping) else str(network)
        return {"network": given, "network_epochs": None, "checkpoints": paths}

    def steps(self, primitives: Sequence[str], options: Mapping[str, Any]) -> int:
        return len(primitives) if options["network"] is None else 1

    def make(self, run: SourceRun, name: str, example, cut, folder: Path, progress: ProgressLine, threads: Any,
             options: Mapping[str, Any]) -> dict[str, Path]:
        if options["network"] is not None:
            progress(f"network: taken from {options['network']}, no training; the example's clips are bound to it")
            return dict(options["checkpoints"])
        checkpoints = train_networks(run, list(cut.used), folder, options["network_epochs"], progress, threads)
        weights = fingerprint(load_autoencoder(run.autoencoder_ckpt))
        for primitive, path in checkpoints.items():
            check_network(path, primitive, weights, run_timeline(run, primitive), run)
        return checkpoints

    def load(self, checkpoint: Path, primitive: str, clips: Sequence[Clip], records: Sequence[Mapping[str, Any]],
             name: str, neutral_style: str, autoencoder) -> EvalModel:
        network = load_generative(checkpoint, autoencoder)
        network.set_sampling(sampling_defaults())
        described = [{**describe_clip(c), "encoded_frames": network.timeline_frames, **dict(r)}
                     for c, r in zip(clips, records)]
        bound = network.bind_example(list(clips), name, described)
        spec = network.spec
        return EvalModel(name, primitive, name, bound, bound.style_examples, dict(spec["autoencoder"]), str(checkpoint),
                         network.timeline_frames, bound.target_gram, spec.get("dataset"), "canonical")

    def report(self, models: Mapping[str, EvalModel], folder: Path, options: Mapping[str, Any]) -> dict[str, Any]:
        networks = {p: m.source.model for p, m in models.items()}
        here = options["network"] is None
        return {"network": {
            "trained_here": here, "given": options["network"],
            "epochs": trained_epochs(folder, list(models)) if here else None,
            "checkpoints": {p: recorded_path(m.checkpoint, folder) for p, m in models.items()},
            "trained_styles": {p: n.styles for p, n in networks.items()},
            "sampling": {p: {"temperature": networks[p].sample_temperature, "centred": networks[p].sample_centred,
                             "pooling": m.source.pooling} for p, m in models.items()},
            "excluded_styles": {p: n.excluded_styles for p, n in networks.items()}}}

    def entry(self, primitive: str, clips: Sequence[Clip], origin: Sequence[int] = (), examples: int = 1
              ) -> dict[str, Any]:
        sampling = sampling_defaults()  # what load() applied: a loaded style samples as its report measured
        if examples == 1:
            return {"method": "zero_shot", "example": EXAMPLE_FILE, "sampling": sampling,
                    "clips": [[int(c.start), int(c.stop)] for c in clips]}
        return {"method": "zero_shot", "example": [example_file(i) for i in range(examples)], "sampling": sampling,
                "clips": [[int(c.start), int(c.stop), int(i)] for c, i in zip(clips, origin)]}


def model_config() -> DictConfig:
    """``configs/model/zero_shot.yaml`` as written (how ``method=zero_shot`` trains and samples its networks)."""
    from stylemotion.config import config_dir

    return OmegaConf.load(Path(config_dir()) / "model" / "zero_shot.yaml")


def sampling_defaults() -> dict[str, Any]:
    """``sample_temperature``, ``sample_centred`` and ``sample_pooling`` of ``configs/model/zero_shot.yaml``: how every
    network of ``method=zero_shot`` samples."""
    cfg = model_config()
    return {"sample_temperature": float(cfg.get("sample_temperature", 1.0)),
            "sample_centred": bool(cfg.get("sample_centred", False)),
            "sample_pooling": str(cfg.get("sample_pooling", "mean"))}
