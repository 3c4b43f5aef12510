"""Suite ``multilinear``: Krüger §4.1 on Bandai: class tensors ``(66 DOF, f frames, actors, styles, repetitions)``
of walks and runs, the tensor-vs-PCA reconstruction of held-out takes (Tables 4.1–4.3 / Figs. 4.6–4.7 in form),
the physics-based multiscale DTW against the plain pose DTW, and synthesized style blends with their root path.

Per seed and class: Bandai's takes of the class are split by take (``TakeSet.split(seed, 0.15, 0.15)``, grouped
by content and style); the first ``--repetitions`` train takes of each style fill the tensor (the actor mode has one
entry per actor group only where every actor performed every style; in Bandai each of the three actors performed
other styles, so actor and style coincide and the actor mode has one entry, docs/data.md), val
takes choose the natural ranks, test takes report. Errors are mean joint distances in the root-local frame (cm;
the thesis' eq. 4.6 measured quaternion angles) and the mean distance of the integrated root track (cm), of a
held-out take warped onto the model's timeline against its reconstruction:

* **natural weights** ``k_a + k_s + k_r`` coefficients (eq. 3.5 fitted by least squares): ``(k_s, k_r)`` chosen
  on val among the splits of each budget, against PCA of the training motions with as many components;
* **natural subspace** (``k_s · k_r`` Tucker coefficients, ``(k_s, k_r)`` chosen on val) against PCA;
* **technical modes** (Figs. 4.6/4.7): the DOF mode truncated to ``k`` (``k`` coefficients per frame) against PCA
  of the training poses with ``k`` components;
* **truncation table** (Tables 4.1–4.3): seed 0's training tensor reconstructed in-sample with each mode cut.

Warping: both methods build the same split's tensor; compared by the foot-contact agreement of every warped
training take with the reference (share of frame × foot states equal), the held-out error at the val-chosen
natural-weight budget of 10, and the DTW cost cells evaluated. Synthesis: each style's mean motion and the 50/50
blend of ``normal`` with each other style, from the physics-warped model: walked distance (does the blend land
between its parents?) and foot skating (``synthesis.quality.skating``) beside the real takes'.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, fmt_spread, md_table, provenance_line, spread, take_split_record

DESCRIPTION = ("Krüger §4.1 multilinear model on Bandai walks and runs: held-out reconstruction, tensor vs PCA at "
               "matched coefficients (ranks chosen on val), physics multiscale DTW vs pose DTW, style blends")
DEFAULT_SEEDS = (0, 1, 2)
VAL_FRACTION = TEST_FRACTION = 0.15
BUDGETS = (3, 4, 6, 8, 10, 13, 16)
SUBSPACES = (2, 4, 8, 16, 32)
TECHNICAL = (1, 2, 3, 5, 10, 20)
HEADLINE_BUDGET = 10


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--contents", nargs="+", default=["walk", "run"], help="motion classes")
    parser.add_argument("--repetitions", type=int, default=8, help="train takes per style in the tensor")


def _errors(fitted: np.ndarray, x: np.ndarray, fps: float) -> tuple[float, float]:
    from stylemotion.multilinear.compare import path_error, pose_error

    return pose_error(fitted, x) * 100, path_error(fitted, x, fps) * 100


def _natural(model, k_s: int, k_r: int):
    return model.truncated((model.ranks[0], model.ranks[1], 1, k_s, k_r))


def _held_out(model, pca, val: list[np.ndarray], test: list[np.ndarray], fps: float) -> dict[str, Any]:
    from stylemotion.multilinear.compare import fit_natural_weights, pose_error, project_natural, project_technical

    def val_error(make) -> float:
        return float(np.mean([pose_error(make(x), x) for x in val])) * 100

    def test_error(make) -> list[float]:
        return np.mean([_errors(make(x), x, fps) for x in test], axis=0).tolist()

    natural = {(s, r): _natural(model, s, r) for s in range(1, model.ranks[3] + 1)
               for r in range(1, model.ranks[4] + 1)}
    out: dict[str, Any] = {"weights": [], "subspace": [], "technical": []}
    for budget in BUDGETS:
        pairs = [p for p in natural if 1 + sum(p) == budget]
        if not pairs or budget - 1 > pca["motions"].max_components:
            continue
        scores = {p: val_error(lambda x, m=natural[p]: fit_natural_weights(m, x)[0]) for p in pairs}
        best = min(scores, key=scores.get)
        out["weights"].append({
            "budget": budget, "chosen": list(best), "val_cm": scores[best],
            "tensor": test_error(lambda x, m=natural[best]: fit_natural_weights(m, x)[0]),
            "pca": test_error(lambda x, k=budget: _pca_motion(pca, x, k))})
    for size in SUBSPACES:
        pairs = [p for p in natural if p[0] * p[1] == size]
        if not pairs or size > pca["motions"].max_components:
            continue
        scores = {p: val_error(lambda x, m=natural[p]: project_natural(m, x)) for p in pairs}
        best = min(scores, key=scores.get)
        out["subspace"].append({
            "coefficients": size, "chosen": list(best), "val_cm": scores[best],
            "tensor": test_error(lambda x, m=natural[best]: project_natural(m, x)),
            "pca": test_error(lambda x, k=size: _pca_motion(pca, x, k))})
    for k in TECHNICAL:
        small = model.truncated((k, *model.ranks[1:]))
        out["technical"].append({
            "k": k, "tensor": test_error(lambda x, m=small: project_technical(m, x)),
            "pca": test_error(lambda x, k=k: pca["poses"].reconstruct(x, k))})
    return out


def _pca_motion(pca, x: np.ndarray, k: int) -> np.ndarray:
    return pca["motions"].reconstruct(x.T.reshape(1, -1), k).reshape(x.shape[1], -1).T


def _truncation_table(model, theta: np.ndarray) -> list[dict[str, Any]]:
    from stylemotion.multilinear.compare import path_error, pose_error
    from stylemotion.multilinear.decomposition import model_entries, reconstruct

    full = model.ranks
    rows = []
    cuts = ([("none", full)]
            + [("DOF", (k, *full[1:])) for k in (40, 20, 10, 5, 3, 1)]
            + [("frame", (full[0], k, *full[2:])) for k in (60, 30, 20, 10, 5)]
            + [("DOF and frame", (20, 20, *full[2:])), ("DOF and frame", (10, 10, *full[2:]))]
            + [("style", (*full[:3], k, full[4])) for k in range(full[3] - 1, 0, -2)]
            + [("repetition", (*full[:4], k)) for k in range(full[4] - 1, 0, -2)])
    size = theta.size
    for mode, ranks in cuts:
        ranks = tuple(min(r, f) for r, f in zip(ranks, full))
        small = model.truncated(ranks)
        rec = reconstruct(small.core, small.factors)
        e = [(pose_error(rec[:, :, 0, s, r].T, theta[:, :, 0, s, r].T) * 100,
              path_error(rec[:, :, 0, s, r].T, theta[:, :, 0, s, r].T, model.fps) * 100)
             for s in range(theta.shape[3]) for r in range(theta.shape[4])]
        rows.append({"mode": mode, "core": list(ranks), "entries": int(np.prod(ranks)),
                     "core_percent": 100 * float(np.prod(ranks)) / size,
                     "memory_percent": 100 * model_entries(ranks, model.dims) / size,
                     "pose_cm": float(np.mean([a for a, _ in e])), "path_cm": float(np.mean([b for _, b in e]))})
    return rows


def _contact_agreement(model, theta: np.ndarray) -> float:
    from stylemotion.primitives.contacts import foot_contacts
    from stylemotion.representation import frames_to_positions

    ref = foot_contacts(model.reference, model.fps)
    agree = [float((foot_contacts(frames_to_positions(theta[:, :, 0, s, r].T, model.fps), model.fps) == ref).mean())
             for s in range(theta.shape[3]) for r in range(theta.shape[4])]
    return float(np.mean(agree))


def _synthesis(model, real: list[np.ndarray]) -> dict[str, Any]:
    from stylemotion.synthesis.quality import skating

    def figures(p: np.ndarray) -> tuple[float, float]:
        return float(np.linalg.norm(p[-1, 0, [0, 2]] - p[0, 0, [0, 2]])), skating(p, model.fps)[0]

    parents = {s: figures(model.synthesize(style={s: 1.0})) for s in model.styles}
    blends = []
    for s in model.styles:
        if s == "normal":
            continue
        d, sk = figures(model.synthesize(style={"normal": 0.5, s: 0.5}))
        lo, hi = sorted([parents["normal"][0], parents[s][0]])
        blends.append({"style": s, "distance_m": d, "between": bool(lo <= d <= hi), "skating": sk})
    return {"parents": {s: {"distance_m": v[0], "skating": v[1]} for s, v in parents.items()}, "blends": blends,
            "real_skating": float(np.mean([skating(p, model.fps)[0] for p in real]))}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.datasets.actors import actor_groups
    from stylemotion.datasets.registry import load_dataset
    from stylemotion.multilinear.compare import PCA
    from stylemotion.multilinear.model import build_model

    data = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"), contents=args.contents)
    fps = 30.0
    results: dict[str, Any] = {"classes": {}, "repetitions": args.repetitions}
    splits = {}
    for content in args.contents:
        takes = [t for t in data.takes if t.content == content]
        groups = actor_groups(takes)
        crossed = len({tuple(styles) for styles in groups.styles.values()}) == 1  # every actor in every style
        per_seed = []
        for seed in seeds:
            whole = data.split(seed, VAL_FRACTION, TEST_FRACTION)
            part = {k: [t for t in v if t.content == content] for k, v in whole.items()}
            splits[f"{content}/{seed}"] = take_split_record(part, seed, VAL_FRACTION, TEST_FRACTION)
            examples = {}
            for t in part["train"]:
                actor = str(groups.takes[t.name]) if crossed else "all"
                examples.setdefault((actor, t.style), []).append(t.positions)
            entry: dict[str, Any] = {"seed": seed}
            for method in ("physics", "pose"):
                model, theta, stats = build_model(content, examples, fps, args.repetitions, method)
                val = [model.warp(t.positions) for t in part["val"]]
                test = [model.warp(t.positions) for t in part["test"]]
                rows = theta.reshape(theta.shape[0] * theta.shape[1], -1).T
                pca = {"motions": PCA(rows), "poses": PCA(np.moveaxis(theta, 0, -1).reshape(-1, theta.shape[0]))}
                held = _held_out(model, pca, val, test, fps)
                headline = next(w for w in held["weights"] if w["budget"] == HEADLINE_BUDGET)["tensor"]
                entry[method] = {"shape": list(theta.shape), "cells_per_take": float(stats.cells.mean()),
                                 "contact_agreement": _contact_agreement(model, theta),
                                 "budget_test_cm": headline, **held}
                if method == "physics":
                    entry["synthesis"] = _synthesis(model, [t.positions for t in part["test"]])
                    if seed == seeds[0]:
                        results["classes"].setdefault(content, {})["truncation"] = _truncation_table(model, theta)
            per_seed.append(entry)
            print(f"{content} seed {seed}: physics {entry['physics']['budget_test_cm']}, "
                  f"pose {entry['pose']['budget_test_cm']}", flush=True)
        results["classes"].setdefault(content, {}).update(
            {"actor_groups": len(groups.styles), "actor_mode": "actors" if crossed else "one entry: actors and styles "
             "do not cross", "takes": len(takes), "seeds": per_seed})
    results["splits"] = {"kind": "by take, per class and seed (grouped by style): train fills the tensor, val "
                                 "chooses the natural ranks, test reports", "parts": splits}
    return results


# -- render -------------------------------------------------------------------------------------------------


def _cell(values: list[float]) -> str:
    s = spread(values)
    return f"{fmt_spread(s)} (max {fmt(s.get('max'))})"


def _rows(seeds: list[dict[str, Any]], family: str, key: str) -> dict[Any, list[dict[str, Any]]]:
    out: dict[Any, list[dict[str, Any]]] = {}
    for entry in seeds:
        for row in entry["physics"][family]:
            out.setdefault(row[key], []).append(row)
    return out


def _comparison(r: dict[str, Any], family: str, key: str, label: str) -> str:
    parts = []
    for content, c in r["classes"].items():
        rows = []
        for value, per_seed in _rows(c["seeds"], family, key).items():
            chosen = ", ".join(sorted({"×".join(map(str, x["chosen"])) for x in per_seed})) if "chosen" in per_seed[0] \
                else "—"
            wins = sum(x["tensor"][0] < x["pca"][0] for x in per_seed)
            rows.append([content, str(value), chosen, _cell([x["tensor"][0] for x in per_seed]),
                         _cell([x["pca"][0] for x in per_seed]), _cell([x["tensor"][1] for x in per_seed]),
                         _cell([x["pca"][1] for x in per_seed]), f"{wins}/{len(per_seed)}"])
        parts.extend(rows)
    return md_table(["class", label, "k_s×k_r (val)", "tensor pose cm", "PCA pose cm", "tensor root cm",
                     "PCA root cm", "seeds tensor < PCA"], parts)


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    prov = provenance_line(record)
    warping_rows, synth_rows, trunc_parts, head = [], [], [], []
    for content, c in r["classes"].items():
        for method in ("physics", "pose"):
            es = [e[method] for e in c["seeds"]]
            warping_rows.append([content, "multiscale DTW, physics features" if method == "physics"
                                 else "plain DTW, joint coordinates",
                                 _cell([e["contact_agreement"] * 100 for e in es]),
                                 _cell([e["budget_test_cm"][0] for e in es]),
                                 _cell([e["budget_test_cm"][1] for e in es]),
                                 fmt(float(np.mean([e["cells_per_take"] for e in es])), 0)])
        blends = [b for e in c["seeds"] for b in e["synthesis"]["blends"]]
        synth_rows.append([content, f"{sum(b['between'] for b in blends)}/{len(blends)}",
                           _cell([b["skating"] for b in blends]),
                           _cell([v["skating"] for e in c["seeds"] for v in e["synthesis"]["parents"].values()]),
                           _cell([e["synthesis"]["real_skating"] for e in c["seeds"]])])
        trunc = c["truncation"]
        trunc_parts.append(f"**{content}** (tensor {' × '.join(map(str, c['seeds'][0]['physics']['shape']))}, "
                           f"seed {c['seeds'][0]['seed']}'s training takes)\n\n" + md_table(
            ["truncated", "core", "entries", "core %", "memory %", "E pose cm", "E root cm"],
            [[t["mode"], " × ".join(map(str, t["core"])), f"{t['entries']:,}", fmt(t["core_percent"], 3),
              fmt(t["memory_percent"], 1), fmt(t["pose_cm"], 3), fmt(t["path_cm"], 2)] for t in trunc]))
        w = {row["budget"]: row for e in c["seeds"] for row in e["physics"]["weights"]
             if row["budget"] == HEADLINE_BUDGET}
        per = [row for e in c["seeds"] for row in e["physics"]["weights"] if row["budget"] == HEADLINE_BUDGET]
        if w:
            head.append(f"{content}: tensor {fmt_spread(spread([x['tensor'][0] for x in per]))} cm vs PCA "
                        f"{fmt_spread(spread([x['pca'][0] for x in per]))} cm")
    n = len(next(iter(r["classes"].values()))["seeds"])
    headline = (f"Held-out Bandai takes from {HEADLINE_BUDGET} coefficients (natural weights, ranks chosen on val; "
                f"mean joint error, {n} seeds): " + "; ".join(head) + f". {prov}")
    return {
        "headline": headline,
        "weights": _comparison(r, "weights", "budget", "coefficients (1 + k_s + k_r)") + f"\n\n{prov}",
        "subspace": _comparison(r, "subspace", "coefficients", "coefficients (k_s · k_r)") + f"\n\n{prov}",
        "technical": _comparison(r, "technical", "k", "k per frame") + f"\n\n{prov}",
        "warping": md_table(["class", "warping", "foot contacts agreeing with the reference %",
                             f"held-out pose cm ({HEADLINE_BUDGET} coeff.)", "held-out root cm",
                             "DTW cells per take"], warping_rows) + f"\n\n{prov}",
        "truncation": "\n\n".join(trunc_parts) + f"\n\n{prov}",
        "synthesis": md_table(["class", "50/50 blends with normal whose walked distance lies between the parents'",
                               "blend skating", "style means' skating", "real test takes' skating"],
                              synth_rows) + f"\n\n{prov}",
    }
