"""Benchmark of stylemotion.annotate on Bandai (benchmarks/annotate.md): Krüger's Table 3.2, sub-class
parametrization, tensor truncation (Tables 4.1/4.4 analogues) and annotation speed.

    python scripts/bench_annotate.py --documents 100 --out runs/bench_annotate

Documents: ``--seconds`` long, test-split takes of random contents joined by ``--blend`` unlabelled frames
(stylemotion.annotate.documents). Templates: ``--per-class`` train takes per content. Sub-class: the walk
tensor (``--repetitions`` train takes per style; accuracy also for 3, 5, 8, 12)
fits every test and validation walk take, and every walk
segment the annotation finds in the documents; the evaluation package's StyleClassifier, fitted on the same
train walk takes, is the comparison. Prints markdown tables and writes ``results.json`` into ``--out``.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np
from omegaconf import OmegaConf

from stylemotion.annotate.annotation import (
    AnnotationSettings,
    annotate_distances,
    class_distances,
    frame_scores,
    segment_scores,
)
from stylemotion.annotate.documents import random_document
from stylemotion.annotate.features import relational_features
from stylemotion.annotate.model import learn_model
from stylemotion.annotate.tensors import build_tensor, n_mode_svd
from stylemotion.datasets import build_dataset
from stylemotion.evaluation.classifier import StyleClassifier
from stylemotion.io.atomic import atomic_write_bytes
from stylemotion.morphable.warping import resample
from stylemotion.representation import positions_to_frames
from stylemotion.skeleton import CANONICAL_PARENTS

REPETITION_SWEEP = (3, 5, 8, 12)
TAUS = (0.005, 0.01, 0.02, 0.03, 0.04, 0.05, 0.08, 0.13)


def load(data: str):
    """The ``data`` config's dataset (Bandai: ``$STYLEMOTION_DATA`` or ``../shared/data``, run from the repo root)
    and its default split."""
    import stylemotion.configs

    cfg = OmegaConf.load(Path(stylemotion.configs.__file__).parent / "data" / f"{data}.yaml")
    takeset = build_dataset(cfg)
    split = cfg.get("split") or {}
    return takeset, takeset.split(int(split.get("seed", 0)), float(split.get("val_fraction", 0.1)),
                                  float(split.get("test_fraction", 0.1)))


def pooled(pairs):
    """Concatenate documents (a blank frame between, so that no segment spans two) and score them."""
    truth, pred = [], []
    for t, p in pairs:
        truth += list(t) + [""]
        pred += list(p) + [""]
    return {**frame_scores(truth, pred), **segment_scores(truth, pred)}


def table_32(documents, model, settings):
    started = time.perf_counter()
    features = [relational_features(d.positions, d.fps) for d in documents]
    feature_s = time.perf_counter() - started
    started = time.perf_counter()
    distances = [class_distances(f, model.templates, settings) for f in features]
    distance_s = time.perf_counter() - started
    rows = []
    for min_run in (0, settings.min_run):
        for keyframes in (False, True):
            for tau in TAUS:
                t0 = time.perf_counter()
                annotations = [annotate_distances(d, tau, keyframes, min_run) for d in distances]
                label_s = time.perf_counter() - t0
                scores = pooled([(doc.labels, a.label_names()) for doc, a in zip(documents, annotations)])
                rows.append({"min_run": min_run, "keyframes": keyframes, "tau": tau,
                             **{k: round(v, 4) for k, v in scores.items()}, "label_s": round(label_s, 3)})
    frames = sum(len(d.labels) for d in documents)
    timing = {"frames": frames, "features_s": round(feature_s, 2), "distances_s": round(distance_s, 2),
              "per_hour_s": round((feature_s + distance_s) * 108000 / frames, 1)}
    return rows, timing, distances


def clip_frames(positions, length):
    frames = positions_to_frames(np.asarray(positions, dtype=np.float64), 30.0)[0]
    return resample(frames, np.linspace(0, len(frames) - 1, length))


def subclass(split, repetitions, documents, distances, settings, model_classes):
    train = {}
    for t in split["train"]:
        if t.content == "walk":
            train.setdefault(t.style, []).append(t.positions)
    started = time.perf_counter()
    tensor, theta = build_tensor("walk", train, 30.0, min(repetitions, *(len(v) for v in train.values())))
    build_s = time.perf_counter() - started
    held = [t for t in split["test"] + split["val"] if t.content == "walk"]
    started = time.perf_counter()
    fits = [tensor.parametrize(t.positions) for t in held]
    fit_s = (time.perf_counter() - started) / len(held)
    truth = np.array([t.style for t in held])
    tensor_acc = float(np.mean([f.style == s for f, s in zip(fits, truth)]))
    length = tensor.frames
    train_takes = [t for t in split["train"] if t.content == "walk"]
    clf = StyleClassifier(components=16, seed=0).fit(
        np.stack([clip_frames(t.positions, length) for t in train_takes]),
        np.array([t.num_frames / 30.0 for t in train_takes]), [t.style for t in train_takes])
    report = clf.evaluate(np.stack([clip_frames(t.positions, length) for t in held]),
                          np.array([t.num_frames / 30.0 for t in held]), truth)
    # annotated walk segments of the documents (key frames on, default tau): style of the take they overlap most
    walk = model_classes.index("walk")
    seg_right = seg_total = 0
    for doc, dist in zip(documents, distances):
        a = annotate_distances(dist, settings.tau, True, settings.min_run)
        labels = a.labels
        edges = np.flatnonzero(np.diff(np.r_[-2, labels, -2]) != 0)
        for s, e in zip(edges[:-1], edges[1:]):
            if labels[s] != walk or e - s < 2:
                continue
            overlap = [(min(e, pe) - max(s, ps), style) for _, c, style, ps, pe in doc.parts if c == "walk"]
            overlap = [o for o in overlap if o[0] > 0]
            if not overlap:
                continue
            seg_total += 1
            seg_right += tensor.parametrize(doc.positions[s:e]).style == max(overlap)[1]
    counts = {s: int((truth == s).sum()) for s in tensor.styles}
    sweep = {}
    for r in REPETITION_SWEEP:
        if r <= min(len(v) for v in train.values()):
            other = build_tensor("walk", train, 30.0, r)[0]
            sweep[r] = round(float(np.mean([other.parametrize(t.positions).style == t.style for t in held])), 4)
    return {"repetition_sweep": sweep, "styles": list(tensor.styles), "repetitions": tensor.repetitions,
            "held_out_takes": len(held),
            "per_style": counts, "tensor_accuracy": round(tensor_acc, 4),
            "classifier_accuracy": round(report.accuracy, 4), "chance": round(1 / len(tensor.styles), 4),
            "majority": round(max(counts.values()) / len(held), 4), "fit_s_per_take": round(fit_s, 3),
            "build_s": round(build_s, 2), "document_walk_segments": seg_total,
            "document_walk_segment_accuracy": round(seg_right / seg_total, 4) if seg_total else None}, tensor, theta


def bone_angles(coords):
    """Bone directions ``(..., 20, 3)`` of root-local coordinates ``(..., 63)``."""
    p = coords.reshape(*coords.shape[:-1], 21, 3)
    child = [j for j, parent in enumerate(CANONICAL_PARENTS) if parent >= 0]
    bones = p[..., child, :] - p[..., [CANONICAL_PARENTS[j] for j in child], :]
    return bones / np.maximum(np.linalg.norm(bones, axis=-1, keepdims=True), 1e-9)


def truncation(tensor, theta):
    d, f, s, r = theta.shape
    original = np.moveaxis(theta, (0, 1), (-1, -2))          # (s, r, f, d)
    rows = []
    for ranks in [(63, f, s, r), (40, f, s, r), (30, f // 2, s, r), (20, f // 4, s, r), (15, f // 4, s, 3),
                  (10, f // 8, s, 3), (8, f // 8, 4, 2), (5, 16, 3, 2)]:
        small = tensor.truncated(ranks)
        recon = np.stack([np.stack([small.synthesize(np.eye(s)[i], np.eye(r)[j]) for j in range(r)])
                          for i in range(s)])
        cm = 100 * np.linalg.norm((recon - original).reshape(s, r, f, 21, 3), axis=-1).mean()
        cos = np.clip((bone_angles(recon) * bone_angles(original)).sum(-1), -1, 1)
        rows.append({"ranks": list(ranks), "kib": round(small.nbytes / 1024, 1),
                     "error_cm": round(float(cm), 3), "error_deg": round(float(np.degrees(np.arccos(cos)).mean()), 3)})
    flat = original.reshape(s * r, -1)
    t0 = time.perf_counter()
    for _ in range(5):
        n_mode_svd(theta)
    svd_s = (time.perf_counter() - t0) / 5
    from sklearn.decomposition import PCA

    t0 = time.perf_counter()
    for _ in range(5):
        PCA(n_components=min(flat.shape) - 1, svd_solver="full").fit(flat)
    pca_s = (time.perf_counter() - t0) / 5
    return rows, {"theta_shape": list(theta.shape), "theta_kib": round(theta.nbytes / 1024, 1),
                  "n_mode_svd_s": round(svd_s, 4), "pca_s": round(pca_s, 4)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", default="bandai")
    parser.add_argument("--documents", type=int, default=100)
    parser.add_argument("--seconds", type=float, default=40.0)
    parser.add_argument("--blend", type=int, default=8)
    parser.add_argument("--per-class", type=int, default=9)
    parser.add_argument("--repetitions", type=int, default=12)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="runs/bench_annotate")
    args = parser.parse_args()
    out = Path(args.out)
    if (out / "results.json").exists():
        raise SystemExit(f"{out / 'results.json'} exists; choose another --out")
    load_avg = os.getloadavg()
    takeset, split = load(args.data)
    t0 = time.perf_counter()
    model = learn_model(split["train"], takeset.fps, args.per_class, args.seed, tensors=False)
    learn_s = time.perf_counter() - t0
    rng = np.random.default_rng(args.seed)
    pool = [(t.name, t.content, t.style, t.positions) for t in split["test"]]
    documents = [random_document(pool, takeset.fps, args.seconds, rng, args.blend) for _ in range(args.documents)]
    settings = AnnotationSettings()
    rows, timing, distances = table_32(documents, model, settings)
    sub, tensor, theta = subclass(split, args.repetitions, documents, distances, settings, list(model.classes))
    trunc, decomposition = truncation(tensor, theta)
    results = {"data": args.data, "args": vars(args), "load_average_at_start": [round(x, 2) for x in load_avg],
               "load_average_at_end": [round(x, 2) for x in os.getloadavg()], "learn_templates_s": round(learn_s, 2),
               "templates": {t.label: {"frames": t.num_frames, "consistent": round(float(t.mask.mean()), 3)}
                             for t in model.templates},
               "documents": len(documents), "document_frames": timing["frames"], "table_3_2": rows,
               "timing": timing, "subclass": sub, "truncation": trunc, "decomposition": decomposition}
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(out / "results.json", (json.dumps(results, indent=1) + "\n").encode())
    print("| min_run | key frames | τ | P1 | R1 | F1 | P2 | R2 | F2 |\n|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        scores = " | ".join(f"{r[k]:.3f}" for k in ("P1", "R1", "F1", "P2", "R2", "F2"))
        print(f"| {r['min_run']} | {'with' if r['keyframes'] else 'no'} | {r['tau']} | {scores} |")
    print(json.dumps({k: v for k, v in results.items() if k not in ("table_3_2", "truncation")}, indent=1))
    print("| ranks (DOF, frames, style, rep) | KiB | error cm | error deg |\n|---|---|---|---|")
    for r in trunc:
        print(f"| {tuple(r['ranks'])} | {r['kib']} | {r['error_cm']} | {r['error_deg']} |")


if __name__ == "__main__":
    main()
