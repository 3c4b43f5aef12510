"""Summarize VAE / style-CVAE sweeps as JSON lines: held-out reconstruction error, sample durations,
and a preview of the thesis' style-distance table (Table 5.1).

    python scripts/vae_sweep_report.py --vae-sweep runs/train/primitive_vae/multirun/<id> \\
        --cvae-sweep runs/train/style_cvae/multirun/<id> [-n 1000] [--seed 0]

For every primitive of the VAE sweep (one line each, ``"kind": "reconstruction"``): MPJPE (cm) on the
held-out **test** clips of the neutral data, (a) through the autoencoder alone (encode, decode,
restore the duration, integrate the root) and (b) through VAE (posterior mean) + autoencoder, both
against the recorded clips at 30 fps, plus training time and sample durations against the data's.

Then (``"kind": "style_distance"``) for each primitive the matrix D(m, s) = mean over ``n`` samples
of model ``m`` of ‖Gram(encoder(x_i)) − Gram(encoder(s))‖ (thesis eq. 5.12): ``m`` is the neutral
VAE or a style CVAE, ``s`` each CVAE's example(s) (its recorded target Gram) or, for ``neutral``,
the mean motion of the neutral training clips. Samples are re-encoded from their time-normalized
frames. ``pose_sd_cm`` is a diversity proxy: the standard deviation across clips (or samples) of
the root-local joint positions of the time-normalized frames, in cm. ``real_clips_to_own_example``
is the same distance for the real clips of each style (train
split, example left out): a sample closer to its example than that is more "stylish" than the
style's own clips. A preview only; the evaluation issue owns the real table.
"""

from __future__ import annotations

import argparse
import json
from datetime import datetime
from pathlib import Path

import torch
import yaml

from stylemotion.datamodules.features import FeatureDataModule
from stylemotion.datasets import build_dataset
from stylemotion.models.cvae import StyleCVAE
from stylemotion.models.loading import load_generative
from stylemotion.models.sampling import decode_features, masked_mpjpe
from stylemotion.models.style import feature_style_distance, gram
from stylemotion.models.vae import PrimitiveVAE


def runs_of(sweep: Path | None) -> list[Path]:
    return sorted(p for p in sweep.iterdir() if (p / "checkpoints" / "best.ckpt").is_file()) if sweep else []


def datamodule(run: Path, takesets: dict) -> FeatureDataModule:
    """The run's FeatureDataModule (without style), sharing one dataset build per data config."""
    cfg = yaml.safe_load((run / "config_resolved.yaml").read_text())
    key = json.dumps(cfg["data"], sort_keys=True)
    if key not in takesets:
        takesets[key] = build_dataset(cfg["data"])
    options = {k: v for k, v in cfg["datamodule"].items() if k != "_target_"}
    options.update(style=None, examples=None)
    dm = FeatureDataModule(takeset=takesets[key], split=cfg["data"]["split"], **options)
    dm.setup("test")
    return dm


def train_seconds(run: Path) -> float | None:
    """Seconds between the first and the last line of the run's ``train.log`` (Hydra's job log:
    data loading, feature encoding, fit, test and the GIF)."""
    log = run / "train.log"
    stamps = [line[1:24] for line in log.read_text().splitlines() if line.startswith("[20")] if log.is_file() else []
    if len(stamps) < 2:
        return None
    first, last = (datetime.strptime(s, "%Y-%m-%d %H:%M:%S,%f") for s in (stamps[0], stamps[-1]))
    return round((last - first).total_seconds(), 1)


@torch.no_grad()
def reconstruction(model: PrimitiveVAE, dm: FeatureDataModule, run: Path, n: int, seed: int) -> dict:
    test = dm.datasets["test"]
    ae_only = decode_features(dm.autoencoder, test.features, test.duration_s, dm.timeline_frames, dm.fps)
    through_vae = model.reconstruct(test.features, test.duration_s)
    durations = model.sample(n, seed=seed).duration_s
    train = dm.datasets["train"].duration_s
    return {"kind": "reconstruction", "run": str(run), "primitive": model.primitive, "test_clips": len(test),
            "ae_only_mpjpe_cm": round(100 * masked_mpjpe(ae_only.positions, test.positions, test.num_frames).item(), 3),
            "vae_ae_mpjpe_cm": round(100 * masked_mpjpe(through_vae.positions, test.positions,
                                                        test.num_frames).item(), 3),
            "train_duration_s": [round(train.mean().item(), 4), round(train.std().item(), 4)],
            "sample_duration_s": [round(durations.mean().item(), 4), round(durations.std().item(), 4)],
            "run_seconds": train_seconds(run), "epochs": json.loads((run / "metrics.json").read_text()).get("epoch")}


def _pose_sd(frames: torch.Tensor) -> float:
    """Standard deviation across clips of the root-local joint positions of time-normalized frames
    ``(n, length, 66)``, averaged over frames, joints and axes, in cm (a diversity proxy)."""
    return round(100 * frames[..., :63].std(0).mean().item(), 3)


@torch.no_grad()
def style_table(vae: PrimitiveVAE, cvaes: list[StyleCVAE], dm: FeatureDataModule, n: int, seed: int) -> dict:
    mean_motion = dm.clip_data.datasets["train"].frames.mean(0, keepdim=True)
    targets = {"neutral": gram(dm.autoencoder.encode(mean_motion))[0]}
    targets.update({m.style: m.style_gram for m in cvaes})
    rows, pose_sd = {}, {"training clips": _pose_sd(dm.clip_data.datasets["train"].frames)}
    for name, model in [("neutral", vae)] + [(m.style, m) for m in cvaes]:
        samples = model.sample(n, seed=seed)
        features = dm.autoencoder.encode(samples.normalized_frames)
        rows[name] = {s: round(feature_style_distance(features, g).mean().item(), 4) for s, g in targets.items()}
        pose_sd[name] = _pose_sd(samples.normalized_frames)
    diagonal = sum(min(row, key=row.get) == name for name, row in rows.items())
    # reference: how far real clips of each style (train split, the example itself left out) are from its example
    real = {}
    for m in cvaes:
        ref = FeatureDataModule(takeset=dm.clip_data.takeset, autoencoder=dm.autoencoder, primitive=dm.primitive,
                                content_styles=[m.style], timeline=dm.timeline_frames, min_train_clips=1,
                                split=dm.clip_data.split_cfg)
        ref.setup("fit")
        used = {(e["take"], e["start"]) for e in m.style_examples}
        keep = [i for i, c in enumerate(ref.datasets["train"].clips) if (c.take, c.start) not in used]
        distances = feature_style_distance(ref.datasets["train"].features[keep], m.style_gram)
        real[m.style] = round(distances.mean().item(), 4)
    return {"kind": "style_distance", "primitive": vae.primitive, "samples": n, "seed": seed,
            "rows_min_on_diagonal": f"{diagonal}/{len(rows)}", "D": rows,
            "real_clips_to_own_example": real, "pose_sd_cm": pose_sd,
            "examples": {m.style: m.style_examples for m in cvaes}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vae-sweep", type=Path, required=True)
    parser.add_argument("--cvae-sweep", type=Path)
    parser.add_argument("-n", type=int, default=1000, help="samples per model")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    takesets: dict = {}
    cvaes: dict[str, list[StyleCVAE]] = {}
    for run in runs_of(args.cvae_sweep):
        model = load_generative(run / "checkpoints" / "best.ckpt")
        cvaes.setdefault(model.primitive, []).append(model)
        print(json.dumps({"kind": "style_run", "run": str(run), "primitive": model.primitive, "style": model.style,
                          "run_seconds": train_seconds(run),
                          "epochs": json.loads((run / "metrics.json").read_text()).get("epoch"),
                          "test": json.loads((run / "metrics.json").read_text()).get("test")}), flush=True)
    for run in runs_of(args.vae_sweep):
        model = load_generative(run / "checkpoints" / "best.ckpt")
        dm = datamodule(run, takesets)
        print(json.dumps(reconstruction(model, dm, run, args.n, args.seed)), flush=True)
        if cvaes.get(model.primitive):
            print(json.dumps(style_table(model, cvaes[model.primitive], dm, args.n, args.seed)), flush=True)


if __name__ == "__main__":
    main()
