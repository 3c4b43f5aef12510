"""Benchmark of the Morphable Graph (issue 14) on Bandai (or the synthetic default), as JSON lines.

    python scripts/bench_morphable.py --parts k,dims,tree,path,tables --out runs/bench_morphable [--data bandai]

Parts (each prints JSON lines, also appended to ``<out>/morphable.jsonl``):

* ``k`` (Fig. 3.9): joint-space RMSE of the spline fit against the number of coefficients ``K`` for the
  walk and run stance primitives (training clips of the neutral style);
* ``dims`` (Fig. 3.10): reconstruction error in feature space (unexplained share of the coefficients'
  variance) and in joint space (RMSE, m) against latent dimensions, FPCA / normalized FPCA / SFPCA, on
  walk_leftStance's training clips;
* ``tree`` (Fig. 4.12): ``--constraints`` random position, orientation and pose constraints at the last
  keyframe (targets from fresh mixture samples): median error, evaluations and time of the thesis' k-means,
  GMM and median trees of the codes (beam search), of the model's tree (keyframe space) by beam and by branch
  and bound at several evaluation budgets, the best of 100 random samples, and brute force over the tree's
  10,000 codes;
* ``path``: the 10 m S-curve of ``stylemotion-generate`` with the two stance models (seeds 0 1 2);
* ``tables`` (Tables 5.2/5.3): pose_SD, V_SD, step_SD of 10,000 samples per stance model against the
  training clips, and the model size against the training data's;
* ``density`` (Fig. 4.9): the left foot at the last frame, mocap against 60,000 samples (``density_foot_l.png``);
* ``vae`` (Fig. 3.10's fourth curve, with ``--vae-run``): the walk_leftStance VAE of a finished
  ``stylemotion-reproduce`` run on the same training clips: posterior mean → decoder → autoencoder →
  positions against the recorded clips (joint-space RMSE, m) and against the autoencoder's own
  reconstruction (the VAE's compression alone), the unexplained share of its input's variance, and the
  three FPCA variants at the VAE's latent size for comparison;
* ``arm`` (Fig. 3.9/3.10 for an arm primitive, and a keyframe constraint): ``--arm-primitive`` clips
  (``raise``, ``lower`` or, for wave contents, ``wave`` cycles) of the ``--arm-content`` takes
  (:mod:`stylemotion.morphable.arm`), spline RMSE against ``K``, the three reductions against latent
  dimensions, a model fitted with the default settings, and the hand reaching targets at the primitive's
  last frame (the held-out clips' own end positions, and random points of the box the training clips' end
  positions span): error of the mean motion, of the tree's candidate and after the MAP solve; and
  Fig. 4.9 for the hand (``density_hand_l.png``);
* ``rows`` (Tables 5.1–5.3, with ``--vae-run``): the run's evaluation (its VAEs and CVAEs, its settings) with the
  two stance models as ``morphable`` extra rows (:mod:`stylemotion.morphable.rows`), report in ``<out>/report``;
* ``latent`` (Fig. 3.11): t-SNE of the training clips' 20-dimensional codes per method, coloured by content,
  and how often a code's 5 nearest neighbours share its content (``latent_tsne.png``).

Models are fitted once into ``<out>/models/<primitive>/model.npz`` (default settings, the neutral style)
and reused by later runs.
"""

from __future__ import annotations

import argparse
import json
import os
import time
import warnings
from pathlib import Path

import numpy as np
from omegaconf import OmegaConf

from stylemotion.config import CONFIG_DIR
from stylemotion.datamodules.clips import ClipDataModule
from stylemotion.evaluation.tables import variance_stats
from stylemotion.models.sampling import pad_motions
from stylemotion.morphable import FitSettings, MorphableModel, fit_primitive
from stylemotion.morphable.bspline import SplineBasis
from stylemotion.morphable.constraints import KeyframeConstraint, objective
from stylemotion.morphable.fpca import METHODS, fit_reduction
from stylemotion.morphable.model import (
    coefficient_vectors,
    functional_data,
    joint_error_function,
    reconstruction_error,
    spline_rmse,
)
from stylemotion.morphable.tree import SpaceTree, brute_force
from stylemotion.morphable.variants import variant_name
from stylemotion.primitives.segmentation import parse_primitive, time_normalize
from stylemotion.skeleton import CANONICAL_JOINTS
from stylemotion.synthesis.controller import SharpTurnWarning
from stylemotion.synthesis.generate import generate

STANCES = ("walk_leftStance", "walk_rightStance")
DIMS = (1, 2, 3, 5, 8, 10, 15, 20, 30, 40)
CONSTRAINED_JOINTS = ("Hand_L", "Hand_R", "Foot_L", "Foot_R", "Head")
BOUNDED_BUDGETS = (30, 60, 120, 240)


class Bench:
    def __init__(self, data: str, out: Path, style: str):
        self.data_name, self.out, self.style = data, out, style
        self.data = OmegaConf.to_container(OmegaConf.load(CONFIG_DIR / "data" / f"{data}.yaml"), resolve=True)
        out.mkdir(parents=True, exist_ok=True)
        self.log = out / "morphable.jsonl"

    def emit(self, record: dict) -> None:
        line = json.dumps({"data": self.data_name, **record}, default=float)
        print(line, flush=True)
        with self.log.open("a") as fh:
            fh.write(line + "\n")

    def clips(self, primitive: str) -> dict[str, list]:
        action, name = parse_primitive(primitive)
        dm = ClipDataModule(data=self.data, action=action, primitives=[name], styles=[self.style])
        dm.setup()
        return dm.clips

    def model(self, primitive: str) -> MorphableModel:
        path = self.out / "models" / primitive / "model.npz"
        if path.is_file():
            return MorphableModel.load(path)
        began = time.perf_counter()
        model = fit_primitive(self.clips(primitive)["train"], FitSettings(), meta={"data": self.data_name})
        fitted = time.perf_counter() - began
        model.build_tree()
        model.save(path)
        self.emit({"part": "fit", "primitive": primitive, "seconds_fit": fitted,
                   "seconds_with_tree": time.perf_counter() - began, **{k: model.meta["fit"][k] for k in
                                                                       ("clips", "joint_rmse_m", "gmm_components")},
                   "num_coefficients": model.basis.num_coefficients, "timeline": model.length})
        return model


def part_k(b: Bench) -> None:
    for primitive in STANCES + ("run_leftStance", "run_rightStance"):
        data = functional_data(b.clips(primitive)["train"])
        for k in range(4, data.length + 1):
            b.emit({"part": "k", "primitive": primitive, "K": k, "clips": len(data.aligned), "timeline": data.length,
                    "joint_rmse_m": spline_rmse(data, k)})


def part_dims(b: Bench, k: int | None, iterations: int, primitive: str = "walk_leftStance",
              clips: list | None = None, counts: tuple[int, ...] = DIMS) -> None:
    clips = b.clips(primitive)["train"] if clips is None else clips
    data = functional_data(clips)
    k = k or b.model(primitive).basis.num_coefficients
    basis = SplineBasis(k)
    vectors, groups, _ = coefficient_vectors(data, basis)
    error = joint_error_function(data, basis, vectors)
    total = ((vectors - vectors.mean(0)) ** 2).sum()
    for dims in counts:
        if dims >= len(vectors):
            continue
        for method in METHODS:
            began = time.perf_counter()
            pca, record = fit_reduction(vectors, groups, dims, method, error, iterations)
            rebuilt = pca.reconstruct(pca.project(vectors))
            b.emit({"part": "dims", "primitive": primitive, "K": k, "dims": dims, "method": method,
                    "feature_unexplained": float(((rebuilt - vectors) ** 2).sum() / total),
                    "joint_rmse_m": float(np.sqrt(error(rebuilt))), "seconds": time.perf_counter() - began,
                    "sfpca_start": record.get("start")})


def _constraint(kind: str, rng: np.random.Generator, model: MorphableModel) -> KeyframeConstraint:
    code = model.gmm.sample(1, rng)
    pos, rot = model.poses_at(code, [model.length - 1], rotations=True)
    joint = CONSTRAINED_JOINTS[rng.integers(len(CONSTRAINED_JOINTS))]
    j = CANONICAL_JOINTS.index(joint)
    if kind == "position":
        return KeyframeConstraint("position", pos[0, 0, j], joint=joint)
    if kind == "orientation":
        return KeyframeConstraint("orientation", rot[0, 0, j], joint=joint)
    return KeyframeConstraint("pose", pos[0, 0])


def part_tree(b: Bench, count: int, candidates: list[int]) -> None:
    """Fig. 4.12: the thesis' trees (k-means, GMM and median splits of the codes, 16 per leaf, beam search) and
    the default tree (k-means on the keyframe values, 4 per leaf) by beam and by branch and bound."""
    for primitive in STANCES:
        model = b.model(primitive)
        trees = {}
        for split in ("kmeans", "gmm", "median"):
            began = time.perf_counter()
            trees[split] = SpaceTree.build(model.tree.latent, split=split, seed=0, leaf_size=16)
            b.emit({"part": "tree_build", "primitive": primitive, "split": split, "space": "latent", "leaf_size": 16,
                    "seconds": time.perf_counter() - began, "depth": trees[split].depth,
                    "nodes": len(trees[split].start)})
        began = time.perf_counter()
        bounds = model.keyframe_bounds()
        b.emit({"part": "tree_bounds", "primitive": primitive, "space": model.tree.space,
                "nodes": len(model.tree.start), "depth": model.tree.depth, "seconds": time.perf_counter() - began,
                "bytes": bounds.nbytes})
        rng = np.random.default_rng(1)
        for kind in ("position", "orientation", "pose"):
            rows: dict[str, list[tuple[float, int, float]]] = {}

            def record(method: str, found, seconds: float, rows=rows) -> None:
                rows.setdefault(method, []).append((found.cost, found.evaluations, seconds))

            for _ in range(count):
                constraint = _constraint(kind, rng, model)
                cost = objective(model, [constraint])
                t = time.perf_counter()
                record("brute_force", brute_force(model.tree.latent, cost), time.perf_counter() - t)
                random = model.gmm.sample(100, rng)
                rows.setdefault("random_100", []).append((float(cost(random).min()), 100, 0.0))
                for split, tree in trees.items():
                    for c in candidates:
                        t = time.perf_counter()
                        record(f"{split}_c{c}", tree.search(cost, c), time.perf_counter() - t)
                t = time.perf_counter()
                record("keyframes_c4", model.tree.search(cost, 4), time.perf_counter() - t)
                bound = bounds.lower_bound([constraint], model.length)
                for budget in BOUNDED_BUDGETS:
                    t = time.perf_counter()
                    found = model.tree.search_bounded(cost, bound, budget)
                    record(f"bounded_{budget}", found, time.perf_counter() - t)
                    rows.setdefault(f"bounded_{budget}_exact", []).append((float(found.exact), 0, 0.0))
            brute = np.median([e for e, _, _ in rows["brute_force"]])
            for method, values in rows.items():
                err = np.array([e for e, _, _ in values])
                if method.endswith("_exact"):
                    b.emit({"part": "tree", "primitive": primitive, "kind": kind, "method": method,
                            "constraints": count, "share_proved_optimal": float(err.mean())})
                    continue
                b.emit({"part": "tree", "primitive": primitive, "kind": kind, "method": method, "constraints": count,
                        "median_error": float(np.median(err)), "median_vs_brute": float(np.median(err) / brute),
                        "mean_ratio_to_own_brute": float(np.mean(err / np.maximum([e for e, _, _ in
                                                                                    rows["brute_force"]], 1e-12))),
                        "median_evaluations": float(np.median([n for _, n, _ in values])),
                        "max_evaluations": int(max(n for _, n, _ in values)),
                        "median_ms": 1000 * float(np.median([t for _, _, t in values]))})


def part_path(b: Bench, seeds: list[int]) -> None:
    models = {p: str(b.out / "models" / p / "model.npz") for p in STANCES}
    for p in STANCES:
        b.model(p)
    for seed in seeds:
        out = b.out / "generate" / f"seed{seed}"
        cfg = {"model": {"family": "morphable"}, "models": models, "style": "neutral", "seed": seed, "out": str(out),
               "force": True, "outputs": {"bvh": True, "gif": seed == seeds[0]}}
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", SharpTurnWarning)
            s = generate(cfg)
        b.emit({"part": "path", "seed": seed, **{f"deviation_{k}": s["deviation"][k] for k in ("mean_m", "max_m",
                                                                                               "final_m")},
                "duration_s": s["duration_s"], "steps": s["steps"], "mean_speed_mps": s["mean_speed_mps"],
                "skating": s["foot_skating_ratio"], "skating_raw": s["foot_skating_ratio_before_cleanup"],
                "transition_speed_ratio": s["transitions"]["ratio"], "bvh_mpjpe_m": s.get("bvh_reimport_mpjpe_m"),
                "synthesis_s": s["synthesis_seconds"], "sharp_turn_warnings": len(caught),
                "load": os.getloadavg()[0]})


#: Paths of part lookahead: the standard S-curve, a sharper double S, and a right-angle corner.
LOOKAHEAD_PATHS = {
    "s_curve": {"s_curve": {"length_m": 10.0, "amplitude_m": 1.0, "waves": 1.0}},
    "double_s": {"s_curve": {"length_m": 10.0, "amplitude_m": 1.0, "waves": 2.0}},
    "corner": {"points": [[0.0, 0.0], [0.0, 3.0], [0.0, 4.0], [0.3, 4.7], [1.0, 5.0], [2.0, 5.0], [5.0, 5.0]]},
}


def _variant_models(runs: list[Path]) -> dict[str, dict[str, str]]:
    """``{walk_<stance>: {variant: model file}}`` of stylemotion-train experiment=morphable_graph run folders."""
    found: dict[str, dict[str, str]] = {}
    for run in runs:
        model = MorphableModel.load(run)
        key = f"{model.meta['action']}_{model.meta['primitive']}"
        found.setdefault(key, {})[str(model.meta.get("variant", "all"))] = str(model.meta["path"])
    return found


def part_lookahead(b: Bench, runs: list[Path]) -> None:
    """The graph walk's look-ahead (§4.5.1) among turn variants, against one model per stance, on three paths."""
    models = _variant_models(runs)
    three = ["straight", "left", "right"]
    graphs = {"one model": (["all"], 1), "3 variants, greedy": (three, 1), "3 variants, T=2": (three, 2),
              "3 variants, T=3": (three, 3), "all + turns, T=2": (["all", "left", "right"], 2)}
    for path_name, path in LOOKAHEAD_PATHS.items():
        for graph_name, (variants, steps) in graphs.items():
            names = [variant_name(None if v == "all" else v) for v in variants]
            chosen = {key: [found[n] for n in names] for key, found in models.items()}
            out = b.out / "lookahead" / path_name / graph_name.replace(" ", "_").replace(",", "").replace("+", "")
            cfg = {"model": {"family": "morphable"}, "models": chosen, "style": "neutral", "seed": 0, "out": str(out),
                   "force": True, "path": path, "morphable": {"lookahead_steps": steps},
                   "outputs": {"bvh": False, "gif": False}}
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always", SharpTurnWarning)
                s = generate(cfg)
            used = [st["variant"] for st in json.loads((out / "summary.json").read_text())["steps_detail"]]
            b.emit({"part": "lookahead", "path": path_name, "graph": graph_name, "variants": names,
                    "lookahead_steps": steps, **{f"deviation_{k}": s["deviation"][k] for k in ("mean_m", "max_m",
                                                                                            "final_m")},
                    "steps": s["steps"], "skating": s["foot_skating_ratio"],
                    "transition_speed_ratio": s["transitions"]["ratio"], "synthesis_s": s["synthesis_seconds"],
                    "variants_used": {n: used.count(n) for n in set(used)}, "sharp_turn_warnings": len(caught),
                    "load": os.getloadavg()[0]})


def part_tables(b: Bench, samples: int) -> None:
    for primitive in STANCES:
        model, clips = b.model(primitive), b.clips(primitive)["train"]
        frames, n = pad_motions([c.frames for c in clips])
        positions, _ = pad_motions([c.positions for c in clips])
        normalized = np.stack([time_normalize(c.frames, model.length) for c in clips])
        real = variance_stats(frames.numpy(), positions.numpy(), n.numpy(), normalized)
        began = time.perf_counter()
        s = model.sample(samples, seed=0)
        seconds = time.perf_counter() - began
        fake = variance_stats(s.frames.numpy(), s.positions.numpy(), s.num_frames.numpy(), s.normalized_frames.numpy())
        data_bytes = sum(c.positions.astype(np.float32).nbytes for c in clips)
        model_bytes = (b.out / "models" / primitive / "model.npz").stat().st_size
        b.emit({"part": "tables", "primitive": primitive, "samples": samples, "sample_seconds": seconds,
                "training": real, "morphable": fake,
                "ratio": {k: fake[k] / real[k] for k in ("pose_sd", "v_sd", "step_sd", "pose_across_sd")},
                "model_bytes": model_bytes, "model_bytes_without_tree": sum(
                    v.nbytes for k, v in model.to_arrays().items() if not k.startswith("tree_")),
                "training_positions_bytes": data_bytes})


def part_density(b: Bench, samples: int, model: MorphableModel | None = None, clips: list | None = None,
                 joint: str = "Foot_L", name: str = "walk_leftStance") -> None:
    """Fig. 4.9: ``joint`` at the last frame of a primitive (default the left foot of walk_leftStance), mocap
    against ``samples`` model samples (``density_<joint>.png``)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if model is None:
        model, clips = b.model("walk_leftStance"), b.clips("walk_leftStance")["train"]
    j = CANONICAL_JOINTS.index(joint)
    real = np.stack([c.positions[-1, j] for c in clips])
    fake = model.poses_at(model.gmm.sample(samples, 0), [model.length - 1])[:, 0, j]
    fig, axes = plt.subplots(2, 2, figsize=(8, 7))
    for row, (points, label_) in enumerate(((real, f"motion capture ({len(real)} clips)"),
                                            (fake, f"Morphable Graph ({samples:,} samples)"))):
        for col, (i, k, label) in enumerate(((0, 2, "x (left) / z (forward), m"), (0, 1, "x / y (up), m"))):
            axes[row, col].hexbin(points[:, i], points[:, k], gridsize=40, cmap="viridis", mincnt=1,
                                  extent=(real[:, i].min() - 0.1, real[:, i].max() + 0.1,
                                          real[:, k].min() - 0.1, real[:, k].max() + 0.1))
            axes[row, col].set_title(f"{label_}: {label}", fontsize=8)
    fig.suptitle(f"{b.data_name} {name}: {joint} at the last frame (Fig. 4.9)", fontsize=9)
    fig.tight_layout()
    path = b.out / f"density_{joint.lower()}.png"
    fig.savefig(path, dpi=80)
    plt.close(fig)
    inside = np.mean([(fake[:, k] >= np.quantile(real[:, k], 0.005)) & (fake[:, k] <= np.quantile(real[:, k], 0.995))
                      for k in range(3)], axis=0).mean()
    b.emit({"part": "density", "primitive": name, "joint": joint, "samples": samples, "figure": str(path),
            "real_mean_m": real.mean(0).tolist(), "samples_mean_m": fake.mean(0).tolist(),
            "real_sd_m": real.std(0).tolist(), "samples_sd_m": fake.std(0).tolist(),
            "samples_inside_real_range": float(inside)})


def part_vae(b: Bench, run_folder: Path, k: int | None, iterations: int) -> None:
    """Fig. 3.10's fourth curve: the run's walk_leftStance VAE on the training clips of the FPCA curves."""
    import torch

    from stylemotion.datamodules.features import encode_frames
    from stylemotion.models.loading import load_generative
    from stylemotion.models.sampling import decode_features
    from stylemotion.training.run_folder import FinishedRun, read_json_object

    primitive = "walk_leftStance"
    run = FinishedRun(run_folder, read_json_object(run_folder / "reproduce.json", "reproduce.json"), {})
    stages = [s for s in run.stages("vae") if (s.get("values") or {}).get("primitive") == primitive]
    if not stages:
        raise SystemExit(f"--vae-run {run_folder}: its reproduce.json has no vae stage of {primitive}")
    ckpt = run.located(stages[0]["checkpoint"])
    vae = load_generative(ckpt)
    clips = b.clips(primitive)["train"]
    spec = vae.spec
    if spec["clips"]["train"] != len(clips) or spec["content_styles"] != [b.style]:
        raise SystemExit(f"--vae-run {run_folder}: {ckpt} was trained on {spec['clips']['train']} clips of "
                         f"{spec['content_styles']}, these are {len(clips)} of [{b.style!r}]")
    length, fps = vae.timeline_frames, vae.fps
    began = time.perf_counter()
    features = encode_frames(vae.autoencoder, np.stack([time_normalize(c.frames, length) for c in clips]))
    duration = torch.tensor([c.duration_s for c in clips], dtype=torch.float32)
    recon = vae.reconstruct(features, duration)
    floor = decode_features(vae.autoencoder, features, duration, length, fps)
    seconds = time.perf_counter() - began
    recorded, _ = pad_motions([c.positions for c in clips])
    if recon.positions.shape != recorded.shape or not torch.equal(recon.num_frames, floor.num_frames):
        raise SystemExit(f"reconstructions {tuple(recon.positions.shape)} do not match the clips "
                         f"{tuple(recorded.shape)}: durations changed the frame counts")
    valid = (torch.arange(recorded.shape[1])[None] < recon.num_frames[:, None]).numpy()

    def rmse(a: torch.Tensor, ref: torch.Tensor) -> float:
        return float(np.sqrt((((a - ref) ** 2).sum(-1).mean(-1)).numpy()[valid].mean()))

    with torch.no_grad():
        y = vae.normalize(features, duration)
        rebuilt = vae.net.decode(vae.net.encode(y)[0])
    unexplained = float(((rebuilt - y) ** 2).sum() / ((y - y.mean(0)) ** 2).sum())
    b.emit({"part": "vae", "primitive": primitive, "checkpoint": str(ckpt), "dims": vae.hparams.latent_dim,
            "clips": len(clips), "feature_unexplained": unexplained,
            "joint_rmse_m": rmse(recon.positions, recorded), "joint_rmse_vs_autoencoder_m": rmse(recon.positions,
                                                                                                 floor.positions),
            "autoencoder_rmse_m": rmse(floor.positions, recorded), "seconds": seconds, "load": os.getloadavg()[0]})
    part_dims(b, k, iterations, primitive, clips, (int(vae.hparams.latent_dim),))


def part_arm(b: Bench, content: str, iterations: int, k: int | None = None, targets: int = 50,
             primitive: str = "raise") -> None:
    """An arm primitive (``content``'s ``primitive`` clips: ``raise``, ``lower`` or a wave content's ``wave``
    cycles): Fig. 3.9, Fig. 3.10, a model (``k`` coefficients, default by the RMSE cut-off), hand keyframes at its
    last frame and Fig. 4.9 for the hand."""
    from stylemotion.datasets.registry import build_dataset
    from stylemotion.morphable.arm import arm_clips
    from stylemotion.morphable.synthesis import MapSettings, UnreachableConstraintWarning, solve_constraints

    takes = build_dataset(b.data).split(**b.data.get("split", {}))
    clips, rejected = {}, {}
    for part in ("train", "test"):
        clips[part], rejected[part] = arm_clips([t for t in takes[part] if t.style == b.style], content, primitive)
    name = f"{content}_{primitive}"
    data = functional_data(clips["train"])
    b.emit({"part": "arm_clips", "primitive": name, "clips": {p: len(c) for p, c in clips.items()},
            "rejected": rejected, "timeline": data.length,
            "frames": [int(min(c.num_frames for c in clips["train"])), int(max(c.num_frames for c in clips["train"]))]})
    for count in range(4, data.length + 1):
        b.emit({"part": "k", "primitive": name, "K": count, "clips": len(data.aligned), "timeline": data.length,
                "joint_rmse_m": spline_rmse(data, count)})
    path = b.out / "models" / (name if k is None else f"{name}_K{k}") / "model.npz"
    if path.is_file():
        model = MorphableModel.load(path)
    else:
        began = time.perf_counter()
        model = fit_primitive(clips["train"], FitSettings(num_coefficients=k),
                              meta={"data": b.data_name, "action": content, "primitive": primitive})
        model.build_tree()
        model.save(path)
        b.emit({"part": "fit", "primitive": name, "K_given": k, "seconds_with_tree": time.perf_counter() - began,
                **{k: model.meta["fit"][k] for k in ("clips", "joint_rmse_m", "gmm_components")},
                "num_coefficients": model.basis.num_coefficients, "timeline": model.length,
                "test_joint_rmse_m": reconstruction_error(model, clips["test"]), "load": os.getloadavg()[0]})
    part_dims(b, model.basis.num_coefficients, iterations, name, clips["train"])
    hand = "Hand_L" if "left" in content else "Hand_R"
    part_density(b, 60_000, model, clips["train"], hand, name)
    j = CANONICAL_JOINTS.index(hand)
    ends = np.stack([c.positions[-1, j] for c in clips["train"]])
    rng = np.random.default_rng(0)
    goals = {"held-out clip": [c.positions[-1, j] for c in clips["test"]],
             "box of training ends": list(rng.uniform(ends.min(0), ends.max(0), (targets, 3)))}
    mean_code = (model.gmm.weights[:, None] * model.gmm.means).sum(0)
    mean_hand = model.poses_at(mean_code[None], [model.length - 1])[0, 0, j]
    for scale in (0.02, 0.005):
        for kind, points in goals.items():
            rows = []
            for target in points:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", UnreachableConstraintWarning)
                    began = time.perf_counter()
                    result = solve_constraints(model, [KeyframeConstraint("position", target, joint=hand)],
                                               MapSettings(constraint_scale_m=scale))
                rows.append((float(np.linalg.norm(mean_hand - target)), result.start_errors_m[0], result.errors_m[0],
                             result.evaluations, time.perf_counter() - began,
                             result.neg_log_prior))
            r = np.array(rows)
            b.emit({"part": "arm_keyframe", "primitive": name, "joint": hand, "targets": kind, "count": len(rows),
                    "constraint_scale_m": scale, "median_mean_motion_m": float(np.median(r[:, 0])),
                    "median_tree_m": float(np.median(r[:, 1])), "median_map_m": float(np.median(r[:, 2])),
                    "max_map_m": float(r[:, 2].max()), "share_within_2cm": float((r[:, 2] <= 0.02).mean()),
                    "median_evaluations": float(np.median(r[:, 3])), "median_seconds": float(np.median(r[:, 4])),
                    "median_neg_log_prior": float(np.median(r[:, 5])), "load": os.getloadavg()[0]})


def part_rows(b: Bench, run_folder: Path) -> None:
    """Tables 5.1–5.3 of a finished run's models with the Morphable Graph's stance models as extra rows."""
    from stylemotion.evaluation.run import run_evaluation
    from stylemotion.morphable.rows import ROW
    from stylemotion.training.run_folder import FinishedRun, read_json_object

    run = FinishedRun(run_folder, read_json_object(run_folder / "reproduce.json", "reproduce.json"),
                      read_json_object(run_folder / "report" / "report.json", "report"))
    checkpoints = [str(run.located(s["checkpoint"])) for kind in ("vae", "cvae") for s in run.stages(kind)]
    settings = {k: v for k, v in run.meta["settings"].items() if k != "seed"}
    began = time.perf_counter()
    results = run_evaluation(run.data_cfg, checkpoints, settings, b.out / "report", run.seed,
                             autoencoder_ckpt=str(run.autoencoder_ckpt),
                             command="scripts/bench_morphable.py --parts rows",
                             extra_rows={p: {ROW: b.model(p)} for p in STANCES})
    for p in STANCES:
        t = results["table_5_1"][p]
        b.emit({"part": "rows", "primitive": p, "run": str(run_folder), "seconds": time.perf_counter() - began,
                "variance": {r: results["variance"][p][r] for r in ("training_data", "neutral", ROW)},
                "variance_ratio": {r: results["variance_ratio"][p][r] for r in ("neutral", ROW)},
                "table_5_1_examples": t["examples"], "table_5_1_neutral": t["distance"][t["models"].index("neutral")],
                "table_5_1_morphable": t["extra_rows"][ROW], "load": os.getloadavg()[0]})


def part_latent(b: Bench, k: int | None, iterations: int, dims: int = 20) -> None:
    """Fig. 3.11: 2-D t-SNE of the latent codes of walk_leftStance's training clips by method, coloured by content
    (walk / walk-turn-left / walk-turn-right); the agreement of each code's 5 nearest neighbours' content."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from sklearn.manifold import TSNE
    from sklearn.model_selection import cross_val_score
    from sklearn.neighbors import KNeighborsClassifier

    clips = b.clips("walk_leftStance")["train"]
    data = functional_data(clips)
    basis = SplineBasis(k or b.model("walk_leftStance").basis.num_coefficients)
    vectors, groups, _ = coefficient_vectors(data, basis)
    error = joint_error_function(data, basis, vectors)
    labels = np.array([c.content for c in clips])
    names = sorted(set(labels))
    fig, axes = plt.subplots(1, len(METHODS), figsize=(4 * len(METHODS), 4))
    for ax, method in zip(axes, METHODS):
        pca, _ = fit_reduction(vectors, groups, dims, method, error, iterations)
        codes = pca.project(vectors)
        codes = codes / codes.std()
        knn = float(cross_val_score(KNeighborsClassifier(5), codes, labels, cv=5).mean())
        xy = TSNE(2, random_state=0, init="pca", perplexity=30).fit_transform(codes)
        for name in names:
            ax.scatter(*xy[labels == name].T, s=6, label=name)
        ax.set_title(f"{method}: 5-NN content accuracy {knn:.2f}", fontsize=9)
        b.emit({"part": "latent", "method": method, "dims": dims, "knn5_content_accuracy": knn,
                "contents": {n: int((labels == n).sum()) for n in names}})
    axes[0].legend(fontsize=7)
    fig.suptitle(f"{b.data_name} walk_leftStance latent codes ({dims} dims), t-SNE (Fig. 3.11)", fontsize=9)
    fig.tight_layout()
    fig.savefig(b.out / "latent_tsne.png", dpi=80)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", default="bandai")
    parser.add_argument("--style", default="normal")
    parser.add_argument("--out", default="runs/bench_morphable")
    parser.add_argument("--parts", default="k,dims,tree,path,tables")
    parser.add_argument("--K", type=int, help="coefficients for dims and the arm model (default: the fitted model's)")
    parser.add_argument("--sfpca-iterations", type=int, default=15)
    parser.add_argument("--constraints", type=int, default=200, help="per kind and primitive")
    parser.add_argument("--candidates", type=int, nargs="*", default=[1, 2, 4])
    parser.add_argument("--seeds", type=int, nargs="*", default=[0, 1, 2])
    parser.add_argument("--samples", type=int, default=10_000)
    parser.add_argument("--arm-content", default="raise-up-left-hand", help="arm takes of part arm")
    parser.add_argument("--arm-primitive", default="raise", choices=["raise", "lower", "wave"],
                        help="the arm primitive of part arm (wave: of a wave-… --arm-content)")
    parser.add_argument("--vae-run", type=Path, help="a finished stylemotion-reproduce run folder (part vae)")
    parser.add_argument("--variant-runs", type=Path, nargs="*", default=[],
                        help="part lookahead: stylemotion-train experiment=morphable_graph run folders of both walk "
                             "stances with turn=null (variant all), left, right and straight")
    args = parser.parse_args(argv)
    b = Bench(args.data, Path(args.out), args.style)
    parts = args.parts.split(",")
    unknown = set(parts) - {"k", "dims", "tree", "path", "tables", "density", "latent", "vae", "arm", "rows",
                            "lookahead"}
    if unknown:
        parser.error(f"unknown parts {sorted(unknown)}")
    if "k" in parts:
        part_k(b)
    if "dims" in parts:
        part_dims(b, args.K, args.sfpca_iterations)
    if "tree" in parts:
        part_tree(b, args.constraints, args.candidates)
    if "path" in parts:
        part_path(b, args.seeds)
    if "tables" in parts:
        part_tables(b, args.samples)
    if "density" in parts:
        part_density(b, 60_000)
    if "latent" in parts:
        part_latent(b, args.K, args.sfpca_iterations)
    if "arm" in parts:
        part_arm(b, args.arm_content, args.sfpca_iterations, args.K, primitive=args.arm_primitive)
    if ("vae" in parts or "rows" in parts) and args.vae_run is None:
        parser.error("parts vae and rows need --vae-run <finished stylemotion-reproduce run folder>")
    if "vae" in parts:
        part_vae(b, args.vae_run, args.K, args.sfpca_iterations)
    if "rows" in parts:
        part_rows(b, args.vae_run)
    if "lookahead" in parts:
        if not args.variant_runs:
            parser.error("part lookahead needs --variant-runs <run folders>")
        part_lookahead(b, args.variant_runs)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
