"""Suite ``style_examples``: the zero-shot network conditioned on k = 1, 2, 4, 8 examples of a style it never saw.

Issue 27, item 2: does a style keep more of its variation when the model sees several takes of it? No network is
trained here: the suite reads the finished leave-one-style-out trainings of suite ``zero_shot``
(``--loso runs/benchmarks/zero_shot/<data>/loso_<judge>[_e<epochs>]``, one ``seed<k>/`` per seed, each with its
``zero_shot.json``). For each seed ``k``, each primitive ``p`` and left-out style ``s`` there:

1. the network of ``p`` trained without ``s`` (and on an autoencoder that never saw ``s``:
   :func:`stylemotion.evaluation.zero_shot.load_left_out`, decoding with its own autoencoder,
   :func:`~stylemotion.evaluation.zero_shot.generator_autoencoder`);
2. for each k of ``--ks``: k example clips drawn from the **train-split** clips of ``s`` of ``p`` (one seeded
   permutation per seed, primitive and style, its first k: the draws are nested, k = 2 holds k = 1's clip),
   bound to the network and pooled by each of ``--pooling``: ``mean`` (their mean embedding and anchor, the pooling
   ``stylemotion-style example=[…]`` uses, :meth:`~stylemotion.models.zero_shot.ZeroShotStyleVAE.condition`) and
   ``per_sample`` (each sample conditioned on one of the k clips drawn with the sampling seed,
   :meth:`~stylemotion.models.zero_shot.ZeroShotStyleVAE.per_sample_condition`; for k ≥ 2, where it differs);
3. ``--samples`` samples (seed ``k``), measured by the judge of suite ``zero_shot`` (the reproduction the trainings
   were evaluated with, ``zero_shot.json``'s ``meta.run``: its autoencoder's Table 5.1 space and its style
   classifier, :func:`stylemotion.evaluation.pipeline.real_side`): **recognition** (the share classified as
   ``s``), the **Table 5.1 row** and whether ``s``'s own column (the example of the run's CVAE of ``s``) is its
   minimum (:func:`stylemotion.evaluation.zero_shot._table_row`), and pose_SD, V_SD, step_SD, pose_across_SD
   (:func:`stylemotion.evaluation.tables.variance_stats`) and diversity (mean pairwise distance in the classifier's
   features, :func:`stylemotion.evaluation.metrics.diversity`), each also as a share of the same figure of the
   style's **held-out** (val + test split) real clips.

The aims of issue 27 at k = 4: V_SD and step_SD ≥ 80 % and diversity ≥ 70 % of the held-out real clips, recognition
≥ 90 %, the own column the minimum; k = 1 is the single-example protocol of suite ``zero_shot`` (its example is one
train clip drawn here, not the CVAE's example).

``--data`` names the data the trainings are of (checked against the judge's); synthetic is a smoke test only.
"""

from __future__ import annotations

import argparse
import zlib
from pathlib import Path
from typing import Any

from suites.common import fmt, fmt_range, fmt_spread, md_table, progress_printed, provenance_line, spread
from suites.zero_shot import data_label

DESCRIPTION = ("zero-shot style network conditioned on k = 1, 2, 4, 8 train-split examples of a style it never saw "
               "(suite zero_shot's leave-one-style-out trainings, no training per k): recognition, Table 5.1 row, "
               "V_SD, step_SD, pose spread and diversity against the style's held-out real clips, over seeds")
DEFAULT_SEEDS = (0, 1, 2)
ROOT = Path(__file__).resolve().parents[2]
#: Example counts of the curve.
KS = (1, 2, 4, 8)
#: Variation figures, measured on the samples and on the style's held-out real clips.
VARIATION = ("pose_sd", "v_sd", "step_sd", "pose_across_sd", "diversity")
#: Issue 27's aims at k = 4: a share of the held-out real clips' figure each style must reach.
AIMS = {"v_sd": 0.8, "step_sd": 0.8, "diversity": 0.7}
#: The aimed recognition at k = 4.
AIM_RECOGNITION = 0.9
#: Poolings of the k clips (:data:`stylemotion.models.zero_shot.POOLINGS`, kept here for a light ``--help``).
POOLINGS = ("mean", "per_sample")


def row_label(k: int, pooling: str) -> str:
    """The key and table label of one row: ``"4"`` (mean pooling) or ``"4 per_sample"``."""
    return str(k) if pooling == "mean" else f"{k} {pooling}"


def row_labels(ks: list[int], poolings: list[str]) -> list[str]:
    """Every row of the curve, by k then pooling (``per_sample`` only for k ≥ 2, where it differs from the mean)."""
    return [row_label(k, p) for k in ks for p in POOLINGS if p in poolings and (p == "mean" or k > 1)]


def add_arguments(parser: argparse.ArgumentParser, loso: Path | None = None) -> None:
    """The suite's options; ``loso``: ``--loso``'s default (None: the option is required)."""
    parser.add_argument("--loso", type=Path, required=loso is None, default=loso,
                        help="suite zero_shot's trainings: a folder with seed<k>/zero_shot.json per seed (e.g. "
                             "runs/benchmarks/zero_shot/bandai/loso_<judge>_e<epochs>); read only")
    parser.add_argument("--data", choices=("synthetic", "bandai"), default="synthetic",
                        help="the data the trainings are of (checked against their judge run)")
    parser.add_argument("--ks", type=int, nargs="+", default=list(KS), help="example counts of the curve")
    parser.add_argument("--samples", type=int, default=1000, help="samples per network, k and seed")
    parser.add_argument("--pooling", nargs="+", choices=POOLINGS, default=["mean"],
                        help="how the k clips condition the samples: mean (their mean embedding, stylemotion-style's) "
                             "and/or per_sample (one clip drawn per sample)")
    parser.add_argument("--styles", nargs="+", default=None, help="left-out styles (default: every one trained)")
    parser.add_argument("--primitives", nargs="+", default=None, help="primitives (default: every one trained)")


def relative(path: Path | str) -> str:
    path = Path(path)
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def draw_examples(clips: list, ks: list[int], seed: int, primitive: str, style: str) -> dict[int, list]:
    """k → the first k clips of one permutation of ``clips`` (sorted by take and frame first) seeded by ``seed``
    and the primitive and style (nested draws); a k above the clip count is left out."""
    import numpy as np

    ordered = sorted(clips, key=lambda c: (c.take, c.start))
    rng = np.random.default_rng([int(seed), zlib.crc32(f"{primitive}/{style}".encode())])
    permuted = [ordered[i] for i in rng.permutation(len(ordered))]
    return {k: permuted[:k] for k in ks if k <= len(permuted)}


class Judge:
    """The judge run of the trainings (``zero_shot.json``'s ``meta.run``, with the evaluation settings of its report
    ``meta.report``: ``report_test`` holds out the test clips only): its autoencoder, data and, per primitive, its
    real side and Table 5.1 columns, built once."""

    def __init__(self, folder: str | Path, report: str = "report"):
        from stylemotion.datasets import build_dataset
        from stylemotion.evaluation.zero_shot import read_run
        from stylemotion.models.checkpoints import load_autoencoder

        self.source = read_run(folder, report)
        self.autoencoder = load_autoencoder(self.source.autoencoder_ckpt)
        self.takeset = build_dataset(self.source.data_cfg)
        self._sides: dict[str, tuple[Any, list[str], Any]] = {}

    def side(self, primitive: str) -> tuple[Any, list[str], Any]:
        """``(real side, Table 5.1 column names, their Grams)`` of ``primitive``, as suite zero_shot's evaluation
        has them: the neutral mean motion and the example of each of the run's CVAEs."""
        if primitive not in self._sides:
            import torch

            from stylemotion.evaluation.pipeline import example_column_gram, real_side
            from stylemotion.models.loading import NEUTRAL, EvalModel, load_model

            source, settings = self.source, self.source.settings
            cvaes = [load_model(source.cvaes[(q, s)], settings.neutral_style, self.autoencoder)
                     for q, s in source.cvaes if q == primitive]
            real = real_side(primitive, cvaes, self.takeset, settings, source.data_cfg.get("split"))
            neutral = EvalModel(NEUTRAL, primitive, settings.neutral_style, source=None)
            grams = torch.stack([example_column_gram(self.autoencoder, real, m) for m in [neutral, *real.models]])
            self._sides[primitive] = (real, [NEUTRAL] + [m.name for m in real.models], grams)
        return self._sides[primitive]


def variation_figures(real, motions) -> dict[str, float]:
    """pose_SD, V_SD, step_SD, pose_across_SD (:func:`~stylemotion.evaluation.tables.variance_stats`) and diversity
    (classifier features) of ≥ 2 motions."""
    from stylemotion.evaluation.metrics import diversity
    from stylemotion.evaluation.tables import variance_stats

    stats = variance_stats(motions.frames.numpy(), motions.positions.numpy(), motions.num_frames.numpy(),
                           motions.normalized_frames.numpy())
    return {**{k: float(stats[k]) for k in VARIATION[:-1]}, "diversity": diversity(real.features(motions))}


def curve_start(judge: Judge, primitive: str, style: str) -> tuple[Any, dict[str, float], list, dict[str, Any]]:
    """``(truth features, held-out figures, train-split clips, the curve's header)`` of one style: what every k of
    its curve is measured against and drawn from."""
    from stylemotion.evaluation.sources import motions_from_clips

    real, _, _ = judge.side(primitive)
    heldout = motions_from_clips(real.data.heldout(style), real.length)
    reference = variation_figures(real, heldout)
    train = real.data.split("train", style)
    return (real.features(real.truth[style]), reference, train,
            {"train_clips": len(train), "heldout_clips": len(heldout.num_frames), "real": reference, "ks": {}})


def style_curve(judge: Judge, network, primitive: str, style: str, ks: list[int], samples: int,
                seed: int, poolings: tuple[str, ...] = ("mean",)) -> dict[str, Any]:
    """The curve of one left-out network: per k its recognition, Table 5.1 row and variation (and shares of the
    held-out real clips'), and the held-out real clips' figures."""
    from stylemotion.datamodules.features import describe_clip
    from stylemotion.evaluation.zero_shot import generator_autoencoder
    from stylemotion.models.loading import EvalModel

    generator_autoencoder(network)  # it decodes with the autoencoder it was trained on
    truth, reference, train, out = curve_start(judge, primitive, style)
    draws = draw_examples(train, ks, seed, primitive, style)
    for label in row_labels(list(draws), list(poolings)):
        k, pooling = int(label.split()[0]), (label.split()[1:] or ["mean"])[0]
        clips = draws[k]
        records = [describe_clip(c) for c in clips]
        bound = network.bind_example(clips, style, records, pooling)
        model = EvalModel(f"zero_shot:{style}", primitive, style, bound, records, dict(network.spec["autoencoder"]),
                          network.checkpoint_file, network.timeline_frames, bound.target_gram,
                          network.spec.get("dataset"), "canonical")
        out["ks"][label] = judged_samples(judge, model, bound.sample(samples, seed=seed), truth, reference, records)
    return out


def judged_samples(judge: Judge, model, drawn, truth, reference: dict[str, float],
                   records: list[dict[str, Any]]) -> dict[str, Any]:
    """One curve point: the judge's recognition of ``drawn`` (samples of ``model``) as its style, their Table 5.1
    row, their variation and its share of the held-out real clips' (``reference``), and the example clips."""
    from stylemotion.evaluation.pipeline import recognition
    from stylemotion.evaluation.zero_shot import _table_row

    real, columns, grams = judge.side(model.primitive)
    judged = recognition(real, model, real.features(drawn), truth)
    row = _table_row(judge.autoencoder, drawn.normalized_frames, model.style, columns, grams, judge.source.settings)
    figures = variation_figures(real, drawn)
    return {"recognition": judged.share, "own_column_is_minimum": bool(row["own_column_is_minimum"]),
            "nearest_column": row["nearest_column"], "table_5_1_row": row["table_5_1_row"], **figures,
            "vs_real": {m: figures[m] / reference[m] if reference[m] else None for m in VARIATION},
            "examples": [{k_: r[k_] for k_ in ("take", "start", "stop")} for r in records]}


def run(args: argparse.Namespace, seeds: list[int], protocol: dict[str, Any] | None = None) -> dict[str, Any]:
    """The curves of every seed's trainings (``--loso``/``args.folder``, default ``seed{seed}``);
    ``protocol`` as :func:`summarize`'s."""
    import torch

    from stylemotion.evaluation.zero_shot import ZeroShotRunError, load_left_out
    from stylemotion.io.jsonfile import read_json_object

    torch.set_num_threads(1)
    ks = sorted({int(k) for k in args.ks})
    if not ks or ks[0] < 1:
        raise ZeroShotRunError(f"--ks must be whole numbers ≥ 1, got {args.ks}")
    poolings = [p for p in POOLINGS if p in (getattr(args, "pooling", None) or ["mean"])]
    judges: dict[tuple[str, str], Judge] = {}
    per_seed: dict[str, Any] = {}
    for seed in seeds:
        folder = args.loso.expanduser() / str(getattr(args, "folder", None) or "seed{seed}").format(seed=seed)
        record = read_json_object(folder / "zero_shot.json", "suite zero_shot's results",
                                  f"run suite zero_shot with --seeds {seed} first")
        if record["meta"].get("leaky"):
            raise ZeroShotRunError(f"{folder} holds the leaky protocol (networks on the judge's autoencoder); give "
                                   "the leakage-free trainings")
        judge_folder, report = str(record["meta"]["run"]), str(record["meta"].get("report") or "report")
        if (judge_folder, report) not in judges:
            judges[(judge_folder, report)] = Judge(judge_folder, report)
        judge = judges[(judge_folder, report)]
        name = judge.source.data_cfg.get("name")
        if (name == "synthetic") != (args.data == "synthetic"):
            raise ZeroShotRunError(f"{folder}'s judge run holds {name!r} data, not --data {args.data}")
        curves: dict[str, Any] = {}
        for p, res in record["primitives"].items():
            if args.primitives and p not in args.primitives:
                continue
            for s, row in res["styles"].items():
                if args.styles and s not in args.styles:
                    continue
                network = load_left_out(Path(row["zero_shot"]["checkpoint"]), p, s if "left_out" not in row
                                        else row["left_out"], row["generator_autoencoder"]["fingerprint"])
                # sampled as that evaluation sampled it (recorded since the networks' sampling settings exist)
                if row["zero_shot"].get("sample_temperature") is not None:
                    network.set_sample_temperature(row["zero_shot"]["sample_temperature"])
                if row["zero_shot"].get("sample_centred") is not None:
                    network.set_sample_centred(row["zero_shot"]["sample_centred"])
                with progress_printed(f"[seed {seed} {p}/{s}]"):
                    curves.setdefault(p, {})[s] = style_curve(judge, network, p, s, ks, args.samples, seed,
                                                              tuple(poolings))
        styles = set(judge.takeset.label_values("style")) - {judge.source.settings.neutral_style}
        per_seed[str(seed)] = {"loso": relative(folder), "judge": relative(judge_folder), "curves": curves,
                               "data_styles": sorted(styles)}
    return summarize(per_seed, ks, args, poolings, protocol)



def _narrowed_upstream(per_seed: dict[str, Any], left_out: list[tuple[str, str]]) -> bool:
    """Whether the trainings left out fewer styles than the judge's data has (seeds recorded before this: no)."""
    data = {s for v in per_seed.values() for s in v.get("data_styles") or []}
    return bool(data) and bool(data - {s for _, s in left_out})


def zero_shot_protocol(args: argparse.Namespace) -> dict[str, Any]:
    """Where this suite's models come from and what each split serves (recorded with its results)."""
    return {"loso": relative(args.loso.expanduser()),
            "splits": {"examples": "k clips of the left-out style drawn from its train-split clips (nested: one seeded "
                                   "permutation per seed, primitive and style)",
                       "reference": "the left-out style's held-out (val + test split) real clips",
                       "judge": "suite zero_shot's judge run: its autoencoder (Table 5.1) and style classifier "
                                "(fitted on the train-split clips of every style, the left-out one included)",
                       "networks": "suite zero_shot's leave-one-style-out trainings (autoencoder and network without "
                                   "the style); nothing trained here",
                       "seed_varies": "the trainings (a seed each), the example draws and the samples; the judge "
                                      "is fixed"}}


def summarize(per_seed: dict[str, Any], ks: list[int], args: argparse.Namespace,
              poolings: list[str] | None = None, protocol: dict[str, Any] | None = None) -> dict[str, Any]:
    """Spreads over seeds per style and k, the headline per k (means over styles), and the aims met at each k;
    ``protocol`` (default :func:`zero_shot_protocol`) says where the models come from."""
    rows = row_labels(ks, poolings or ["mean"])
    first = next(iter(per_seed.values()))
    left_out = [(p, s) for p, styles in first["curves"].items() for s in styles]
    per_style: dict[str, Any] = {}
    for p, s in left_out:
        curves = [v["curves"][p][s] for v in per_seed.values() if s in v["curves"].get(p, {})]
        per_style.setdefault(p, {})[s] = {
            "seeds": len(curves), "train_clips": curves[0]["train_clips"], "heldout_clips": curves[0]["heldout_clips"],
            "real": curves[0]["real"],
            "ks": {str(k): {"recognition": spread(c["ks"][str(k)]["recognition"] for c in curves if str(k) in c["ks"]),
                            "own_column_is_minimum": sum(bool(c["ks"][str(k)]["own_column_is_minimum"])
                                                         for c in curves if str(k) in c["ks"]),
                            "vs_real": {m: spread(c["ks"][str(k)]["vs_real"][m] for c in curves if str(k) in c["ks"])
                                        for m in VARIATION}}
                   for k in rows}}
    headline: dict[str, Any] = {}
    for k in rows:
        by_seed = {}
        for key, v in per_seed.items():
            cells = [v["curves"][p][s]["ks"][str(k)] for p, s in left_out
                     if str(k) in v["curves"].get(p, {}).get(s, {}).get("ks", {})]
            if cells:
                by_seed[key] = {
                    "recognition": sum(c["recognition"] for c in cells) / len(cells),
                    "own_column_is_minimum": sum(bool(c["own_column_is_minimum"]) for c in cells), "rows": len(cells),
                    **{m: _mean(c["vs_real"][m] for c in cells) for m in VARIATION},
                    "aims_met": sum(all((c["vs_real"][m] or 0) >= a for m, a in AIMS.items())
                                    and c["recognition"] >= AIM_RECOGNITION for c in cells)}
        headline[str(k)] = {**{key: spread(b[key] for b in by_seed.values())
                               for key in ("recognition", "own_column_is_minimum", "aims_met", *VARIATION)},
                            "rows_per_seed": max((b["rows"] for b in by_seed.values()), default=0)}
    return {"data": args.data, **(protocol or zero_shot_protocol(args)), "ks": ks, "rows": rows,
            "poolings": poolings or ["mean"], "samples": args.samples,
            "judge": sorted({v["judge"] for v in per_seed.values()}),
            "left_out": [f"{p}/{s}" for p, s in left_out],
            # narrowed here (--styles) or upstream (suite zero_shot left out fewer styles than the data has)
            "subsample": {"primitives": args.primitives,
                          "styles": args.styles or (sorted({s for _, s in left_out})
                                                    if _narrowed_upstream(per_seed, left_out) else None)},
            "aims": {"k": 4, **{f"{m}_vs_real": a for m, a in AIMS.items()}, "recognition": AIM_RECOGNITION},
            "headline": headline, "per_style": per_style,
            "per_seed": {k: {key: value for key, value in v.items() if key not in ("curves", "data_styles")}
                         for k, v in per_seed.items()}}


def _mean(values) -> float | None:
    finite = [float(v) for v in values if v is not None]
    return sum(finite) / len(finite) if finite else None


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    protocol = (f"Networks of suite zero_shot (`{r['loso']}`: per seed an autoencoder and a network that never saw "
                f"the left-out style), each conditioned on k clips of the style drawn from its train split (nested "
                f"draws), pooled by their mean embedding and anchor (as `stylemotion-style example=[…]` pools them) "
                f"or, in rows named per_sample, one clip drawn per sample; "
                f"{r['samples']:,} samples per network, k and seed, judged by run(s) {', '.join(r['judge'])} (its "
                f"autoencoder's Table 5.1 columns and its style classifier). Variation as a share of the style's "
                f"held-out (val + test) real clips.")
    return render_curve(record, "Zero-shot style network from k examples of a style it never saw", "left-out style",
                        protocol)


def render_curve(record: dict[str, Any], title: str, style_noun: str, protocol: str) -> dict[str, str]:
    """The blocks of a k-examples curve: ``headline`` (per k, means over styles), ``per_style`` and ``real``
    (the held-out clips' own figures); ``title`` names the model, ``style_noun`` its styles (``left-out style``
    or ``style``), ``protocol`` says where its models and clips come from."""
    r = record["results"]
    seeds = len(record.get("seeds", []))
    prov = provenance_line(record)
    label = data_label(r, f"{style_noun}s")
    rows = []
    for k in r.get("rows") or r["ks"]:
        h = r["headline"][str(k)]
        rows.append([str(k), f"{fmt_spread(h['recognition'], 3)} ({fmt_range(h['recognition'], 3)})",
                     f"{fmt_spread(h['own_column_is_minimum'], 1)} of {h['rows_per_seed']}",
                     *(fmt_spread(h[m], 2) for m in ("v_sd", "step_sd", "pose_across_sd", "pose_sd", "diversity")),
                     f"{fmt_spread(h['aims_met'], 1)} of {h['rows_per_seed']}"])
    listed = "left out" if style_noun == "left-out style" else f"{style_noun}s"
    headline = (f"{label}{title} ({r['data']}, {seeds} seeds; {listed}: {', '.join(r['left_out'])}). Means over "
                f"{style_noun}s, then mean ± sd (min–max for recognition) over seeds.\n\n"
                + md_table(["k (pooling: mean unless named)", "recognition",
                            "Table 5.1 rows whose minimum is the own example", "V_SD / real", "step_SD / real",
                            "pose_across_SD / real", "pose_SD / real", "diversity / real",
                            "styles meeting issue 27's k = 4 aims (V_SD, step_SD ≥ 80 %, diversity ≥ 70 %, "
                            "recognition ≥ 90 %)"], rows)
                + f"\n\n{protocol} {prov}")
    style_rows = []
    for p, styles in r["per_style"].items():
        for s, v in styles.items():
            for k in r.get("rows") or r["ks"]:
                cell = v["ks"][str(k)]
                style_rows.append([p, s, str(k), fmt_spread(cell["recognition"], 3),
                                   f"{cell['own_column_is_minimum']}/{cell['recognition']['n']}",
                                   *(fmt_spread(cell["vs_real"][m], 2) for m in ("v_sd", "step_sd", "pose_across_sd",
                                                                                 "diversity"))])
    clips = "; ".join(f"{p}/{s}: {v['train_clips']} train, {v['heldout_clips']} held-out"
                      for p, styles in r["per_style"].items() for s, v in styles.items())
    per_style = (f"{label}Per {style_noun} and k ({r['data']}, {seeds} seeds): mean ± sd over seeds; seeds whose "
                 "Table 5.1 row has the style's own example as its minimum.\n\n"
                 + md_table(["primitive", style_noun, "k", "recognition", "own column", "V_SD / real",
                             "step_SD / real", "pose_across_SD / real", "diversity / real"], style_rows)
                 + f"\n\nClips of each style: {clips}. {protocol} {prov}")
    return {"headline": headline, "per_style": per_style,
            "real": md_table(["primitive", style_noun, *VARIATION],
                             [[p, s, *(fmt(v["real"][m], 3) for m in VARIATION)]
                              for p, styles in r["per_style"].items() for s, v in styles.items()])
            + f"\n\nThe held-out real clips' own figures (pose_SD, step_SD, pose_across_SD in cm; V_SD in m/s ⊕ "
              f"rad/s; diversity in classifier feature units). {prov}"}
