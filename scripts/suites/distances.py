"""Suite ``distances``: the thesis' comparison of frame distance measures and feature sets (Krüger §2.3, Figs. 2.3–2.7).

Per seed, random query frames of the Bandai ``test`` takes; for each, the distance under every measure of
:mod:`stylemotion.search.distances` (quaternion, Euler, weighted body-part, point-cloud, pose/velocity/acceleration)
and every feature set of :mod:`stylemotion.search.features` to every frame of the ``test`` takes outside the
query's own take — the same pairs for all. Reported:

1. the asymmetric Spearman matrix of the thesis' Fig. 2.3/2.5: the ``k`` (512, the thesis') nearest frames under
   the row's measure, ρ between their distances under the row's and the column's measure, mean over queries, then
   mean ± sd over seeds; and a heatmap of it;
2. Fig. 2.7's form: ρ of ``E15``'s neighbours with every other measure against the number of neighbours;
3. precision@10 by content label per measure (the 10 nearest frames of other takes sharing the query's content);
4. Fig. 2.4's form: clips (the middle 2 s of 8 random test takes per content), DTW distances between every two
   under every measure, ρ over each clip's 8 nearest clips, and precision@8 by content.

No setting is tuned: the point-cloud windows (1 and 11 frames at 30 fps), the Lee et al. weights and the Wang &
Bodenheimer joints and ``k`` are the thesis'; the PCAs (``pca*``, ``F_pva20``) are fitted on the ``train`` takes.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, fmt_spread, md_table, provenance_line, spread, take_split_record

DESCRIPTION = ("frame distance measures (quaternion, Euler, body-part, point cloud, pose/velocity/acceleration) "
               "against the feature sets: Spearman rank correlations on Bandai test takes (Krüger §2.3)")
DEFAULT_SEEDS = (0, 1, 2)
REPO = Path(__file__).resolve().parents[2]
FIGURE = Path("benchmarks") / "figures" / "distances.png"
#: The thesis' ρ of E15 with D_pc1 over 512 nearest neighbours (§2.3.3, "Root normalizations": 3D normalization).
THESIS_E15_PC1 = "0.55"
FEATURE_SETS = ("E15", "E30", "E39", "E15x3", "E15x5", "E30x3", "E39x3", "pca8", "pca16", "pca25", "EP17", "EP19")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--queries", type=int, default=256, help="query frames per seed")
    parser.add_argument("--k", type=int, default=512, help="nearest frames per query of the matrix (thesis: 512)")
    parser.add_argument("--ks", type=int, nargs="+", default=[8, 32, 128, 512, 2048, 8192],
                        help="numbers of neighbours of the Fig. 2.7 curves (E15's neighbours)")
    parser.add_argument("--chunk", type=int, default=8, help="queries per block of distances (memory)")
    parser.add_argument("--clips-per-content", type=int, default=8,
                        help="test takes per content whose clips the DTW comparison (Fig. 2.4) uses (thesis: ≥ 8)")
    parser.add_argument("--clip-s", type=float, default=2.0, help="clip length, s (the middle of each take)")
    parser.add_argument("--clip-k", type=int, default=8, help="nearest clips per clip (thesis: 8)")
    parser.add_argument("--clip-stride", type=int, default=3,
                        help="align every n-th frame of a clip (3: 10 fps; the measures see every frame)")
    parser.add_argument("--figure", type=Path, default=FIGURE, help="heatmap PNG, relative to the repository")


def _split(bandai: Any) -> tuple[dict[str, list], dict[str, Any]]:
    from omegaconf import OmegaConf

    import stylemotion

    cfg = OmegaConf.load(Path(stylemotion.__file__).parent / "configs" / "data" / "bandai.yaml")
    settings = {"seed": int(cfg.split.seed), "val_fraction": float(cfg.split.val_fraction),
                "test_fraction": float(cfg.split.test_fraction)}
    return bandai.split(**settings), settings


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.datasets import load_dataset
    from stylemotion.search.distances import (
        BODY_PART_WEIGHTS,
        POINT_CLOUD_WINDOWS_30FPS,
        FrameMeasures,
        fit_pva,
        nearest_label_precision,
        neighbour_correlations,
    )
    from stylemotion.search.features import fit_features

    bandai = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"), workers=2)
    split, settings = _split(bandai)
    train = [np.asarray(t.positions) for t in split["train"]]
    fitted = {name: fit_features(name, train, bandai.fps) for name in FEATURE_SETS if name.startswith("pca")}
    fitted["F_pva20"] = fit_pva(train, bandai.fps)
    test = split["test"]
    measures = FrameMeasures([np.asarray(t.positions) for t in test], bandai.fps, FEATURE_SETS, fitted)
    names = measures.names
    contents = np.array([t.content for t in test])[measures.take_id]
    ks = sorted({k for k in args.ks if k < measures.num_frames} | {args.k})

    per_seed: list[dict[str, Any]] = []
    for seed in seeds:
        rng = np.random.default_rng([seed, 28])
        queries = np.sort(rng.choice(measures.num_frames, size=min(args.queries, measures.num_frames), replace=False))
        rho: dict[str, dict[str, list]] = {a: {b: [] for b in names} for a in names}
        curve: dict[int, dict[str, list]] = {k: {b: [] for b in names} for k in ks}
        prec: dict[str, list] = {n: [] for n in names}
        for lo in range(0, len(queries), args.chunk):
            rows = queries[lo:lo + args.chunk]
            dist = {n: measures.distances(n, rows) for n in names}
            excluded = measures.take_id[rows][:, None] == measures.take_id[None, :]
            corr = neighbour_correlations(dist, excluded, [args.k])
            for a in names:
                for b in names:
                    rho[a][b].extend(corr[a][args.k][b].tolist())
            e15 = neighbour_correlations(dist, excluded, ks, rows=["E15"])["E15"]
            for k in ks:
                for b in names:
                    curve[k][b].extend(e15[k][b].tolist())
            for n in names:
                prec[n].extend(nearest_label_precision(dist[n], excluded, contents, contents[rows]).tolist())
        clips = _clip_comparison(test, bandai.fps, seed, args, fitted)
        per_seed.append({"clips": clips,
                         "rho": {a: {b: float(np.nanmean(v)) for b, v in r.items()} for a, r in rho.items()},
                         "curve": {k: {b: float(np.nanmean(v)) for b, v in c.items()} for k, c in curve.items()},
                         "precision": {n: float(np.mean(v)) for n, v in prec.items()},
                         "nan_rho": int(sum(np.isnan(np.asarray(v)).sum() for r in rho.values() for v in r.values()))})

    result = {
        "splits": {"choose": "nothing tuned: point-cloud windows, body-part weights and k are the thesis'; PCAs "
                             "(pca8/16/25, F_pva20) fitted on the train takes",
                   "report": "query frames and candidate frames both from the test takes; a query's own take is "
                             "never its neighbour",
                   "parameters": {
                       "point_cloud_windows_frames_at_30fps": list(POINT_CLOUD_WINDOWS_30FPS),
                       "point_cloud_windows_frames": dict(measures.windows),
                       "point_cloud_weights": "equal per point (no taper)",
                       "body_part_weights": {k: [n for n, w in zip(_joint_names(), v) if w] for k, v in
                                             BODY_PART_WEIGHTS.items()},
                       "wb_weights": "equal on the joints the thesis names (it gives no values)",
                       "k": args.k, "k_source": "thesis Fig. 2.3 caption (512 nearest neighbours)",
                       "rotations": "project IK (positions_to_motion) of the canonical positions; root yaw removed",
                       "normalization": "3d (the thesis' default for its feature sets)"},
                   **take_split_record(split, **settings)},
        "measures": names, "queries_per_seed": int(min(args.queries, measures.num_frames)),
        "candidate_frames": measures.num_frames, "test_takes": len(test), "k": args.k, "ks": ks,
        "rho": {a: {b: spread(s["rho"][a][b] for s in per_seed) for b in names} for a in names},
        "curve": {str(k): {b: spread(s["curve"][k][b] for s in per_seed) for b in names} for k in ks},
        "precision_at_10": {n: spread(s["precision"][n] for s in per_seed) for n in names},
        "nan_rho_per_seed": [s["nan_rho"] for s in per_seed],
        "clips": {"per_content": args.clips_per_content, "seconds": args.clip_s, "k": args.clip_k,
                  "stride": args.clip_stride,
                  "count_per_seed": [s["clips"]["count"] for s in per_seed],
                  "rho": {a: {b: spread(s["clips"]["rho"][a][b] for s in per_seed) for b in names} for a in names},
                  "precision": {n: spread(s["clips"]["precision"][n] for s in per_seed) for n in names}},
    }
    result["figure"] = str(args.figure)
    _plot(result, REPO / args.figure)
    return result


def _clip_comparison(test: list[Any], fps: float, seed: int, args: argparse.Namespace,
                     fitted: dict[str, Any]) -> dict[str, Any]:
    """Fig. 2.4's form: the middle ``clip_s`` of ``clips_per_content`` random test takes per content (takes at least
    that long); DTW distances between every two clips under every measure; per clip its ``clip_k`` nearest other
    clips under the row's measure and ρ with the column's; precision@k by content."""
    from stylemotion.search.distances import (
        FrameMeasures,
        clip_distances,
        nearest_label_precision,
        neighbour_correlations,
    )

    frames = int(round(args.clip_s * fps))
    rng = np.random.default_rng([seed, 2, 4])
    chosen = []
    for content in sorted({t.content for t in test}):
        usable = [t for t in test if t.content == content and t.num_frames >= frames]
        picks = rng.choice(len(usable), size=min(args.clips_per_content, len(usable)), replace=False)
        chosen += [usable[i] for i in sorted(picks)]
    clips = [np.asarray(t.positions[(t.num_frames - frames) // 2:][:frames]) for t in chosen]
    measures = FrameMeasures(clips, fps, FEATURE_SETS, fitted)
    dist = clip_distances(measures, frames, args.clip_stride)
    contents = np.array([t.content for t in chosen])
    own = np.eye(len(clips), dtype=bool)
    corr = neighbour_correlations(dist, own, [args.clip_k])
    names = measures.names
    return {"count": len(clips),
            "rho": {a: {b: float(np.nanmean(corr[a][args.clip_k][b])) for b in names} for a in names},
            "precision": {n: float(np.mean(nearest_label_precision(dist[n], own, contents, contents, args.clip_k)))
                          for n in names}}


def _joint_names() -> tuple[str, ...]:
    from stylemotion.search.distances import rotation_joint_names

    return rotation_joint_names()


def _heatmap(ax: Any, fig: Any, matrix: np.ndarray, names: list[str], title: str) -> None:
    image = ax.imshow(matrix, vmin=-0.2, vmax=1.0, cmap="viridis")
    for i in range(len(names)):
        for j in range(len(names)):
            ax.text(j, i, f"{matrix[i, j]:.2f}", ha="center", va="center", fontsize=5.5,
                    color="black" if matrix[i, j] > 0.6 else "white")
    ax.set_xticks(range(len(names)), names, rotation=90, fontsize=7)
    ax.set_yticks(range(len(names)), names, fontsize=7)
    ax.set_xlabel("distance measure (ranks compared)", fontsize=8)
    ax.set_ylabel("measure choosing the nearest", fontsize=8)
    ax.set_title(title, fontsize=9)
    fig.colorbar(image, ax=ax, fraction=0.04, pad=0.02)


def _plot(result: dict[str, Any], path: Path) -> None:
    """Three panels: the frame matrix (Fig. 2.3), the clip matrix (Fig. 2.4), ρ with E15 against k (Fig. 2.7)."""
    from matplotlib import colormaps
    from matplotlib.figure import Figure

    names = result["measures"]
    fig = Figure(figsize=(22, 7))
    ax, ax_clips, ax2 = fig.subplots(1, 3, gridspec_kw={"width_ratios": [1.2, 1.2, 1]})
    for axis, rho, title in (
            (ax, result["rho"], f"frames: ρ over the {result['k']} nearest (Bandai test takes, mean of seeds)"),
            (ax_clips, result["clips"]["rho"], f"clips (DTW): ρ over the {result['clips']['k']} nearest")):
        matrix = np.array([[rho[a][b].get("mean", np.nan) for b in names] for a in names])
        _heatmap(axis, fig, matrix, names, title)
    ks = [int(k) for k in result["curve"]]
    colours = colormaps["tab20"].colors
    for i, b in enumerate(n for n in names if n != "E15"):
        ax2.plot(ks, [result["curve"][str(k)][b].get("mean", np.nan) for k in ks], marker="o", ms=3, label=b,
                 color=colours[i % len(colours)], ls="-" if b.startswith(("D_", "F_")) else "--")
    ax2.set_xscale("log", base=2)
    ax2.set_xlabel("nearest frames under E15", fontsize=8)
    ax2.set_ylabel("Spearman ρ with E15", fontsize=8)
    ax2.set_title("Fig. 2.7's form: ρ against the number of neighbours\n(solid: §2.3.1 measures, dashed: feature sets)",
                  fontsize=9)
    ax2.legend(fontsize=6, ncol=2)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.stem}.tmp{path.suffix}")
    fig.savefig(tmp, dpi=90, metadata={"Software": None})
    tmp.replace(path)


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    prov = provenance_line(record)
    names = r["measures"]
    rows = [[a, *(fmt(r["rho"][a][b].get("mean"), 2) for b in names)] for a in names]
    matrix = (md_table(["A \\ B", *names], rows)
              + f"\n\nMean Spearman ρ over seeds: for each of {r['queries_per_seed']} random query frames per seed, "
                f"its {r['k']} nearest frames under A (row) among the {r['candidate_frames']:,} frames of the "
                f"{r['test_takes']} test takes (its own take excluded); ρ between their distances under A and "
                f"under B (column). Largest sd over seeds: "
                f"{max(r['rho'][a][b].get('sd', 0.0) for a in names for b in names):.3f}. {prov}")
    ks = r["ks"]
    curve_rows = [[b, *(fmt_spread(r["curve"][str(k)][b]) for k in ks)] for b in names if b != "E15"]
    curve = (md_table(["B \\ k", *map(str, ks)], curve_rows)
             + f"\n\nρ between E15 and B over E15's k nearest frames (Fig. 2.7's form), mean ± sd over seeds. {prov}")
    prec_rows = [[n, fmt_spread(r["precision_at_10"][n])] for n in names]
    precision = (md_table(["measure", "precision@10 by content"], prec_rows)
                 + f"\n\nShare of a query frame's 10 nearest frames of other test takes with the query's content "
                   f"label (10 contents), mean ± sd over seeds. {prov}")
    c = r["clips"]
    clip_rows = [[a, *(fmt(c["rho"][a][b].get("mean"), 2) for b in names)] for a in names]
    clip_block = (md_table(["A \\ B", *names], clip_rows)
                  + f"\n\nMean Spearman ρ over seeds (Fig. 2.4's form): the middle {c['seconds']:g} s of "
                    f"{c['per_content']} random test takes per content ({', '.join(map(str, c['count_per_seed']))} "
                    f"clips per seed), every {c['stride']}th frame aligned; DTW (steps (1, 0), (0, 1), (1, 1), "
                    f"accumulated frame distances) between every "
                    f"two clips under each measure; per clip its {c['k']} nearest other clips under A (row) and ρ "
                    f"between their DTW distances under A and under B (column). Largest sd over seeds: "
                    f"{max(c['rho'][a][b].get('sd', 0.0) for a in names for b in names):.3f}. {prov}")
    clip_prec = (md_table(["measure", f"clips: precision@{c['k']} by content"],
                          [[n, fmt_spread(c["precision"][n])] for n in names])
                 + f"\n\nShare of a clip's {c['k']} nearest other clips (DTW under the measure) with its content, "
                   f"mean ± sd over seeds. {prov}")
    e15 = r["rho"]["E15"]
    clip_e15 = r["clips"]["rho"]["E15"]
    headline = (f"Frame distance measures (Krüger §2.3.1) against the feature sets on Bandai test takes "
                f"({r['queries_per_seed']} query frames × {len(record.get('seeds', []))} seeds): over E15's "
                f"{r['k']} nearest frames, Spearman ρ "
                f"with the point-cloud distance D_pc1 is {fmt_spread(e15['D_pc1'])} (the thesis: {THESIS_E15_PC1} "
                f"on HDM05), with D_pc11 {fmt_spread(e15['D_pc11'])}, with D_quat {fmt_spread(e15['D_quat'])}, with "
                f"E15x3 {fmt_spread(e15['E15x3'])}; compared as DTW distances of 2 s clips, E15 ranks like E15x3 with "
                f"ρ {fmt_spread(clip_e15['E15x3'])} and like D_pc11 with {fmt_spread(clip_e15['D_pc11'])}. "
                f"precision@10 by content: E15 {fmt_spread(r['precision_at_10']['E15'])}, D_pc11 "
                f"{fmt_spread(r['precision_at_10']['D_pc11'])}, D_quat {fmt_spread(r['precision_at_10']['D_quat'])} "
                f"([benchmarks/distances.md](benchmarks/distances.md)). {prov}")
    settings = r["splits"]["parameters"]
    params = (md_table(["setting", "value", "source"], [
        ["point-cloud windows",
         ", ".join(f"{k}: {v} frames" for k, v in settings["point_cloud_windows_frames"].items()),
         "thesis (D_pc1, D_pc11 at 30 fps)"],
        ["body-part joints (Lee)", ", ".join(settings["body_part_weights"]["lee"]), "thesis §2.3.1 (weights 1)"],
        ["body-part joints (WB)", ", ".join(settings["body_part_weights"]["wb"]), settings["wb_weights"]],
        ["k", str(settings["k"]), settings["k_source"]],
        ["rotations", settings["rotations"], "—"],
        ["PCAs", "pca8/16/25, F_pva20", r["splits"]["choose"]],
    ]) + f"\n\n{prov}")
    return {"matrix": matrix, "curve": curve, "precision": precision, "headline": headline, "settings": params,
            "clips": clip_block, "clip_precision": clip_prec}
