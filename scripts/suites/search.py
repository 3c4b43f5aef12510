"""Suite ``search``: motion-database search quality (Krüger ch. 2) with failures counted.

1. **LNG against exact subsequence DTW.** Random 1 s and 3 s queries cut from takes the database does not
   hold; the LNG's best match at each candidate ``k`` against DTW's over every database frame with the same
   steps (:func:`stylemotion.search.evaluation.compare_lng_dtw`). ``k`` is chosen on queries from the
   ``val`` takes (database: ``train``) and reported on queries from the ``test`` takes (database: ``train`` +
   ``val``). A query without an LNG path is a miss in every figure.
2. **Retrieval precision@10 by content.** One random 2 s query per test take and seed against ``train`` +
   ``val``, with the chosen ``k``; a missing match counts as a wrong one.
3. **Other captures.** Random windows of the three walks in ``other-skeletons`` (other actors, studios and
   skeletons), read by the path ``stylemotion-search`` takes for a user's file
   (:func:`stylemotion.search.command.load_query`), against all of Bandai with the command's defaults.

Speed (ms per alignment or k-NN query) is not measured here: it needs an idle machine.
"""

from __future__ import annotations

import argparse
from collections import Counter, defaultdict
from pathlib import Path
from typing import Any

import numpy as np
from suites.common import DATA_ROOT, fmt, fmt_spread, md_table, provenance_line, spread, take_split_record

DESCRIPTION = ("motion-database search: LNG vs exact subsequence DTW (k chosen on val queries), precision@10 by "
               "content, queries from other captures")
DEFAULT_SEEDS = (0, 1, 2)
#: Issue 13's aim for the share of queries where the LNG returns DTW's best segment (the k rule below).
SAME_SEGMENT_AIM = 0.95
LOCOMOTION = ("walk", "walk-turn-left", "walk-turn-right")
CAPTURES = ("walk_21joint_60fps.bvh", "female-walk_21joint_60fps.bvh", "xia_neutral_01_000_31joint_120fps.bvh")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--ks", type=int, nargs="+", default=[64, 256, 1024], help="candidate neighbours per frame")
    parser.add_argument("--lng-queries", type=int, default=20,
                        help="LNG vs DTW queries per seed, query length and split (val, test)")
    parser.add_argument("--lengths-s", type=float, nargs="+", default=[1.0, 3.0], help="LNG vs DTW query lengths")
    parser.add_argument("--retrieval-s", type=float, default=2.0, help="retrieval query length, s")
    parser.add_argument("--capture-windows", type=int, default=4, help="windows per capture file, length and seed")
    parser.add_argument("--capture-lengths-s", type=float, nargs="+", default=[1.0, 2.0])
    parser.add_argument("--rank-frames", type=int, default=256, help="frames per seed of the rank agreement")
    parser.add_argument("--rank-k", type=int, default=512, help="nearest frames per frame of the rank agreement")
    parser.add_argument("--rank-features", nargs="+", default=None, help="feature sets (default: all)")
    parser.add_argument("--turn-features", nargs="+", default=["E15", "EP17", "EP19"],
                        help="feature sets compared on left/right turn queries (Krüger §2.6.2)")


def _split_settings() -> dict[str, Any]:
    from omegaconf import OmegaConf

    import stylemotion

    cfg = OmegaConf.load(Path(stylemotion.__file__).parent / "configs" / "data" / "bandai.yaml")
    return {"seed": int(cfg.split.seed), "val_fraction": float(cfg.split.val_fraction),
            "test_fraction": float(cfg.split.test_fraction)}


def _choose_k(val: dict[int, list[float]], ks: list[int]) -> tuple[int, str]:
    """The smallest k whose mean validation share of same best segment (1 s queries) reaches the aim, else
    the k with the highest share (ties: the smaller)."""
    means = {k: float(np.mean(val[k])) for k in ks}
    reaching = [k for k in ks if means[k] >= SAME_SEGMENT_AIM]
    if reaching:
        return min(reaching), f"smallest k reaching {SAME_SEGMENT_AIM:.0%} same best segment on val 1 s queries"
    best = max(means.values())
    return min(k for k in ks if means[k] == best), (f"no k reached {SAME_SEGMENT_AIM:.0%} on val 1 s queries: the "
                                                    f"highest share")


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.datasets import TakeSet, load_dataset
    from stylemotion.search import DEFAULT_K, FrameIndex
    from stylemotion.search.evaluation import (
        STILL_SPEED_M_S,
        compare_lng_dtw,
        mean_joint_speed,
        random_segments,
        summarize_lng,
    )

    ks = sorted(set(args.ks))
    bandai = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"), workers=2)
    settings = _split_settings()
    split = bandai.split(seed=settings["seed"], val_fraction=settings["val_fraction"],
                         test_fraction=settings["test_fraction"])
    databases = {"val": TakeSet("bandai-train", split["train"], bandai.fps),
                 "test": TakeSet("bandai-train+val", split["train"] + split["val"], bandai.fps)}
    indexes = {part: FrameIndex.build(ts, "E15") for part, ts in databases.items()}

    # 1. LNG vs DTW: per split, seed, length and k, the per-query comparisons.
    per: dict[str, Any] = defaultdict(list)  # (part, seed, seconds, k) -> records
    classes: dict[tuple[str, float], list[str]] = defaultdict(list)
    swept = []
    for p, part in enumerate(("val", "test")):
        index, takes = indexes[part], split[part]
        bounds = index.database.take_bounds
        for seed in seeds:
            for seconds in args.lengths_s:
                m = int(round(seconds * bandai.fps))
                rng = np.random.default_rng([seed, p, m])
                for t, start in random_segments([tk.num_frames for tk in takes], m, args.lng_queries, rng):
                    clip = np.asarray(takes[t].positions[start:start + m])
                    result = compare_lng_dtw(index.features_of(clip), index, bounds, ks)
                    swept.append(result.takes_swept)
                    still = "still" if mean_joint_speed(clip, bandai.fps) < STILL_SPEED_M_S else "moving"
                    classes[(part, seconds)].append(still)
                    for k in ks:
                        per[(part, seed, seconds, k)].append(result.record(k))
    summaries = [{"split": part, "seed": seed, "query_s": seconds, "k": k,
                  **summarize_lng(per[(part, seed, seconds, k)])}
                 for part in ("val", "test") for seed in seeds for seconds in args.lengths_s for k in ks]
    val_share = {k: [s["same_segment"] for s in summaries if s["split"] == "val" and s["k"] == k
                     and s["query_s"] == min(args.lengths_s)] for k in ks}
    chosen, rule = _choose_k(val_share, ks)
    pooled = []
    for part in ("val", "test"):
        for seconds in args.lengths_s:
            for k in ks:
                records = [r for seed in seeds for r in per[(part, seed, seconds, k)]]
                labels = classes[(part, seconds)]
                row = {"split": part, "query_s": seconds, "k": k, **summarize_lng(records)}
                for label in ("still", "moving"):
                    chosen_records = [r for r, c in zip(records, labels) if c == label]
                    row[label] = summarize_lng(chosen_records) if chosen_records else {"queries": 0}
                pooled.append(row)

    # 2. Retrieval precision@10 by content, test takes against train + val, chosen k.
    retrieval = _retrieval(indexes["test"], split["test"], seeds, args.retrieval_s, chosen)

    # 3. Other captures against all of Bandai with the command's defaults.
    captures = _captures(bandai, seeds, args.capture_windows, args.capture_lengths_s, DEFAULT_K)

    # 4. Rank agreement between feature sets (Fig. 2.5/2.7) on the train + val database.
    from stylemotion.search import feature_names

    feature_indexes = _feature_indexes(indexes["test"], [*(args.rank_features or feature_names()),
                                                         *args.turn_features])
    ranks = _ranks(feature_indexes, seeds, args.rank_frames, args.rank_k, args.rank_features)

    # 5. Left and right turns per feature set (§2.6.2): test turn takes against train + val, the chosen k.
    turn_takes = [t for t in split["test"] if t.content in ("walk-turn-left", "walk-turn-right")]
    turns = {name: _retrieval(feature_indexes[name], turn_takes, seeds, args.retrieval_s, chosen)
             for name in args.turn_features}

    return {"splits": {"choose": "val takes (queries) against train takes (database)",
                       "report": "test takes (queries) against train + val takes (database)",
                       "other_captures": "the other-skeletons walks (queries) against every Bandai take",
                       **take_split_record(split, **settings)},
            "features": "E15", "steps": "thesis (1,1), (0,1), (1,0)", "normalize": "none",
            "database_frames": {part: ix.database.num_frames for part, ix in indexes.items()},
            "database_takes": {part: ix.database.num_takes for part, ix in indexes.items()},
            "still_speed_m_s": STILL_SPEED_M_S,
            "k_choice": {"candidates": ks, "val_same_segment_1s": {str(k): val_share[k] for k in ks},
                         "rule": rule, "aim": SAME_SEGMENT_AIM, "chosen": chosen, "default_at_run": DEFAULT_K},
            "dtw_takes_swept": {"mean": float(np.mean(swept)), "max": int(np.max(swept))},
            "lng_per_seed": summaries, "lng_pooled": pooled, "retrieval": retrieval, "captures": captures,
            "ranks": ranks, "turns_by_features": turns}


def _feature_indexes(e15: Any, names: list[str]) -> dict[str, Any]:
    """E15's index and one index of each other set of ``names`` over the same database."""
    from stylemotion.search import FrameIndex

    return {n: e15 if n == "E15" else FrameIndex.build(e15.database, n) for n in dict.fromkeys(["E15", *names])}


def _ranks(feature_indexes: dict[str, Any], seeds: list[int], frames: int, k: int,
           names: list[str] | None) -> dict[str, Any]:
    from stylemotion.search import feature_names
    from stylemotion.search.evaluation import rank_agreement

    names = names or feature_names()
    indexes = {n: feature_indexes[n] for n in names}
    e15 = feature_indexes["E15"]
    per_seed = []
    for seed in seeds:
        rng = np.random.default_rng([seed, 4])
        chosen = rng.choice(e15.database.num_frames, size=min(frames, e15.database.num_frames), replace=False)
        per_seed.append(rank_agreement(indexes, chosen, min(k, e15.database.num_frames)))
    return {"features": names, "frames_per_seed": frames, "k": k,
            "rho": {a: {b: spread(s[a][b] for s in per_seed) for b in names} for a in names}}


def _retrieval(index: Any, takes: list[Any], seeds: list[int], seconds: float, k: int) -> dict[str, Any]:
    from stylemotion.search import search_features
    from stylemotion.search.evaluation import precision_at

    m = int(round(seconds * index.database.fps))
    usable = [t for t in takes if t.num_frames >= m]
    by_content: dict[str, dict[str, list[float]]] = defaultdict(lambda: defaultdict(list))
    overall: dict[str, list[float]] = defaultdict(list)
    turns: dict[str, Counter] = defaultdict(Counter)
    opposite_share: dict[str, list[float | None]] = defaultdict(list)  # per seed: matches turning the other way
    for seed in seeds:
        rng = np.random.default_rng([seed, 2, m])
        rows = defaultdict(list)
        seed_turns: dict[str, Counter] = defaultdict(Counter)
        for take in usable:
            start = int(rng.integers(0, take.num_frames - m + 1))
            found = search_features(index.features_of(take.positions[start:start + m]), index, k, 10).matches
            contents = [f.content for f in found]
            row = {"p10": precision_at(contents, take.content, 10), "found": len(found), "none": not found,
                   "found_precision": (sum(c == take.content for c in contents) / len(contents)) if contents else None}
            rows[take.content].append(row)
            rows["all"].append(row)
            if take.content in ("walk-turn-left", "walk-turn-right"):
                other = "walk-turn-right" if take.content == "walk-turn-left" else "walk-turn-left"
                turns[take.content].update(opposite=contents.count(other), matches=len(contents))
                seed_turns[take.content].update(opposite=contents.count(other), matches=len(contents))
        for content, counts in seed_turns.items():
            opposite_share[content].append(counts["opposite"] / counts["matches"] if counts["matches"] else None)
        for content, rs in rows.items():
            target = overall if content == "all" else by_content[content]
            target["p10"].append(float(np.mean([r["p10"] for r in rs])))
            target["found"].append(float(np.mean([r["found"] for r in rs])))
            target["none"].append(float(sum(r["none"] for r in rs)))
            target["queries"].append(float(len(rs)))
            kept = [r["found_precision"] for r in rs if r["found_precision"] is not None]
            target["found_precision"].append(float(np.mean(kept)) if kept else None)
    pack = lambda d: {key: spread(v) for key, v in d.items()}  # noqa: E731
    return {"query_s": seconds, "k": k, "queries_per_seed": len(usable), "all": pack(overall),
            "by_content": {c: pack(d) for c, d in sorted(by_content.items())},
            "turns": {c: dict(v) for c, v in turns.items()},
            "turn_opposite_share": {c: spread(v) for c, v in sorted(opposite_share.items())}}


def _captures(bandai: Any, seeds: list[int], windows: int, lengths_s: list[float], k: int) -> dict[str, Any]:
    from stylemotion.search import FrameIndex, search_motion
    from stylemotion.search.command import load_query
    from stylemotion.search.evaluation import precision_at

    index = FrameIndex.build(bandai, "E15")
    folder = DATA_ROOT / "other-skeletons"
    files = {name: load_query(str(folder / name), bandai, index.database) for name in CAPTURES}
    rows = []
    for seconds in lengths_s:
        per_seed: dict[str, list[float]] = defaultdict(list)
        contents: Counter = Counter()
        answered = queries = 0
        for seed in seeds:
            rng = np.random.default_rng([seed, 3, int(seconds * 1000)])
            p10, walk10, near_walk = [], [], []
            for name, whole in files.items():
                rate, total = whole.record["file_fps"], whole.record["file_frames"]
                span = int(round(seconds * rate))
                for _ in range(windows):
                    start = int(rng.integers(0, total - span + 1))
                    query = load_query(f"{folder / name}:{start}-{start + span}", bandai, index.database)
                    result = search_motion(query.positions, index, k, 10)
                    found = result.matches
                    labels = [x.content for x in found]
                    nearest = [index.database.contents[t] for t in index.database.take_id[result.indices[:, 0]]]
                    near_walk.append(sum(c in LOCOMOTION for c in nearest) / len(nearest))
                    contents.update(labels)
                    queries += 1
                    answered += bool(found)
                    p10.append(precision_at(labels, "walk", 10))
                    walk10.append(sum(c in LOCOMOTION for c in labels[:10]) / 10)
            per_seed["p10_walk"].append(float(np.mean(p10)))
            per_seed["p10_walk_or_turn"].append(float(np.mean(walk10)))
            per_seed["nearest_walk_or_turn"].append(float(np.mean(near_walk)))
        total_matches = sum(contents.values())
        rows.append({"query_s": seconds, "queries": queries, "answered": answered, "matches": total_matches,
                     "contents": {c: n for c, n in contents.most_common()},
                     "p10_walk": spread(per_seed["p10_walk"]),
                     "p10_walk_or_turn": spread(per_seed["p10_walk_or_turn"]),
                     "nearest_walk_or_turn": spread(per_seed["nearest_walk_or_turn"])})
    return {"files": list(CAPTURES), "k": k, "top": 10, "features": "E15", "windows_per_file_length_seed": windows,
            "database_takes": index.database.num_takes, "database_frames": index.database.num_frames,
            "file_fps": {n: q.record["file_fps"] for n, q in files.items()},
            "file_frames": {n: q.record["file_frames"] for n, q in files.items()}, "rows": rows}


# --- rendering ---------------------------------------------------------------------------------------------------


def _pct(value: float | None) -> str:
    return "—" if value is None else f"{100 * value:.1f} %"


def _seed_spread(r: dict[str, Any], split: str, seconds: float, k: int, key: str) -> dict[str, Any]:
    return spread(s[key] for s in r["lng_per_seed"] if s["split"] == split and s["query_s"] == seconds and s["k"] == k)


def _pooled(r: dict[str, Any], split: str, seconds: float, k: int) -> dict[str, Any]:
    return next(p for p in r["lng_pooled"] if p["split"] == split and p["query_s"] == seconds and p["k"] == k)


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice = r["k_choice"]
    k = choice["chosen"]
    lengths = sorted({p["query_s"] for p in r["lng_pooled"]})
    seeds = len(record.get("seeds", []))
    prov = provenance_line(record)

    # headline
    rows = []
    for seconds in lengths:
        p = _pooled(r, "test", seconds, k)
        rows.append([f"LNG vs exact DTW, {seconds:g} s test queries (k = {k}, chosen on val)",
                     f"same best segment {fmt_spread(_seed_spread(r, 'test', seconds, k, 'same_segment'))}; "
                     f"ρ {fmt_spread(_seed_spread(r, 'test', seconds, k, 'spearman_rho'), 3)}; "
                     f"no path {p['no_path']} of {p['queries']}"])
    ret = r["retrieval"]
    rows.append([f"precision@10 by content, {ret['query_s']:g} s test queries (missing matches wrong)",
                 f"{fmt_spread(ret['all']['p10'])}; no match for {fmt(ret['all']['none']['mean'], 1)} of "
                 f"{ret['queries_per_seed']} queries per seed"])
    for row in r["captures"]["rows"]:
        rows.append([f"other captures, {row['query_s']:g} s walk queries vs all of Bandai (command defaults)",
                     f"answered {row['answered']} of {row['queries']}; precision@10 walk or turn "
                     f"{fmt_spread(row['p10_walk_or_turn'])}"])
    headline = (md_table(["search (E15, thesis steps)", f"mean ± sd over {seeds} seeds of query choice"], rows)
                + f"\n\nEvery query counts: one without an LNG path is a miss (ρ: worst rank). {prov}")

    # k choice
    crow = [[str(c), _pct(float(np.mean(choice["val_same_segment_1s"][str(c)]))),
             ", ".join(_pct(v) for v in choice["val_same_segment_1s"][str(c)]),
             "**chosen**" if c == k else ""] for c in choice["candidates"]]
    default_note = ("the command's default" if choice["default_at_run"] == k
                    else f"differs from the default at the run ({choice['default_at_run']})")
    k_block = (md_table(["k", "val: same best segment, 1 s (mean)", "per seed", ""], crow)
               + f"\n\nRule: {choice['rule']} (aim {_pct(choice['aim'])}); k = {k}: {default_note}. "
                 f"Validation: {r['lng_pooled'][0]['queries']} queries per length (all seeds) from the "
                 f"{r['splits']['takes']['val']} val takes against the {r['database_takes']['val']:,} train takes. "
                 f"{prov}")

    # LNG vs DTW on test
    lrow = []
    for seconds in lengths:
        for c in choice["candidates"]:
            p = _pooled(r, "test", seconds, c)
            lrow.append([f"{seconds:g} s", f"{c}{' (chosen)' if c == k else ''}", f"{p['queries']}",
                         f"{p['no_path']}",
                         fmt_spread(_seed_spread(r, "test", seconds, c, "same_segment")),
                         fmt_spread(_seed_spread(r, "test", seconds, c, "overlap")),
                         fmt_spread(_seed_spread(r, "test", seconds, c, "spearman_rho"), 3),
                         f"{fmt(p['cost_ratio_mean'], 3)} / {fmt(p['cost_ratio_p95'], 3)} / "
                         f"{fmt(p['cost_ratio_max'], 3)} ({p['cost_ratio_n']})",
                         {True: "yes", False: "**no**", None: "—"}[p["lng_never_below_dtw"]]])
    lng_block = (md_table(["query", "k", "queries", "no LNG path", "same best segment", "overlapping best segment",
                           "Spearman ρ (no path = worst rank)",
                           "LNG / DTW cost: mean / p95 / max (queries with a path)", "LNG cost ≥ DTW"], lrow)
                 + f"\n\nQueries: {r['lng_pooled'][0]['queries'] // seeds} random windows per length and seed cut "
                   f"from the {r['splits']['takes']['test']} test takes; database the {r['database_takes']['test']:,} "
                   f"train + val takes ({r['database_frames']['test']:,} frames). Shares and ρ: mean ± sd over the "
                   f"seeds, every query counted (no path = not the same segment, worst LNG rank); cost ratios pooled "
                   f"over the seeds' queries that have a path. DTW swept on average "
                   f"{fmt(r['dtw_takes_swept']['mean'], 1)} takes per query (max {r['dtw_takes_swept']['max']:,}; the "
                   f"others' lower bounds exceed its best cost). {prov}")

    # still vs moving (chosen k, test)
    srow = []
    for seconds in lengths:
        p = _pooled(r, "test", seconds, k)
        for label in ("still", "moving"):
            s = p[label]
            srow.append([f"{seconds:g} s", label, str(s["queries"]), str(s.get("no_path", 0)),
                         _pct(s.get("same_segment")), fmt(s.get("spearman_rho"), 3),
                         fmt(s.get("cost_ratio_max"), 3)])
    still_block = (md_table(["query", "content", "queries", "no LNG path", "same best segment", "Spearman ρ",
                             "max LNG / DTW cost"], srow)
                   + f"\n\nTest queries at k = {k}, pooled over seeds; \"still\": mean joint speed below "
                     f"{r['still_speed_m_s']:g} m/s (standing at a take's start or end). {prov}")

    # retrieval by content
    rrow = [["all", str(ret["queries_per_seed"]), fmt_spread(ret["all"]["p10"]),
             fmt_spread(ret["all"]["found_precision"]), fmt_spread(ret["all"]["found"], 1),
             fmt_spread(ret["all"]["none"], 1)]]
    for content, d in ret["by_content"].items():
        rrow.append([content, fmt(d["queries"]["mean"], 0), fmt_spread(d["p10"]), fmt_spread(d["found_precision"]),
                     fmt_spread(d["found"], 1), fmt_spread(d["none"], 1)])
    turns = ret["turns"]
    turn_text = "; ".join(f"{c} queries: {v.get('opposite', 0)} of {v.get('matches', 0)} matches turn the other way"
                          for c, v in sorted(turns.items()))
    ret_block = (md_table(["content", "queries per seed", "precision@10 (missing = wrong)",
                           "precision of the matches found", "matches found (≤ 10)", "queries without a match"], rrow)
                 + f"\n\nOne random {ret['query_s']:g} s window of every test take per seed against the train + val "
                   f"takes, E15, k = {ret['k']} (chosen above), top 10; mean ± sd over the seeds. The query's "
                   f"actor, content and style are in the database (every Bandai take shares one skeleton): easier "
                   f"than a user's query. Turns, pooled over seeds: {turn_text}. {prov}")

    # other captures
    cap = r["captures"]
    caprow = []
    for row in cap["rows"]:
        top = ", ".join(f"{c} {n}" for c, n in row["contents"].items()) or "none"
        caprow.append([f"{row['query_s']:g} s", str(row["queries"]), str(row["answered"]),
                       fmt(row["matches"] / row["queries"], 1), top, fmt_spread(row["p10_walk"]),
                       fmt_spread(row["p10_walk_or_turn"]), fmt_spread(row["nearest_walk_or_turn"])])
    cap_block = (md_table(["query", "queries", "answered (≥ 1 match)", "matches per query", "contents of the matches",
                           "precision@10 walk", "precision@10 walk or turn",
                           "query frames whose nearest frame is a walk or turn"], caprow)
                 + f"\n\nOther captures: {cap['windows_per_file_length_seed']} random windows per file, length and "
                   f"seed of the three other-skeletons walks (two 21-joint 60 fps, one Xia 31-joint 120 fps), read and "
                   f"put on Bandai's skeleton as `stylemotion-search query=<file>:<start>-<end>` does, against all "
                   f"{cap['database_takes']:,} Bandai takes ({cap['database_frames']:,} frames) with the command's "
                   f"defaults (E15, k = {cap['k']}, top {cap['top']}); precision counts missing matches wrong, "
                   f"mean ± sd over seeds. {prov}")
    rk = r["ranks"]
    names = rk["features"]
    rank_rows = [[a, *(fmt(rk["rho"][a][b]["mean"]) for b in names)] for a in names]
    worst_sd = max(rk["rho"][a][b]["sd"] for a in names for b in names)
    rank_block = (md_table(["A \\ B", *names], rank_rows)
                  + f"\n\nFor {rk['frames_per_seed']} random frames per seed of the train + val takes, their "
                    f"{rk['k']} nearest frames under set A (row); Spearman ρ between those frames' distances under A "
                    f"and under B (column), averaged over the frames; mean over the seeds (largest sd of a cell "
                    f"{fmt(worst_sd, 3)}). {prov}")
    tb = r.get("turns_by_features") or {}
    turn_rows = []
    for name, t in tb.items():
        for content in ("walk-turn-left", "walk-turn-right"):
            d = t["by_content"].get(content)
            if d is None:
                continue
            counts = t["turns"].get(content, {})
            turn_rows.append([name, content, fmt(d["queries"]["mean"], 0), fmt_spread(d["p10"]),
                              fmt_spread(d["found_precision"]),
                              fmt_spread(t["turn_opposite_share"].get(content, {})),
                              f"{counts.get('opposite', 0)} of {counts.get('matches', 0)}", fmt_spread(d["none"], 1)])
    turn_block = (md_table(["features", "query content", "queries per seed", "precision@10 same turn (missing = wrong)",
                            "precision of the matches found", "share of matches turning the other way",
                            "pooled: other way / matches", "queries without a match"], turn_rows)
                  + f"\n\nKrüger §2.6.2 reports that the physics-based sets separate left from right turns better than "
                    f"E15. Every test turn take, one random {ret['query_s']:g} s window per seed (the same windows for "
                    f"every set) against the train + val takes, k = {ret['k']} (chosen above on E15), top 10; "
                    f"mean ± sd over the seeds. The query's actor, content and style are in the database: easier "
                    f"than a user's query. {prov}") if tb else "No turn comparison in this results file."
    return {"headline": headline, "turns": turn_block, "ranks": rank_block, "k_choice": k_block, "lng": lng_block,
            "lng_still": still_block, "retrieval": ret_block, "captures": cap_block}
