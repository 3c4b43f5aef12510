"""Suite ``contact_loss``: the foot-contact velocity loss (``model.contact_weight``, stylemotion/models/contact_loss.py)
of the autoencoder, the neutral VAE, the style CVAE and the zero-shot network, its weight chosen on **validation**
clips, reported on **test** clips, raw foot skating of the samples against real clips of the same style.

    python scripts/benchmarks.py run contact_loss --weights 0 10 100 1000 --ae-weights 0 0.1 1 --seeds 0 1 2

Data: the reproduction's Bandai walks and take split (suite ``style_bandai``'s data stage), one stance primitive
(``--primitive``, walk_leftStance) and one style for the styled models (``--style``). Per seed ``k``:

* **Autoencoders** (seed ``--seeds[0]`` only, ``--ae-epochs`` epochs, the reproduction's autoencoder stage
  otherwise): one per ``--ae-weights`` candidate. Figures: val/mpjpe (windows, root-integrated) and the raw
  foot skating of the primitive's val / test clips of every style passed through the autoencoder, against the
  same clips as recorded.
* **Feature models** on the autoencoder of weight 0 (the default the other models are trained on, so that the
  feature models' candidates differ in their own term only): the neutral VAE, the CVAE of ``--style`` and the
  zero-shot network (trained on every style, this one included, conditioned at sampling on the CVAE's example clip),
  ``--epochs`` epochs each, the reproduction's stage settings otherwise. Seed ``--seeds[0]`` trains every candidate
  of ``--weights``; the other seeds train weight 0 and the chosen weight only. The seed varies the feature models'
  initialization, batches and samples; the data, its split and the autoencoder are fixed.

Figures per trained model: ``--samples`` prior samples drawn with seed ``k`` (validation) and with seed
``k + 1000`` (test), their foot-skating ratio (:func:`stylemotion.primitives.skating.foot_skating`, contacts judged
against the real train takes' resting heights; skating = planted point faster than 0.2 m/s) and that of the
real clips of the model's style (neutral for the VAE) in the val / test split; the share of samples a style
classifier (fitted on the train clips of every style) assigns to the model's style; the reconstruction error of
the val (``val/mpjpe`` at the best epoch, logged by training) and test clips (posterior means, m).

**Rule** (per model, on seed ``--seeds[0]``'s validation figures): among the candidates whose val reconstruction
error is at most ``1 + --tolerance`` times that of weight 0 and whose recognition is at least weight 0's minus
``--recognition-drop`` (VAE: share recognized as neutral; autoencoders: the reconstruction error only), the one
with the lowest val sample-skating ratio (autoencoders: reconstruction skating); ties: the smaller weight; samples
without any contact foot-frame are not eligible (their feet never plant), and when no candidate is, weight 0. No test
clip is read before the choice; the test figures of the other candidates of seed ``--seeds[0]`` are shown but
choose nothing.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from suites import style
from suites.common import fmt, md_table, progress_printed, provenance_line, run_jobs, spread

#: Validation figures printed as each training finishes.
SHOWN = ("val/mpjpe", "val/contact")
DESCRIPTION = ("foot-contact velocity loss weight of the autoencoder, VAE, CVAE and zero-shot network, chosen on "
               "Bandai validation clips; raw sample skating against real clips of the style on test")
DEFAULT_SEEDS = (0, 1, 2)
ROOT = Path(__file__).resolve().parents[2]
MODELS = ("vae", "cvae", "zero_shot")
NAMES = {"autoencoder": "autoencoder (reconstructions)", "vae": "neutral VAE", "cvae": "style CVAE",
         "zero_shot": "zero-shot network"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--data", choices=sorted(style.DATA), default="bandai",
                        help="bandai: dataset-2 walks (the reproduction's data); synthetic: a smoke run only")
    parser.add_argument("--runs", type=Path, default=ROOT / "runs" / "benchmarks" / "contact_loss",
                        help="folder of the trainings (reused when the suite runs again)")
    parser.add_argument("--primitive", default="walk_leftStance", help="the stance primitive")
    parser.add_argument("--style", default="elderly", help="the style of the CVAE and of the zero-shot samples")
    parser.add_argument("--weights", type=float, nargs="+", default=[0.0, 10.0, 100.0, 1000.0],
                        help="candidate contact_weight of the feature models (0 = off, always included)")
    parser.add_argument("--ae-weights", type=float, nargs="*", default=[0.0, 0.1, 1.0],
                        help="candidate contact_weight of the autoencoder (0 always included)")
    parser.add_argument("--ae-epochs", type=int, default=20, help="epochs of each autoencoder")
    parser.add_argument("--epochs", type=int, default=30, help="epochs of each feature model")
    parser.add_argument("--samples", type=int, default=256, help="prior samples per model and split")
    parser.add_argument("--tolerance", type=float, default=0.10,
                        help="largest relative rise of the val reconstruction error over weight 0's")
    parser.add_argument("--recognition-drop", type=float, default=0.05,
                        help="largest drop of the samples' recognition below weight 0's (share)")
    parser.add_argument("--workers", type=int, default=2, help="trainings at once (one thread each)")


# ---------------------------------------------------------------------------------------------
# training (worker processes)


def _replace(overrides: list[str], **values: Any) -> list[str]:
    """``overrides`` with ``key=value`` set for each of ``values`` (keys with dots given as ``a__b``)."""
    keys = {k.replace("__", "."): v for k, v in values.items()}
    kept = [o for o in overrides if str(o).split("=", 1)[0] not in keys]
    return kept + [f"{k}={v}" for k, v in keys.items()]


# ---------------------------------------------------------------------------------------------
# figures of one trained model


class Judge:
    """The real side: the primitive's clips split by take, the resting heights, the style classifier."""

    def __init__(self, takeset: Any, primitive: str, length: int, split: dict[str, Any]):
        from stylemotion.evaluation.classifier import StyleClassifier
        from stylemotion.evaluation.reference import primitive_data
        from stylemotion.evaluation.sources import motions_from_clips

        self.data = primitive_data(takeset, primitive, length, "normal", None, split)
        self.length = length
        #: the style example's record (``take``, ``start``, ``stop``, …) the zero-shot network is conditioned on
        self.example_record: dict[str, Any] = {}
        train = self.data.split("train")
        motions = motions_from_clips(train, length)
        self.classifier = StyleClassifier(32, 1.0, 0).fit(motions.normalized_frames.numpy(),
                                                          motions.duration_s.numpy(), [c.style for c in train])

    def skating(self, motions: Any) -> dict[str, Any]:
        from stylemotion.primitives.skating import foot_skating

        return foot_skating(motions.positions.numpy(), motions.num_frames.numpy(), motions.fps,
                            self.data.rest_heights, self.data.stance_foot).as_dict()

    def real(self, part: str, style_name: str | None) -> Any:
        from stylemotion.evaluation.sources import motions_from_clips

        return motions_from_clips(self.data.split(part, style_name), self.length)

    def recognition(self, motions: Any, style_name: str) -> float:
        predicted = self.classifier.predict(motions.normalized_frames.numpy(), motions.duration_s.numpy())
        return float((predicted == style_name).mean())


def reconstruction_error(model: Any, clips: list, length: int, example: Any = None) -> float:
    """Mean per-joint error (m) of posterior-mean reconstructions of ``clips`` at their real durations."""
    import numpy as np
    import torch

    from stylemotion.models.sampling import masked_mpjpe, pad_motions
    from stylemotion.primitives.segmentation import time_normalize

    frames = torch.from_numpy(np.stack([time_normalize(c.frames, length) for c in clips])).float()
    features = model.autoencoder.encode(frames)
    duration = torch.tensor([c.duration_s for c in clips], dtype=torch.float32)
    recon = model.reconstruct(features, duration) if example is None else model.reconstruct(features, duration,
                                                                                            example)
    positions, num_frames = pad_motions([c.positions for c in clips])
    return float(masked_mpjpe(recon.positions, positions, num_frames))


def feature_figures(kind: str, checkpoint: Path, judge: Judge, style_name: str, seed: int, samples: int
                    ) -> dict[str, Any]:
    """Val and test figures of one trained feature model (see the module doc)."""
    import torch

    from stylemotion.models.loading import load_generative

    model = load_generative(checkpoint)
    target = "normal" if kind == "vae" else style_name
    example = None
    if kind == "zero_shot":
        record = judge.example_record
        clip = judge.data.find_example(record)
        example = model.condition([clip])
        sampler = model.bind_example([clip], style=style_name)
    else:
        sampler = model
    out: dict[str, Any] = {}
    with torch.no_grad():
        for part, draw_seed in (("val", seed), ("test", seed + 1000)):
            drawn = sampler.sample(samples, seed=draw_seed)
            real = judge.real(part, target)
            out[part] = {"samples": judge.skating(drawn), "real": judge.skating(real),
                         "recognition": judge.recognition(drawn, target),
                         "real_clips": len(real),
                         "mpjpe": reconstruction_error(model, judge.data.split(part, target), judge.length, example)}
    return out


def autoencoder_figures(checkpoint: Path, judge: Judge) -> dict[str, Any]:
    """Val and test figures of one autoencoder: the primitive's clips of every style through it (recorded frame
    rate, integrated from the origin) against the same clips as recorded."""
    import torch

    from stylemotion.models.autoencoder import mpjpe
    from stylemotion.models.checkpoints import load_autoencoder
    from stylemotion.models.sampling import MotionSamples, pad_motions
    from stylemotion.representation import frames_to_positions

    ae = load_autoencoder(checkpoint)
    fps = judge.data.fps
    out = {}
    for part in ("val", "test"):
        clips = judge.data.split(part)
        positions, errors = [], []
        with torch.no_grad():
            for c in clips:
                frames = torch.from_numpy(c.frames).float()[None]
                recon = ae(frames)
                positions.append(frames_to_positions(recon[0].double(), fps).float().numpy())
                errors.append(float(mpjpe(recon, frames, fps)))
        padded, num_frames = pad_motions(positions)
        empty = torch.zeros(len(clips), 0, 0)
        recon_m = MotionSamples(padded, empty, num_frames, torch.zeros(len(clips)), empty, empty, fps)
        out[part] = {"samples": judge.skating(recon_m), "real": judge.skating(judge.real(part, None)),
                     "clips": len(clips), "mpjpe": sum(errors) / len(errors)}
    return out


# ---------------------------------------------------------------------------------------------
# the rule


def choose_weight(figures: dict[float, dict[str, Any]], tolerance: float, recognition_drop: float | None
                  ) -> tuple[float, dict[str, str]]:
    """The candidate chosen by the module doc's rule from ``weight → {"val_mpjpe", "val": {...}}``; returns it and
    why each candidate was or was not eligible."""
    base = figures[0.0]
    why: dict[str, str] = {}
    eligible = []
    for w, f in sorted(figures.items()):
        ratio = f["val"]["samples"]["ratio"]
        if f.get("val_mpjpe") is None or not math.isfinite(f["val_mpjpe"]):
            why[f"{w:g}"] = "failed"
            continue
        if ratio is None or not math.isfinite(ratio):
            why[f"{w:g}"] = "no contact foot-frame in the samples"
            continue
        if f["val_mpjpe"] > (1 + tolerance) * base["val_mpjpe"]:
            why[f"{w:g}"] = f"val reconstruction error {f['val_mpjpe'] / base['val_mpjpe']:.2f}× weight 0's"
            continue
        if recognition_drop is not None and f["val"]["recognition"] < base["val"]["recognition"] - recognition_drop:
            why[f"{w:g}"] = "recognition dropped"
            continue
        why[f"{w:g}"] = "eligible"
        eligible.append(w)
    if not eligible:  # nothing qualifies: keep the default
        return 0.0, why
    chosen = min(eligible, key=lambda w: (figures[w]["val"]["samples"]["ratio"], w))
    return chosen, why


# ---------------------------------------------------------------------------------------------
# the suite


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    import torch
    from hydra.core.global_hydra import GlobalHydra
    from omegaconf import OmegaConf

    from stylemotion.datasets import build_dataset
    from stylemotion.training.reproduction import Reproduction, stage_train_config

    torch.set_num_threads(1)
    weights = sorted({0.0, *map(float, args.weights)})
    ae_weights = sorted({0.0, *map(float, args.ae_weights)})
    base = args.runs / args.data / f"{args.primitive}_{args.style}"
    first = seeds[0]
    cfg = style.compose_reproduce(style.reproduce_overrides(args.data, first, base / "reproduce", 1,
                                                            [args.primitive], [args.style]))
    try:
        repro = Reproduction(cfg)
        repro.out.mkdir(parents=True, exist_ok=True)
        with progress_printed("[data]"):
            repro.data_stage()
        stages = {name: [str(o) for o in OmegaConf.to_container(cfg.stages[name], resolve=True)]
                  for name in ("autoencoder", "vae", "cvae")}
        stages["zero_shot"] = ["experiment=zero_shot", *stages["vae"][1:]]
        data_cfg = repro.data_cfg

        def folder(kind: str, weight: float, seed: int) -> Path:
            return base / f"{kind}_w{weight:g}_seed{seed}"

        def job(kind: str, weight: float, seed: int, ae_ckpt: str | None) -> tuple[dict[str, Any], str]:
            epochs = args.ae_epochs if kind == "autoencoder" else args.epochs
            overrides = _replace(stages[kind], trainer__max_epochs=epochs, model__contact_weight=weight)
            if kind != "autoencoder":
                overrides = _replace(overrides, callbacks__samples="null")
            values = {"primitive": args.primitive} if kind != "autoencoder" else {}
            if kind == "cvae":
                values["style"] = args.style
            train_cfg = stage_train_config(overrides, values, data_cfg, folder(kind, weight, seed), seed, 1, ae_ckpt)
            return OmegaConf.to_container(train_cfg, resolve=True), str(folder(kind, weight, seed))

        ae_jobs = {("autoencoder", w, first): job("autoencoder", w, first, None) for w in ae_weights}
    finally:
        GlobalHydra.instance().clear()
    trained = run_jobs(ae_jobs, args.workers, SHOWN)
    ae_ckpt = str(folder("autoencoder", 0.0, first) / "checkpoints" / "best.ckpt")

    cfg = style.compose_reproduce(style.reproduce_overrides(args.data, first, base / "reproduce", 1,
                                                            [args.primitive], [args.style]))
    try:
        first_jobs = {(kind, w, first): job(kind, w, first, ae_ckpt) for kind in MODELS for w in weights}
    finally:
        GlobalHydra.instance().clear()
    trained |= run_jobs(first_jobs, args.workers, SHOWN)

    from stylemotion.models.loading import load_generative

    takeset = build_dataset(data_cfg)
    length = int(load_generative(folder("vae", 0.0, first) / "checkpoints" / "best.ckpt").timeline_frames)
    judge = Judge(takeset, args.primitive, length, dict(data_cfg.get("split") or {}))
    cvae0 = load_generative(folder("cvae", 0.0, first) / "checkpoints" / "best.ckpt")
    judge.example_record = cvae0.style_examples[0]

    def figures_of(kind: str, w: float, seed: int) -> dict[str, Any]:
        ckpt = folder(kind, w, seed) / "checkpoints" / "best.ckpt"
        if kind == "autoencoder":
            f = autoencoder_figures(ckpt, judge)
        else:
            f = feature_figures(kind, ckpt, judge, args.style, seed, args.samples)
        f["val_mpjpe"] = trained[(kind, w, seed)]["val"].get("val/mpjpe") if kind != "autoencoder" else \
            f["val"]["mpjpe"]
        f["val_window_mpjpe"] = trained[(kind, w, seed)]["val"].get("val/mpjpe")
        f["val_contact"] = trained[(kind, w, seed)]["val"].get("val/contact")
        f["train_seconds"] = trained[(kind, w, seed)]["seconds"]
        print(f"[{kind} w {w:g} seed {seed}] val skating {f['val']['samples']['ratio']:.3f} (real "
              f"{f['val']['real']['ratio']:.3f}), test {f['test']['samples']['ratio']:.3f} (real "
              f"{f['test']['real']['ratio']:.3f}), val mpjpe {f['val_mpjpe']}", flush=True)
        return f

    per_seed: dict[str, dict[str, dict[str, Any]]] = {str(first): {}}
    choice: dict[str, Any] = {}
    for kind in ("autoencoder", *MODELS):
        candidates = ae_weights if kind == "autoencoder" else weights
        figs = {w: figures_of(kind, w, first) for w in candidates}
        per_seed[str(first)][kind] = {f"{w:g}": f for w, f in figs.items()}
        drop = None if kind == "autoencoder" else args.recognition_drop
        chosen, why = choose_weight(figs, args.tolerance, drop)
        choice[kind] = {"chosen": chosen, "why": why, "edge": chosen == max(candidates) and chosen > 0}

    cfg = style.compose_reproduce(style.reproduce_overrides(args.data, first, base / "reproduce", 1,
                                                            [args.primitive], [args.style]))
    try:
        later = {(kind, w, seed): job(kind, w, seed, ae_ckpt) for seed in seeds[1:] for kind in MODELS
                 for w in sorted({0.0, choice[kind]["chosen"]})}
    finally:
        GlobalHydra.instance().clear()
    trained |= run_jobs(later, args.workers, SHOWN)
    for seed in seeds[1:]:
        per_seed[str(seed)] = {kind: {f"{w:g}": figures_of(kind, w, seed)
                                      for w in sorted({0.0, choice[kind]["chosen"]})} for kind in MODELS}

    summary: dict[str, Any] = {}
    for kind in MODELS:
        summary[kind] = {}
        for w in sorted({0.0, choice[kind]["chosen"]}):
            rows = [per_seed[s][kind][f"{w:g}"] for s in per_seed]
            summary[kind][f"{w:g}"] = {
                "test_samples": spread(r["test"]["samples"]["ratio"] for r in rows),
                "test_real": spread(r["test"]["real"]["ratio"] for r in rows),
                "test_ratio_to_real": spread(r["test"]["samples"]["ratio"] / r["test"]["real"]["ratio"] for r in rows),
                "test_recognition": spread(r["test"]["recognition"] for r in rows),
                "test_mpjpe": spread(r["test"]["mpjpe"] for r in rows),
                "test_planted_mid_mps": spread(r["test"]["samples"]["planted_mid_mps"] for r in rows)}
    split = data_cfg.get("split") or {}
    return {"data": args.data, "primitive": args.primitive, "style": args.style, "weights": weights,
            "ae_weights": ae_weights, "epochs": args.epochs, "ae_epochs": args.ae_epochs, "samples": args.samples,
            "tolerance": args.tolerance, "recognition_drop": args.recognition_drop,
            "example": judge.example_record, "timeline_frames": length,
            "rule": (f"per model, on seed {first}'s validation figures: among candidates with val reconstruction "
                     f"error ≤ {1 + args.tolerance:g}× weight 0's and sample recognition ≥ weight 0's − "
                     f"{args.recognition_drop:g} (autoencoder: the error only), the lowest val skating ratio "
                     "(samples; autoencoder: reconstructions of the val clips); ties: the smaller weight"),
            "splits": {"data": {"kind": "by take", **split},
                       "choose": "val clips (skating reference, reconstruction) and val-seeded samples; no test clip",
                       "report": "test clips and samples drawn with seed + 1000",
                       "seed_varies": "feature models' initialization, batches and samples; one autoencoder "
                                      f"(seed {first}, weight 0) under every feature model"},
            "choice": choice, "summary": summary, "per_seed": per_seed}


# ---------------------------------------------------------------------------------------------
# rendering


def _pct(v: float | None) -> str:
    return "—" if v is None or not math.isfinite(v) else f"{100 * v:.1f} %"


def _pm(sp: dict[str, Any], scale: float = 100, digits: int = 1, unit: str = "") -> str:
    """``mean ± sd`` of a :func:`~suites.common.spread` times ``scale``; ``—`` (with the count missing) for none."""
    if not sp.get("n"):
        return f"— ({sp.get('missing', 0)} missing)"
    text = f"{fmt(scale * sp['mean'], digits)} ± {fmt(scale * sp['sd'], digits)}{unit}"
    return text + (f", {sp['missing']} missing" if sp.get("missing") else "")


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    prov = provenance_line(record)
    first = next(iter(r["per_seed"]))
    rows = []
    for kind in ("autoencoder", *MODELS):
        for w, f in r["per_seed"][first][kind].items():
            chosen = float(w) == r["choice"][kind]["chosen"]
            rows.append([NAMES[kind], f"**{w}**" if chosen else w,
                         f"{_pct(f['val']['samples']['ratio'])} / {_pct(f['val']['real']['ratio'])}",
                         f"{_pct(f['val']['samples']['contact_share'])} / {_pct(f['val']['real']['contact_share'])}",
                         fmt(f["val_contact"], 3), "—" if kind == "autoencoder" else _pct(f["val"]["recognition"]),
                         fmt(100 * f["val_mpjpe"], 2) if f.get("val_mpjpe") is not None else "—",
                         r["choice"][kind]["why"].get(w, ""),
                         f"{_pct(f['test']['samples']['ratio'])} / {_pct(f['test']['real']['ratio'])}"])
    edges = [NAMES[k] for k, c in r["choice"].items() if c.get("edge")]
    val = (f"Foot-contact velocity loss (`model.contact_weight`, stylemotion/models/contact_loss.py) on {r['data']} "
           f"{r['primitive']}, style {r['style']} for the CVAE and the zero-shot network (example "
           f"{r['example'].get('take')}[{r['example'].get('start')}:{r['example'].get('stop')}]); "
           f"autoencoders {r['ae_epochs']} epochs, feature models {r['epochs']} epochs on the weight-0 autoencoder; "
           f"{r['samples']} samples per model and split. Candidates trained with seed {first}. Skating: share of "
           "contact foot-frames whose planted point moves > 0.2 m/s (samples / real clips of the model's style in "
           "that split; autoencoder: the primitive's clips of every style through it / as recorded). Rule: "
           f"{r['rule']}.\n\n"
           + md_table(["model", "contact_weight", "val skating (model / real)", "val contact share (model / real)",
                       "val contact loss (m²/s²)",
                       "val recognition", "val MPJPE (cm)", "eligible", "test skating (model / real)"], rows)
           + "\n\nChosen (bold): " + ", ".join(f"{NAMES[k]} {c['chosen']:g}" for k, c in r["choice"].items())
           + (f". **At the edge of the grid** for {', '.join(edges)}: a larger weight was not tried." if edges else ".")
           + f" {prov}")
    seeds = len(r["per_seed"])
    trows = []
    for kind in MODELS:
        for w, s in r["summary"][kind].items():
            trows.append([NAMES[kind], f"**{w}**" if float(w) == r["choice"][kind]["chosen"] else w,
                          _pm(s["test_samples"], unit=" %"), _pm(s["test_real"], unit=" %"),
                          _pm(s["test_ratio_to_real"], 1, 2), _pm(s["test_recognition"], unit=" %"),
                          _pm(s["test_mpjpe"], 100, 2),
                          f"{s['test_samples']['n']}"])
    test = (f"**Test** figures of weight 0 and the chosen weight (bold), mean ± sd over {seeds} seed(s) of the feature "
            f"models (one autoencoder), {r['data']} {r['primitive']}: raw skating of {r['samples']} samples drawn "
            f"with seed + 1000 against the test clips of the model's style (neutral for the VAE), recognition by a "
            f"classifier fitted on the train clips of every style, and the reconstruction error of the test clips.\n\n"
            + md_table(["model", "contact_weight", "sample skating", "real skating", "samples ÷ real",
                        "recognition", "test MPJPE (cm)", "seeds"], trows) + f"\n\n{prov}")
    parts = []
    for kind in MODELS:
        chosen = r["choice"][kind]["chosen"]
        s0, sc = r["summary"][kind]["0"], r["summary"][kind][f"{chosen:g}"]
        text = f"{NAMES[kind]} {_pm(s0['test_samples'], unit=' %')}"
        if chosen:
            text += f" → {_pm(sc['test_samples'], unit=' %')} at weight {chosen:g}"
        else:
            text += " (weight 0 chosen)"
        parts.append(text + f" (real {_pm(s0['test_real'], unit=' %')})")
    headline = (f"Raw foot skating of samples (share of contact foot-frames sliding > 0.2 m/s, {r['data']} "
                f"{r['primitive']}, CVAE and zero-shot style {r['style']}; **test** clips, {seeds} seed(s)), without "
                "and with the foot-contact velocity loss at the weight chosen on validation clips: "
                + "; ".join(parts) + ". Autoencoder: weight "
                + f"{r['choice']['autoencoder']['chosen']:g} chosen. Details: benchmarks/evaluation.md. {prov}")
    return {"headline": headline, "validation": val, "test": test}
