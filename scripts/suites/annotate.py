"""Suite ``annotate``: Krüger ch. 3 on Bandai — annotation by class motion templates (Table 3.2) and the style
of a motion from its class motion tensor (§3.3, §4.1), plus a document of other captures.

Annotation: templates from ``--per-class`` train takes per content (drawn with the seed). Documents: every
val (or test) take exactly once, in an order drawn with the seed, joined by ``--blend`` unlabelled frames into
documents of at least ``--seconds`` (:func:`stylemotion.annotate.documents.partition_documents`), and
documents of **cuts**: each take's middle 2–3 s (a seeded length, as long as a user's short recording; the other
captures' walks are 2.1–2.7 s) joined the same way. τ, ``min_run``, the key-frame tolerance and ``sub_frames``
(whole templates or windows of them, §3.3's sub-templates) are chosen on the val documents of both kinds
(objective: mean over seeds and the two kinds of (F1 + F2) / 2, pooled over a seed's documents), and reported on
the test documents of both kinds. Other captures: the walks of ``other-skeletons`` read as
``stylemotion-annotate`` reads a user's file, joined into one document.

Tensors: the walk tensor from ``r`` train takes per style (drawn with the seed); ``r`` chosen by the style
accuracy on val walk takes, reported on test walk takes, beside the evaluation package's StyleClassifier.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np
from suites.common import (
    DATA_ROOT,
    bandai_split_settings,
    fmt,
    fmt_spread,
    md_table,
    provenance_line,
    spread,
    take_split_record,
)

DESCRIPTION = ("annotation by motion templates (Table 3.2) and style by class motion tensors on Bandai: τ, "
               "min_run, key frames and tensor repetitions chosen on val takes, reported on test takes; "
               "a document of other captures")
DEFAULT_SEEDS = (0, 1, 2)

TAUS = (0.01, 0.015, 0.02, 0.025, 0.03, 0.04, 0.05, 0.08, 0.13)
MIN_RUNS = (0, 10, 20, 30, 45, 60)
KEYFRAME_TOLERANCES = (None, 0.0, 0.1, 0.2)      # None: no key-frame preselection
SUB_FRAMES = (0, 45, 90)                        # 0: whole templates; else windows of that many frames (key frames off)
#: The turning layer (z: classes whose mean turning rates lie z × (sd + sd) apart compete; seconds per piece);
#: (0, 0): off. A first smoke run (one seed, 30 % of the
#: takes) also tried sub-templates of 30 and 60 frames: every one scored below 45 and 90 on val.
TURNING = ((0.0, 0.0),) + tuple((z, w) for z in (1.0, 2.0, 3.0) for w in (0.0, 2.0, 4.0))
CUT_FRAMES = (60, 90)                           # a cut's length, drawn per take (2–3 s at 30 fps)
KINDS = ("takes", "cuts")                       # the two kinds of documents
REPETITIONS = (2, 3, 5, 8, 10, None)                  # None: as many as every style has
OLD_DEFAULT = {"tau": 0.02, "keyframes": 0.1, "min_run": 30, "sub_frames": 0, "turning_z": 0.0,  # before any choice
               "turning_window_s": 0.0}
OTHER_CAPTURES = ("walk_21joint_60fps.bvh", "female-walk_21joint_60fps.bvh", "xia_neutral_01_000_31joint_120fps.bvh")
SCORES = ("P1", "R1", "F1", "P2", "R2", "F2")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--seconds", type=float, default=40.0, help="least length of a document, s")
    parser.add_argument("--blend", type=int, default=8, help="unlabelled blend frames between two takes")
    parser.add_argument("--per-class", type=int, default=9, help="train takes averaged into each template")
    parser.add_argument("--take-fraction", type=float, default=1.0,
                        help="share of the val and test takes each seed uses (a seeded draw; 1 = all)")


def setting_key(tau: float, tol: float | None, min_run: int, sub: int = 0, z: float = 0.0, w: float = 0.0) -> str:
    return (f"tau={tau:g} keyframes={'off' if tol is None else f'{tol:g}'} min_run={min_run} sub_frames={sub} "
            f"turning_z={z:g} turning_window_s={w:g}")


def pooled_scores(documents, predictions) -> dict[str, float]:
    """Table 3.2 scores of a seed's documents pooled (a blank frame between documents)."""
    from stylemotion.annotate.annotation import frame_scores, segment_scores

    truth, pred = [], []
    for doc, p in zip(documents, predictions):
        truth += list(doc.labels) + [""]
        pred += list(p) + [""]
    return {**frame_scores(truth, pred), **segment_scores(truth, pred)}


def _names(labels: np.ndarray, classes: tuple[str, ...]) -> list[str]:
    return ["" if i < 0 else classes[i] for i in labels]


class Annotated:
    """A seed's documents with their features and subsequence-DTW distances (per ``sub_frames``, computed when
    first asked for), re-thresholded cheaply."""

    def __init__(self, documents, model):
        from stylemotion.annotate.feature_sets import compute_features

        self.documents, self.model = documents, model
        t0 = time.perf_counter()
        self.features = [compute_features(d.positions, d.fps, model.feature_set) for d in documents]
        self.features_s = time.perf_counter() - t0
        self.distances_s = 0.0
        self._variants: dict[tuple[float | None, int], list] = {}
        self._families: dict[float, dict[str, set[str]]] = {}
        self.yaw = None
        self.base(0)

    def refined(self, labels: list[np.ndarray], tau: float, tol: float | None, sub: int, z: float, w: float = 0.0
                ) -> list[np.ndarray]:
        """``labels`` (one int array per document) after the turning layer at ``z`` sd in pieces of ``w`` s (``z``
        0: as they are)."""
        from stylemotion.annotate.turning import document_yaw, refine_labels, root_track, template_families

        turning, speed = self.model.record.get("turning"), self.model.record.get("speed")
        if z <= 0 or not (turning or speed):
            return labels
        if self.yaw is None:
            self.yaw = [document_yaw(d.positions, d.fps) for d in self.documents]
            self.track = [root_track(d.positions) for d in self.documents]
        if tau not in self._families:
            self._families[tau] = template_families(self.model.templates, tau)
        return [refine_labels(lab, d.classes, d.delta, yaw, track, doc.fps, self._families[tau], turning, speed, z,
                              int(round(w * doc.fps)))
                for lab, d, yaw, track, doc in zip(labels, self.distances(tol, sub), self.yaw, self.track,
                                                   self.documents)]

    def base(self, sub: int) -> list:
        from stylemotion.annotate.annotation import AnnotationSettings, class_distances

        if (None, sub) not in self._variants:
            t0 = time.perf_counter()
            plain = AnnotationSettings(keyframes=False, sub_frames=sub)
            self._variants[None, sub] = [class_distances(f, self.model.templates, plain) for f in self.features]
            if sub == 0:
                self.distances_s = time.perf_counter() - t0
        return self._variants[None, sub]

    def distances(self, tol: float | None, sub: int = 0):
        from stylemotion.annotate.annotation import with_keyframes

        if tol is None:
            return self.base(sub)
        if sub:
            raise ValueError("key-frame preselection is compared with whole templates only")
        if (tol, 0) not in self._variants:
            self._variants[tol, 0] = [with_keyframes(d, f, self.model.templates, 3, tol)
                                      for d, f in zip(self.base(0), self.features)]
        return self._variants[tol, 0]

    def raw_labels(self, tau: float, tol: float | None, sub: int = 0) -> list[np.ndarray]:
        """Per document the frame labels before ``min_run`` (int, -1 = none)."""
        from stylemotion.annotate.annotation import annotate_distances

        return [annotate_distances(d, tau, tol is not None, 0).labels for d in self.distances(tol, sub)]

    def indices(self, tau: float, tol: float | None, min_run: int, sub: int = 0, z: float = 0.0,
                w: float = 0.0) -> list[np.ndarray]:
        """Per document the frame labels (int, -1 = none) after ``min_run`` and the turning layer."""
        from stylemotion.annotate.annotation import drop_short_runs

        return self.refined([drop_short_runs(raw, min_run) for raw in self.raw_labels(tau, tol, sub)], tau, tol,
                            sub, z, w)

    def labels(self, tau: float, tol: float | None, min_run: int, sub: int = 0, z: float = 0.0,
               w: float = 0.0) -> list[list[str]]:
        return [_names(lab, self.model.classes) for lab in self.indices(tau, tol, min_run, sub, z, w)]


def load_bandai():
    from stylemotion.datasets.registry import load_dataset

    split_cfg = bandai_split_settings()
    takeset = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"))
    return takeset, takeset.split(split_cfg["seed"], split_cfg["val_fraction"], split_cfg["test_fraction"]), split_cfg


def take_pool(takes, fraction: float, rng: np.random.Generator):
    takes = sorted(takes, key=lambda t: t.name)
    if fraction < 1.0:
        keep = sorted(rng.permutation(len(takes))[:max(1, int(round(fraction * len(takes))))])
        takes = [takes[i] for i in keep]
    return [(t.name, t.content, t.style, t.positions) for t in takes]


def cut_takes(pool, rng: np.random.Generator):
    """Each take of ``pool`` cut to its middle ``n`` frames, ``n`` drawn from :data:`CUT_FRAMES` (a whole take when
    shorter): short single-action recordings, as a user's file often is."""
    out = []
    for name, content, style, positions in pool:
        n = int(rng.integers(CUT_FRAMES[0], CUT_FRAMES[1] + 1))
        a = max(0, (len(positions) - n) // 2)
        out.append((name, content, style, positions[a:a + n]))
    return out


def other_captures_document(seed: int, fps: float, blend: int):
    """The other-skeletons walks read by ``stylemotion-annotate``'s reader, in a seeded order, joined."""
    from stylemotion.annotate.command import load_document
    from stylemotion.annotate.documents import join_takes

    folder = DATA_ROOT / "other-skeletons"
    takes = []
    for name in OTHER_CAPTURES:
        positions, _ = load_document(str(folder / name), fps)
        takes.append((name, "walk", "unknown", positions))
    order = np.random.default_rng(seed).permutation(len(takes))
    return join_takes([takes[i] for i in order], fps, blend), {t[0]: int(t[3].shape[0]) for t in takes}


def _bandai_control(test_takes, lengths: list[int], seed: int, fps: float, blend: int, model,
                    setting) -> dict[str, Any]:
    """Like for like with the other captures: the middles of test walk takes (drawn with the seed), cut to
    the other captures' lengths and joined the same way; fraction of walk frames labelled / labelled walk."""
    from stylemotion.annotate.documents import join_takes

    walks = sorted((t for t in test_takes if t.content == "walk"), key=lambda t: t.name)
    chosen = np.random.default_rng([seed, 2]).permutation(len(walks))[:len(lengths)]
    cuts = []
    for i, n in zip(chosen, lengths):
        take = walks[int(i)]
        a = max(0, (take.num_frames - n) // 2)
        cuts.append((take.name, "walk", take.style, take.positions[a:a + n]))
    doc = join_takes(cuts, fps, blend)
    labels = Annotated([doc], model).labels(*setting)[0]
    walk_frames = [lab for lab, want in zip(labels, doc.labels) if want]
    return {"takes": [c[0] for c in cuts], "labelled": float(np.mean([lab != "" for lab in walk_frames])),
            "labelled_walk": float(np.mean([lab == "walk" for lab in walk_frames]))}


def _bone_directions(coords: np.ndarray) -> np.ndarray:
    """Unit bone directions ``(..., 20, 3)`` of ``(..., 63)`` root-local coordinates."""
    from stylemotion.skeleton import CANONICAL_PARENTS

    p = coords.reshape(*coords.shape[:-1], 21, 3)
    child = [j for j, parent in enumerate(CANONICAL_PARENTS) if parent >= 0]
    bones = p[..., child, :] - p[..., [CANONICAL_PARENTS[j] for j in child], :]
    return bones / np.maximum(np.linalg.norm(bones, axis=-1, keepdims=True), 1e-9)


def _truncation(tensor, theta: np.ndarray) -> list[dict[str, Any]]:
    """Memory and reconstruction error of the training examples at a few rank choices (Tables 4.1/4.4)."""
    d, f, s, r = theta.shape
    original = np.transpose(theta, (2, 3, 1, 0))                  # (styles, reps, frames, 63)
    rows = []
    for ranks in [(d, f, s, r), (40, f, s, r), (30, f // 2, s, r), (20, f // 4, s, r), (15, f // 4, s, min(r, 3)),
                  (10, f // 8, s, min(r, 3)), (8, f // 8, min(s, 4), min(r, 2)), (5, 16, min(s, 3), min(r, 2))]:
        small = tensor.truncated(ranks)
        recon = small.reconstruction()
        cm = 100 * np.linalg.norm((recon - original).reshape(s, r, f, 21, 3), axis=-1).mean()
        cos = np.clip((_bone_directions(recon) * _bone_directions(original)).sum(-1), -1, 1)
        rows.append({"ranks": list(ranks), "kib": small.nbytes / 1024, "error_cm": float(cm),
                     "error_deg": float(np.degrees(np.arccos(cos)).mean())})
    return rows


def _walk_segment_styles(annotated: Annotated, tensor, tau: float, tol: float | None,
                         min_run: int, sub: int = 0, z: float = 0.0, w: float = 0.0) -> tuple[int, int]:
    """Walk segments the annotation finds in the documents, and how many the tensor gives the style of the
    walk take they overlap most."""
    right = total = 0
    walk = annotated.model.classes.index("walk")
    for doc, labels in zip(annotated.documents, annotated.indices(tau, tol, min_run, sub, z, w)):
        edges = np.flatnonzero(np.diff(np.r_[-2, labels, -2]) != 0)
        for s, e in zip(edges[:-1], edges[1:]):
            if labels[s] != walk or e - s < 2:
                continue
            overlap = [(min(e, pe) - max(s, ps), style) for _, c, style, ps, pe in doc.parts if c == "walk"]
            overlap = [o for o in overlap if o[0] > 0]
            if not overlap:
                continue
            total += 1
            right += tensor.parametrize(doc.positions[s:e]).style == max(overlap)[1]
    return right, total


def seed_documents(split, fps: float, seed: int, args: argparse.Namespace) -> dict[str, list]:
    """A seed's documents: ``val``/``test`` (whole takes) and ``val_cuts``/``test_cuts`` (2–3 s cuts), every drawn
    take once, in a seeded order (:func:`stylemotion.annotate.documents.partition_documents`)."""
    from stylemotion.annotate.documents import partition_documents

    rng = np.random.default_rng([seed, 1])
    docs = {part: partition_documents(take_pool(split[part], args.take_fraction, rng), fps, args.seconds, rng,
                                      args.blend) for part in ("val", "test")}
    cut_rng = np.random.default_rng([seed, 3])
    docs.update({f"{part}_cuts": partition_documents(cut_takes(take_pool(split[part], args.take_fraction, rng),
                                                               cut_rng), fps, args.seconds, rng, args.blend)
                 for part in ("val", "test")})
    return docs


def score_candidates(annotated: Annotated, documents, candidates) -> dict[str, dict[str, float]]:
    """Pooled Table 3.2 scores of every candidate ``(tau, tol, min_run, sub, z, w)`` on ``documents`` (the raw
    labels of a ``(sub, tol, tau)`` are computed once and re-thresholded)."""
    from stylemotion.annotate.annotation import drop_short_runs

    classes = annotated.model.classes
    out: dict[str, dict[str, float]] = {}
    groups: dict[tuple, list] = {}
    for c in candidates:
        groups.setdefault((c[3], c[1], c[0]), []).append(c)
    for (sub, tol, tau), group in groups.items():
        raws = annotated.raw_labels(tau, tol, sub)
        by_run: dict[int, list] = {}
        for c in group:
            by_run.setdefault(c[2], []).append(c)
        for mr, runs in by_run.items():
            short = [drop_short_runs(raw, mr) for raw in raws]
            for c in runs:
                preds = [_names(lab, classes) for lab in annotated.refined(short, tau, tol, sub, c[4], c[5])]
                out[setting_key(*c)] = pooled_scores(documents, preds)
    return out


def val_objective(val_scores: dict[str, dict[str, list]], key: str, kinds: tuple[str, ...] = KINDS) -> float:
    """The choice's objective: the mean over seeds and document kinds of (F1 + F2) / 2."""
    return float(np.mean([(s["F1"] + s["F2"]) / 2 for k in kinds for s in val_scores[k][key]]))


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1):          # one BLAS thread: the machine is shared (and small QRs run faster)
        return _run(args, seeds)


def _run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.annotate.documents import part_scores
    from stylemotion.annotate.model import learn_model, tensor_examples
    from stylemotion.annotate.tensors import build_tensor
    from stylemotion.evaluation.classifier import StyleClassifier
    from stylemotion.morphable.warping import resample
    from stylemotion.representation import positions_to_frames

    takeset, split, split_cfg = load_bandai()
    fps = float(takeset.fps)
    candidates = [(tau, tol, mr, sub, z, w) for z, w in TURNING for sub in SUB_FRAMES
                  for tol in (KEYFRAME_TOLERANCES if sub == 0 else (None,)) for tau in TAUS for mr in MIN_RUNS]
    val_scores: dict[str, dict[str, list[dict[str, float]]]] = {k: {setting_key(*c): [] for c in candidates}
                                                                for k in KINDS}
    per_seed: dict[int, dict[str, Any]] = {}
    for seed in seeds:
        model = learn_model(split["train"], fps, args.per_class, seed, tensors=False)
        docs = seed_documents(split, fps, seed, args)
        annotated = {part: Annotated(d, model) for part, d in docs.items()}
        for kind, part in zip(KINDS, ("val", "val_cuts")):
            for key, scores in score_candidates(annotated[part], docs[part], candidates).items():
                val_scores[kind][key].append(scores)
            annotated[part]._variants.clear()                    # free memory: val is done
        per_seed[seed] = {"model": model, "annotated": annotated["test"], "annotated_cuts": annotated["test_cuts"],
                          "docs": docs}

    def objective(key: str, kinds: tuple[str, ...] = KINDS) -> float:
        return val_objective(val_scores, key, kinds)

    # the best objective; among equals the first in candidate order (whole templates before windows, key frames
    # off before on, then the smaller τ, then the smaller min_run)
    best = max(candidates, key=lambda c: objective(setting_key(*c)))
    tau, tol, min_run, sub, z, w = best
    chosen = {"tau": tau, "keyframes": tol, "min_run": min_run, "sub_frames": sub, "turning_z": z,
              "turning_window_s": w}
    whole = max((c for c in candidates if c[3] == 0 and c[4] == 0), key=lambda c: objective(setting_key(*c)))
    reported = {"chosen": best,
                "old default": (OLD_DEFAULT["tau"], OLD_DEFAULT["keyframes"], OLD_DEFAULT["min_run"], 0, 0.0, 0.0)}
    if sub or z:
        reported["whole templates alone (best on val without sub-templates or turning layer)"] = whole
    if not sub:
        reported["chosen, no key frames" if tol is not None else "chosen, key frames on (tolerance 0.1)"] = \
            (tau, None if tol is not None else 0.1, min_run, 0, z, w)
    reported["thesis' procedure (chosen τ, no min_run)"] = (tau, tol, 0, sub, z, w)
    test_rows: dict[str, dict[str, Any]] = {}
    cut_rows: dict[str, dict[str, Any]] = {}
    per_class: dict[str, dict[str, list[float]]] = {}
    parts_failures: list[dict[str, Any]] = []
    cross: list[dict[str, Any]] = []
    timing = []
    for seed in seeds:
        annotated, docs = per_seed[seed]["annotated"], per_seed[seed]["docs"]
        for name, setting in reported.items():
            preds = annotated.labels(*setting)
            scores = pooled_scores(docs["test"], preds)
            test_rows.setdefault(name, {"setting": setting_key(*setting), "seeds": []})["seeds"].append(scores)
            cut_preds = per_seed[seed]["annotated_cuts"].labels(*setting)
            cut_rows.setdefault(name, {"setting": setting_key(*setting), "seeds": []})["seeds"].append(
                pooled_scores(docs["test_cuts"], cut_preds))
            if name == "chosen":
                parts = [p for doc, pred in zip(docs["test"], preds) for p in part_scores(doc, pred)]
                recalls = np.array([p["recall"] for p in parts])
                parts_failures.append({"takes": len(parts), "missed": int((recalls == 0).sum()),
                                       "under_half": int((recalls < 0.5).sum()),
                                       "recall_p5": float(np.percentile(recalls, 5)),
                                       "recall_median": float(np.median(recalls))})
                truth = np.array([lab for doc in docs["test"] for lab in doc.labels], dtype=object)
                pred = np.array([lab for p in preds for lab in p], dtype=object)
                for c in annotated.model.classes:
                    rel, ret = truth == c, pred == c
                    entry = per_class.setdefault(c, {"R1": [], "P1": [], "unlabelled": []})
                    entry["R1"].append(float((rel & ret).sum() / max(rel.sum(), 1)))
                    entry["P1"].append(float((rel & ret).sum() / max(ret.sum(), 1)))
                    entry["unlabelled"].append(float((rel & (pred == "")).sum() / max(rel.sum(), 1)))
        frames = sum(len(d.labels) for d in docs["test"])
        timing.append({"frames": frames, "documents": len(docs["test"]), "features_s": annotated.features_s,
                       "distances_s": annotated.distances_s})
        # other captures, annotated with this seed's Bandai templates at the chosen settings
        doc, lengths = other_captures_document(seed, fps, args.blend)
        other = Annotated([doc], annotated.model)
        labels = other.labels(*best)[0]
        walk_frames = [lab for lab, want in zip(labels, doc.labels) if want]
        whole_frames = [lab for lab, want in zip(other.labels(*whole)[0], doc.labels) if want]
        cross.append({"frames": len(doc.labels), "walk_frames": len(walk_frames), "files_frames": lengths,
                      "labelled": float(np.mean([lab != "" for lab in walk_frames])),
                      "labelled_walk": float(np.mean([lab == "walk" for lab in walk_frames])),
                      "whole_templates": {"labelled": float(np.mean([lab != "" for lab in whole_frames])),
                                          "labelled_walk": float(np.mean([lab == "walk" for lab in whole_frames]))},
                      "labels": {c: int(sum(lab == c for lab in labels)) for c in sorted(set(labels) - {""})},
                      "walk_template_frames": next(t.num_frames for t in annotated.model.templates
                                                   if t.label == "walk"),
                      "order": [p[0] for p in doc.parts],
                      "bandai_control": _bandai_control(split["test"], [lengths[p[0]] for p in doc.parts], seed, fps,
                                                        args.blend, annotated.model, best)})

    # class motion tensors: the walk, 7 styles
    walk_val = [t for t in split["val"] if t.content == "walk"]
    walk_test = [t for t in split["test"] if t.content == "walk"]
    train_walks = [t for t in split["train"] if t.content == "walk"]
    tensor_val: dict[str, list[float]] = {str(r): [] for r in REPETITIONS}
    tensors: dict[tuple[int, str], Any] = {}
    for seed in seeds:
        for r in REPETITIONS:
            tensor, theta = build_tensor("walk", tensor_examples(split["train"], "walk", r, seed), fps)
            tensor_val[str(r)].append(float(np.mean([tensor.parametrize(t.positions).style == t.style
                                                     for t in walk_val])))
            tensors[seed, str(r)] = (tensor, theta)
    # highest mean val accuracy; among equals the most repetitions (None = all every style has, last)
    chosen_r = max(REPETITIONS[::-1], key=lambda r: np.mean(tensor_val[str(r)]))
    tensor_test, classifier_test, segments_right, truncation = [], [], [], []
    length = tensors[seeds[0], str(chosen_r)][0].frames

    def clip(positions):
        frames = positions_to_frames(np.asarray(positions, dtype=np.float64), fps)[0]
        return resample(frames, np.linspace(0, len(frames) - 1, length))

    truth = [t.style for t in walk_test]
    for seed in seeds:
        tensor, theta = tensors[seed, str(chosen_r)]
        fits = [tensor.parametrize(t.positions).style for t in walk_test]
        tensor_test.append({"right": int(sum(f == s for f, s in zip(fits, truth))), "takes": len(walk_test),
                            "predicted": fits, "repetitions": tensor.repetitions})
        clf = StyleClassifier(components=16, seed=seed).fit(
            np.stack([clip(t.positions) for t in train_walks]), np.array([t.num_frames / fps for t in train_walks]),
            [t.style for t in train_walks])
        pred = clf.predict(np.stack([clip(t.positions) for t in walk_test]),
                           np.array([t.num_frames / fps for t in walk_test]))
        classifier_test.append({"right": int(sum(p == s for p, s in zip(pred, truth))), "takes": len(walk_test)})
        right, total = _walk_segment_styles(per_seed[seed]["annotated"], tensor, *best)
        segments_right.append({"right": right, "segments": total})
        truncation.append({"shape": list(theta.shape), "theta_kib": theta.nbytes / 1024,
                           "rows": _truncation(tensor, theta)})
    counts = {s: truth.count(s) for s in sorted(set(truth))}

    return {
        "splits": {
            "takes": take_split_record(split, split_cfg["seed"], split_cfg["val_fraction"], split_cfg["test_fraction"]),
            "annotation": "templates from train takes (drawn with the seed); τ, min_run, key-frame tolerance and "
                          "sub_frames chosen on documents of val takes (whole takes and 2–3 s cuts); figures on "
                          "documents of test takes (both kinds)",
            "tensors": "walk tensor from train walk takes (repetitions drawn with the seed); repetitions chosen "
                       "on val walk takes; figures on test walk takes",
            "other captures": "the other-skeletons walks (other actors, studios, skeletons) as one document, "
                              "Bandai templates; nothing chosen on them",
        },
        "settings": {"seconds": args.seconds, "blend": args.blend, "per_class": args.per_class,
                     "take_fraction": args.take_fraction, "keyframe_count": 3,
                     "cut_frames": list(CUT_FRAMES), "sub_frames": list(SUB_FRAMES),
                     "turning": [list(t) for t in TURNING],
                     "objective": "mean over seeds and the two kinds of val documents (whole takes, cuts) of "
                                  "(F1 + F2) / 2"},
        "documents": {part: [{"documents": len(per_seed[s]["docs"][part]),
                              "frames": sum(len(d.labels) for d in per_seed[s]["docs"][part]),
                              "takes": sum(len(d.parts) for d in per_seed[s]["docs"][part])} for s in seeds]
                      for part in ("val", "test", "val_cuts", "test_cuts")},
        "templates": {t.label: t.num_frames for t in per_seed[seeds[0]]["model"].templates},
        "candidates": [{"tau": c[0], "keyframes": c[1], "min_run": c[2], "sub_frames": c[3], "turning_z": c[4],
                        "turning_window_s": c[5],
                        "objective": objective(setting_key(*c)),
                        **{f"objective_{k}": objective(setting_key(*c), (k,)) for k in KINDS},
                        **{k: spread(s[k] for s in val_scores["takes"][setting_key(*c)]) for k in SCORES}}
                       for c in candidates],
        "chosen": chosen, "old_default": OLD_DEFAULT,
        "test": {name: {"setting": row["setting"], **{k: spread(s[k] for s in row["seeds"]) for k in SCORES},
                        "unlabelled": spread(s["unlabelled1"] / s["relevant1"] for s in row["seeds"]),
                        "confused": spread(s["confused1"] / s["relevant1"] for s in row["seeds"]),
                        "spurious_frames": spread(s["spurious1"] for s in row["seeds"]),
                        "per_seed": row["seeds"]} for name, row in test_rows.items()},
        "test_cuts": {name: {"setting": row["setting"], **{k: spread(s[k] for s in row["seeds"]) for k in SCORES},
                             "unlabelled": spread(s["unlabelled1"] / s["relevant1"] for s in row["seeds"]),
                             "confused": spread(s["confused1"] / s["relevant1"] for s in row["seeds"])}
                      for name, row in cut_rows.items()},
        "test_takes": parts_failures,
        "per_class": {c: {k: spread(v) for k, v in e.items()} for c, e in per_class.items()},
        "other_captures": cross,
        "tensor": {"class": "walk", "styles": sorted(counts), "repetition_candidates": [str(r) for r in REPETITIONS],
                   "val_accuracy": {r: spread(v) for r, v in tensor_val.items()}, "val_walk_takes": len(walk_val),
                   "chosen_repetitions": str(chosen_r), "test_walk_takes": len(walk_test), "test_per_style": counts,
                   "test": tensor_test, "classifier_test": classifier_test,
                   "chance": 1 / len(counts), "majority": max(counts.values()) / len(walk_test),
                   "document_walk_segments": segments_right, "truncation": truncation},
        "timing": timing,
    }


# ---------------------------------------------------------------------------------------------------- render

def _turning(z: float, w: float) -> str:
    return "off" if not z else f"z = {z:g}, " + ("whole runs" if not w else f"{w:g} s pieces")


def setting_label(tau: float, tol: float | None, min_run: int, sub: int = 0, z: float = 0.0, w: float = 0.0) -> str:
    return (f"τ = {tau:g}, key frames {'off' if tol is None else f'on (tolerance {tol:g})'}, min_run = {min_run}, "
            + ("whole templates" if not sub else f"sub-templates of {sub} frames") + ", turning layer "
            + _turning(z, w))


def _counts(rows: list[dict[str, Any]], key: str, total: str) -> str:
    s = spread(r[key] for r in rows)
    return f"{fmt_spread(s, 1)} of {rows[0][total]}"


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    prov = provenance_line(record)
    seeds = len(record.get("seeds", []))
    c = r["chosen"]
    chosen_text = setting_label(*(c[k] for k in ("tau", "keyframes", "min_run", "sub_frames", "turning_z",
                                            "turning_window_s")))
    cuts = r["test_cuts"]["chosen"]
    test = r["test"]["chosen"]
    t = r["tensor"]
    n_test_docs = spread(d["documents"] for d in r["documents"]["test"])
    sub = "" if r["settings"]["take_fraction"] >= 1 else (
        f" (each seed a seeded {r['settings']['take_fraction']:.0%} of the val and of the test takes)")
    easier = ("documents are whole single-action Bandai test takes joined by "
              f"{r['settings']['blend']} blend frames — easier than the thesis' continuous recordings")
    cross = r["other_captures"]
    tensor_acc = spread(x["right"] / x["takes"] for x in t["test"])
    clf_acc = spread(x["right"] / x["takes"] for x in t["classifier_test"])
    seg = spread(x["right"] / x["segments"] for x in t["document_walk_segments"] if x["segments"])
    failures = r["test_takes"]
    rows = [
        ["frame P1 / R1 / F1 (" + easier + ")", " / ".join(fmt_spread(test[k], 3) for k in ("P1", "R1", "F1"))],
        ["segment P2 / R2 / F2 (same documents)", " / ".join(fmt_spread(test[k], 3) for k in ("P2", "R2", "F2"))],
        ["class frames left unlabelled / given another class",
         f"{fmt_spread(test['unlabelled'], 3)} / {fmt_spread(test['confused'], 3)}"],
        ["frame F1 / segment F2 on documents of 2–3 s cuts of the test takes (like a user's short recordings)",
         f"{fmt_spread(cuts['F1'], 3)} / {fmt_spread(cuts['F2'], 3)}"],
        ["test takes with no frame labelled right / under half",
         f"{_counts(failures, 'missed', 'takes')} / {_counts(failures, 'under_half', 'takes')}"],
        ["**other captures**: 3 walks of other actors and skeletons, one document: labelled / labelled walk "
         "(the templates alone at their best val setting → the choice)",
         f"{fmt_spread(spread(x['whole_templates']['labelled'] for x in cross), 3)} / "
         f"{fmt_spread(spread(x['whole_templates']['labelled_walk'] for x in cross), 3)} → "
         f"{fmt_spread(spread(x['labelled'] for x in cross), 3)} / "
         f"{fmt_spread(spread(x['labelled_walk'] for x in cross), 3)}"],
        ["same-length cuts of Bandai test walks joined the same way (control): labelled / labelled walk",
         f"{fmt_spread(spread(x['bandai_control']['labelled'] for x in cross), 3)} / "
         f"{fmt_spread(spread(x['bandai_control']['labelled_walk'] for x in cross), 3)}"],
        [f"style of the {t['test_walk_takes']} test walk takes from the walk tensor (one class, "
         f"{len(t['styles'])} styles; repetitions = {t['chosen_repetitions'].replace('None', 'all')}) / "
         "StyleClassifier", f"{fmt_spread(tensor_acc, 3)} / {fmt_spread(clf_acc, 3)}"],
        ["style of the walk segments the annotation finds in the test documents", fmt_spread(seg, 3)],
    ]
    headline = (md_table(["Bandai test takes (annotation: " + chosen_text + ", chosen on val takes)",
                          f"mean ± sd over {seeds} seeds"], rows)
                + f"\n\nTest documents per seed: {fmt(n_test_docs.get('mean'), 0)}{sub}. {prov}")

    # choice: the best val candidates, the old default and the choice
    cands = sorted(r["candidates"], key=lambda x: -x["objective"])
    show = cands[:8]
    names = ("tau", "keyframes", "min_run", "sub_frames", "turning_z", "turning_window_s")

    def same(x: dict[str, Any], y: dict[str, Any]) -> bool:
        return all(x[k] == y[k] for k in names)

    whole = max((x for x in cands if x["sub_frames"] == 0 and x["turning_z"] == 0), key=lambda x: x["objective"])
    for want in (r["old_default"], whole, {**c, "turning_z": 0.0, "turning_window_s": 0.0},
                 {**c, "keyframes": None if c["keyframes"] is not None else 0.1, "sub_frames": 0},
                 {**c, "min_run": 0}):
        match = [x for x in cands if same(x, want)]
        if match and match[0] not in show:
            show.append(match[0])
    choice_rows = []
    for x in show:
        mark = " **(chosen)**" if same(x, c) else (" (old default)" if same(x, r["old_default"]) else "")
        choice_rows.append([f"{x['tau']:g}", "off" if x["keyframes"] is None else f"{x['keyframes']:g}",
                            str(x["min_run"]), "whole" if not x["sub_frames"] else str(x["sub_frames"]),
                            _turning(x["turning_z"], x["turning_window_s"]) + mark,
                            fmt(x["objective"], 3), fmt(x["objective_takes"], 3), fmt(x["objective_cuts"], 3),
                            *[fmt_spread(x[k], 3) for k in SCORES]])
    choice = (md_table(["τ", "key-frame tolerance", "min_run", "sub-templates", "turning layer", "objective",
                        "on whole takes",
                        "on cuts", *[f"{k} (whole takes)" for k in SCORES]], choice_rows)
              + f"\n\n{len(r['candidates'])} candidates (τ × key frames × min_run × sub-template frames × turning "
              f"layer; key frames with whole templates only); the {min(8, len(cands))} best by objective (the mean of "
              "(F1 + F2) / 2 on "
              "val documents of whole takes and on val documents of 2–3 s cuts; among equals the first of: turning "
              "layer off before on, whole templates before windows, key frames off before on, smaller τ, smaller "
              "min_run), then the old default, the best of the templates alone, the choice without the turning "
              "layer, with the key frames switched and without min_run. Val "
              f"documents per seed: {fmt(spread(d['documents'] for d in r['documents']['val']).get('mean'), 0)} "
              f"({fmt(spread(d['frames'] for d in r['documents']['val']).get('mean'), 0)} frames){sub}. {prov}")

    table32 = md_table(["setting", *SCORES, "unlabelled", "other class", "blend frames labelled"],
                       [[f"{name}: {row['setting']}", *[fmt_spread(row[k], 3) for k in SCORES],
                         fmt_spread(row["unlabelled"], 3), fmt_spread(row["confused"], 3),
                         fmt_spread(row["spurious_frames"], 0)] for name, row in r["test"].items()])
    table32 += "\n\nThe same settings on documents of 2–3 s cuts of the test takes:\n\n" + md_table(
        ["setting", *SCORES, "unlabelled", "other class"],
        [[f"{name}: {row['setting']}", *[fmt_spread(row[k], 3) for k in SCORES], fmt_spread(row["unlabelled"], 3),
          fmt_spread(row["confused"], 3)] for name, row in r["test_cuts"].items()])
    table32 += (f"\n\nTest documents per seed: {fmt(n_test_docs.get('mean'), 0)} "
                f"({fmt(spread(d['frames'] for d in r['documents']['test']).get('mean'), 0)} frames, "
                f"{fmt(spread(d['takes'] for d in r['documents']['test']).get('mean'), 0)} takes){sub}; {easier}. "
                f"Per test take at the choice: median recall "
                f"{fmt_spread(spread(x['recall_median'] for x in failures), 3)}, "
                f"5th percentile {fmt_spread(spread(x['recall_p5'] for x in failures), 3)}. {prov}")

    per_class = md_table(["class", "template frames", "R1", "P1", "unlabelled"],
                         [[name, str(r["templates"].get(name, "—")), fmt_spread(e["R1"], 3), fmt_spread(e["P1"], 3),
                           fmt_spread(e["unlabelled"], 3)] for name, e in r["per_class"].items()]) + f"\n\n{prov}"

    x0 = cross[0]
    other = md_table(["seed", "order", "frames (walk)", "whole templates: labelled / walk", "labelled",
                      "labelled walk", "labels given (frames)", "Bandai control: labelled / walk"],
                     [[str(s), " + ".join(x["order"]), f"{x['frames']} ({x['walk_frames']})",
                       f"{fmt(x['whole_templates']['labelled'], 3)} / {fmt(x['whole_templates']['labelled_walk'], 3)}",
                       fmt(x["labelled"], 3),
                       fmt(x["labelled_walk"], 3), ", ".join(f"{k} {v}" for k, v in x["labels"].items()) or "none",
                       f"{fmt(x['bandai_control']['labelled'], 3)} / {fmt(x['bandai_control']['labelled_walk'], 3)}"]
                      for s, x in zip(record.get("seeds", []), cross)])
    other += (f"\n\nFrames per file at 30 fps: {', '.join(f'{k} {v}' for k, v in x0['files_frames'].items())}; "
              f"the walk template has {x0['walk_template_frames']} frames (a match of the whole template needs at "
              f"least half of them; the choice: {chosen_text}). "
              f"{prov}")

    tensor_choice = md_table(["repetitions per style", "val accuracy"],
                             [[("all every style has" if k == "None" else k)
                               + (" **(chosen)**" if k == t["chosen_repetitions"] else ""),
                               fmt_spread(v, 3)] for k, v in t["val_accuracy"].items()])
    tensor_choice += (f"\n\n{t['val_walk_takes']} val walk takes; the highest mean accuracy wins, among equals the "
                      "most "
                      f"repetitions. {prov}")
    reps = spread(x["repetitions"] for x in t["test"])
    tensor_test = md_table(["method", f"right of {t['test_walk_takes']} test walk takes", "accuracy"], [
        ["chance / majority style", "—", f"{fmt(t['chance'], 3)} / {fmt(t['majority'], 3)}"],
        ["evaluation's StyleClassifier (train walk takes)", _counts(t["classifier_test"], "right", "takes"),
         fmt_spread(clf_acc, 3)],
        [f"walk tensor, {fmt(reps.get('mean'), 0)} repetitions per style (eq. 3.6)",
         _counts(t["test"], "right", "takes"),
         fmt_spread(tensor_acc, 3)],
        ["walk tensor on the walk segments found in the test documents (style of the take overlapped most)",
         f"{fmt_spread(spread(x['right'] for x in t['document_walk_segments']), 1)} of "
         f"{fmt_spread(spread(x['segments'] for x in t['document_walk_segments']), 1)}", fmt_spread(seg, 3)]])
    tensor_test += (f"\n\nOne class (walk), {len(t['styles'])} styles; test takes per style: "
                    f"{', '.join(f'{k} {v}' for k, v in t['test_per_style'].items())}. {prov}")

    tr = r["tensor"]["truncation"]
    trunc_rows = []
    for i, row in enumerate(tr[0]["rows"]):
        trunc_rows.append([str(tuple(row["ranks"])), fmt_spread(spread(x["rows"][i]["kib"] for x in tr), 0),
                           fmt_spread(spread(x["rows"][i]["error_cm"] for x in tr), 3),
                           fmt_spread(spread(x["rows"][i]["error_deg"] for x in tr), 2)])
    truncation = (md_table(["ranks (DOF, frames, style, repetition)", "KiB", "error cm", "error deg"], trunc_rows)
                  + f"\n\nΘ {' × '.join(map(str, tr[0]['shape']))} (seed {record['seeds'][0]}), "
                    f"{fmt(tr[0]['theta_kib'], 0)} KiB. {prov}")

    tm = r["timing"]
    load = record.get("load_average_start") or ["?"]
    per_hour = spread((x["features_s"] + x["distances_s"]) * 108000 / x["frames"] for x in tm)
    timing = (f"Relational features and subsequence DTW of the 10 templates (no key frames): "
              f"{fmt_spread(per_hour, 1)} s per hour of motion, measured inside the run with load average "
              f"{load[0]} at its start on {record.get('machine', {}).get('cores', '?')} cores (a loaded figure, not "
              f"a speed claim). {prov}")
    return {"headline": headline, "choice": choice, "table32": table32, "per_class": per_class,
            "other_captures": other, "tensor_choice": tensor_choice, "tensor_test": tensor_test,
            "truncation": truncation, "timing": timing}
