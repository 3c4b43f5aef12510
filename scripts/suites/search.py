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
import time
from collections import Counter, defaultdict
from typing import Any

import numpy as np
from suites.common import (
    DATA_ROOT,
    bandai_split_settings,
    fmt,
    fmt_spread,
    md_table,
    provenance_line,
    quantiles,
    spread,
    take_split_record,
)

from stylemotion.search.settings import SearchSettings

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
    parser.add_argument("--lengths-s", type=float, nargs="+", default=[1.0, 3.0, 5.0], help="LNG vs DTW query lengths")
    parser.add_argument("--grow-rules", nargs="+", default=["stable", "path"], help="k growth rules chosen among")
    parser.add_argument("--grow-bounds", type=int, nargs="+", default=[16384, 65536],
                        help="k_max candidates of the growth (capped at the database's frames)")
    parser.add_argument("--grow-stable-for", type=int, nargs="+", default=[1, 2, 3],
                        help="stable_for candidates of grow=stable: doublings in a row the best segment must hold")
    parser.add_argument("--refine", type=int, nargs="+", default=[0, 8, 32],
                        help="refine candidates (LNG candidates re-ranked by exact DTW in windows; 0: none), chosen "
                             "on val with the growth")
    parser.add_argument("--eps", type=float, nargs="+", default=[0.1, 0.5], help="ε-approximate k-NN evaluated")
    parser.add_argument("--radii", type=float, nargs="+", default=[0.2], help="fixed radii (E15 units) evaluated")
    parser.add_argument("--approx-lengths-s", type=float, nargs="+", default=[1.0, 3.0],
                        help="test query lengths on which ε and radius searches are evaluated")
    parser.add_argument("--retrieval-s", type=float, default=2.0, help="retrieval query length, s")
    parser.add_argument("--capture-windows", type=int, default=4, help="windows per capture file, length and seed")
    parser.add_argument("--capture-lengths-s", type=float, nargs="+", default=[1.0, 2.0],
                        help="capture window lengths (the files hold 2.1–2.7 s)")
    parser.add_argument("--rank-frames", type=int, default=256, help="frames per seed of the rank agreement")
    parser.add_argument("--rank-k", type=int, default=512, help="nearest frames per frame of the rank agreement")
    parser.add_argument("--rank-features", nargs="+", default=None, help="feature sets (default: all)")
    parser.add_argument("--turn-features", nargs="+", default=["E15", "EP17", "EP19"],
                        help="feature sets compared on left/right turn queries (Krüger §2.6.2)")


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


#: The command's growth (grow, k_max, stable_for, refine) before issue 28's stricter stop: run on test beside the
#: chosen.
PREVIOUS_GROWTH = ("stable", 16384, 1, 0)


def _growth_name(grow: str, k_max: int, stable_for: int = 1, refine: int = 0) -> str:
    """Key of a search rule in the results: ``grow <rule> to <k_max>``, ``grow stable over <n> to <k_max>``
    when the best segment must hold over n > 1 doublings, `` + refine <N>`` when the LNG's N best candidates
    are re-ranked by exact DTW."""
    name = f"grow {grow} to {k_max}" if stable_for == 1 else f"grow {grow} over {stable_for} to {k_max}"
    return name + (f" + refine {refine}" if refine else "")


def _rule(chosen: list[Any] | tuple[Any, ...]) -> tuple[str, int, int, int]:
    """``(grow, k_max, stable_for, refine)`` of a recorded rule (a results file before ``stable_for``: 1, before
    ``refine``: 0)."""
    return (str(chosen[0]), int(chosen[1]), int(chosen[2]) if len(chosen) > 2 else 1,
            int(chosen[3]) if len(chosen) > 3 else 0)


def _val_share(per: dict[Any, list], seeds: list[int], lengths: list[float], ks: list[int]) -> dict[int, list[float]]:
    """Per fixed k, the per-seed share of val 1 s queries whose LNG best is DTW's."""
    first = min(lengths)
    return {k: [float(np.mean([r["same_segment"] for r in per[("val", seed, first, k)]])) for seed in seeds]
            for k in ks}


def _choose_growth(per: dict[Any, list], used: dict[Any, list], seeds: list[int], lengths: list[float],
                   candidates: list[tuple[str, int, int, int]], start_k: int) -> dict[str, Any]:
    """The search rule (grow, k_max, stable_for, refine) chosen on every val query (all lengths): among those that
    answer every query and return DTW's best segment for the aim's share at **every** query length (mean over
    seeds; the aim holds per length, so 1 s queries cannot carry 5 s ones), the one of least mean k used, then
    fewest candidates refined; else the highest share at the worst length (then the highest overall, fewest
    unanswered, least mean k, fewest refined). Remaining ties (a bound no val query reached costs nothing more on
    val) go to the larger k_max: headroom for queries unlike validation's."""
    scores = {}
    for grow, km, sf, refine in candidates:
        name = _growth_name(grow, km, sf, refine)
        records = {seed: [r for sec in lengths for r in per[("val", seed, sec, name)]] for seed in seeds}
        ks_used = [u for seed in seeds for sec in lengths for u in used[("val", seed, sec, name)]]
        by_length = {f"{sec:g}": float(np.mean([np.mean([r["same_segment"] for r in per[("val", seed, sec, name)]])
                                                for seed in seeds])) for sec in lengths}
        scores[name] = {"grow": grow, "k_max": km, "stable_for": sf, "refine": refine,
                        "same_segment": [float(np.mean([r["same_segment"] for r in rs])) for rs in records.values()],
                        "same_segment_by_length": by_length,
                        "no_path": int(sum(r["no_path"] for rs in records.values() for r in rs)),
                        "queries": int(sum(len(rs) for rs in records.values())),
                        "mean_k_used": float(np.mean(ks_used)), "max_k_used": int(np.max(ks_used))}
    mean = {n: float(np.mean(v["same_segment"])) for n, v in scores.items()}
    worst = {n: min(v["same_segment_by_length"].values()) for n, v in scores.items()}
    reaching = [n for n, v in scores.items() if v["no_path"] == 0 and worst[n] >= SAME_SEGMENT_AIM]
    if reaching:
        name = min(reaching, key=lambda n: (scores[n]["mean_k_used"], scores[n]["refine"], -scores[n]["k_max"]))
        why = (f"least mean k used among the rules answering every val query with DTW's best segment for "
               f"≥ {SAME_SEGMENT_AIM:.0%} of them at every query length (ties: fewer candidates refined, then the "
               f"larger k_max)")
    else:
        name = max(scores, key=lambda n: (worst[n], mean[n], -scores[n]["no_path"], -scores[n]["mean_k_used"],
                                          -scores[n]["refine"], scores[n]["k_max"]))
        why = (f"no rule reached {SAME_SEGMENT_AIM:.0%} at every length with every val query answered: the highest "
               f"share at the worst length")
    return {"candidates": scores, "start_k": start_k, "rule": why, "aim": SAME_SEGMENT_AIM, "chosen_name": name,
            "chosen": [scores[name]["grow"], scores[name]["k_max"], scores[name]["stable_for"],
                       scores[name]["refine"]],
            "chosen_on": "val: queries cut from the val takes against the train takes (never test)",
            "default_at_run": [SearchSettings.grow, SearchSettings.k_max, SearchSettings.stable_for,
                               SearchSettings.refine],
            "lengths_s": lengths}


def _test_variants(chosen: list[Any], refine_options: list[int] | None = None) -> list[tuple[str, int, int, int]]:
    """The search rules run on test: the chosen one and, beside it, the same growth with every other refine
    option measured (``refine_options``), its other rule to the same bound, ``stable`` with ``stable_for`` 1 to the
    same bound, and :data:`PREVIOUS_GROWTH` (each once)."""
    grow, km, sf, refine = _rule(chosen)
    other = "path" if grow == "stable" else "stable"
    same_growth = [(grow, km, sf, n) for n in sorted(set(refine_options or [refine])) if n != refine]
    return list(dict.fromkeys([(grow, km, sf, refine), *same_growth, (other, km, 1, 0), ("stable", km, 1, 0),
                               PREVIOUS_GROWTH]))


def _as_best(result: Any, index: Any) -> tuple[int, int, float, int] | None:
    if not result.matches:
        return None
    top = result.matches[0]
    return top.global_start, top.global_end - 1, top.cost, int(index.database.take_id[top.global_start])


def _verified_name(chosen: list[Any] | tuple[Any, ...]) -> str:
    """Key of the chosen search rule with the exact verification of its best segment (``verify=True``)."""
    return _growth_name(*_rule(chosen)) + " + verify"


def _test_extras(features: np.ndarray, index: Any, cache: Any, seconds: float, args: argparse.Namespace,
                 chosen: list[Any], start_k: int, costs: dict[Any, list], used: dict[Any, list],
                 seed: int, verified_takes: dict[float, list[int]]) -> dict[str, Any]:
    """On a test query: the gap-tolerant steps at the start k; seconds of the chosen growth (alone, with
    ``verify``, and with the ε and fixed-radius searches) as a ratio to the fixed start k, timed back to back; their
    answers; the takes ``verify`` swept (``verified_takes[seconds]``)."""
    from stylemotion.search import search_features
    from stylemotion.search.lng import GAP_STEPS, lng_match

    grow, km, sf, refine = _rule(chosen)
    dist, ind = cache(start_k)
    found = lng_match(ind, dist, index.database.take_bounds, steps=GAP_STEPS, top=1)
    out = {f"gaps at {start_k}": (found[0].start, found[0].end, found[0].cost, found[0].take) if found else None}
    used[("test", seed, seconds, f"gaps at {start_k}")].append(start_k)

    def timed(**options: Any) -> tuple[Any, float]:
        t0 = time.perf_counter()
        result = search_features(features, index, start_k, 1, **options)
        return result, time.perf_counter() - t0

    _, old = timed()
    result, new = timed(k_max=km, grow=grow, stable_for=sf, refine=refine)
    costs[(seconds, _growth_name(grow, km, sf, refine))].append(new / old)
    verified, t = timed(k_max=km, grow=grow, stable_for=sf, refine=refine, verify=True)
    name = _verified_name(chosen)
    out[name] = _as_best(verified, index)
    used[("test", seed, seconds, name)].append(verified.k)
    costs[(seconds, name)].append(t / old)
    verified_takes[seconds].append(int(verified.takes_verified))
    if seconds in args.approx_lengths_s:
        for eps in args.eps:
            result, t = timed(k_max=km, grow=grow, stable_for=sf, refine=refine, eps=eps)
            out[f"eps {eps:g}"] = _as_best(result, index)
            used[("test", seed, seconds, f"eps {eps:g}")].append(result.k)
            costs[(seconds, f"eps {eps:g}")].append(t / old)
        for radius in args.radii:
            result, t = timed(k_max=km, grow=grow, stable_for=sf, refine=refine, radius=radius)
            out[f"radius {radius:g}"] = _as_best(result, index)
            used[("test", seed, seconds, f"radius {radius:g}")].append(result.k)
            costs[(seconds, f"radius {radius:g}")].append(t / old)
    return out


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.datasets import TakeSet, load_dataset
    from stylemotion.search import DEFAULT_K, FrameIndex
    from stylemotion.search.evaluation import (
        STILL_SPEED_M_S,
        NeighbourCache,
        compare_lng_dtw,
        mean_joint_speed,
        random_segments,
        summarize_lng,
    )

    ks = sorted(set(args.ks))
    bandai = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"), workers=2)
    settings = bandai_split_settings()
    split = bandai.split(seed=settings["seed"], val_fraction=settings["val_fraction"],
                         test_fraction=settings["test_fraction"])
    databases = {"val": TakeSet("bandai-train", split["train"], bandai.fps),
                 "test": TakeSet("bandai-train+val", split["train"] + split["val"], bandai.fps)}
    indexes = {part: FrameIndex.build(ts, "E15") for part, ts in databases.items()}

    # 1. LNG vs DTW: per split, seed, length and k (or k-rule), the per-query comparisons. Validation first: it
    # chooses the fixed k (as before) and the growth rule; test then reports both.
    per: dict[Any, list] = defaultdict(list)  # (part, seed, seconds, key) -> records
    used: dict[Any, list] = defaultdict(list)  # (part, seed, seconds, key) -> k used per query
    classes: dict[tuple[str, float], list[str]] = defaultdict(list)
    costs: dict[Any, list] = defaultdict(list)  # (seconds, key) -> test seconds per query
    swept = []
    verified_takes: dict[float, list[int]] = defaultdict(list)  # query length -> takes verify swept per test query
    refine_options = sorted(set(args.refine))
    candidates = [(rule, km, sf, n) for rule in args.grow_rules for km in sorted(set(args.grow_bounds))
                  for sf in (sorted(set(args.grow_stable_for)) if rule == "stable" else [1]) for n in refine_options]
    growth_choice: dict[str, Any] = {}
    for p, part in enumerate(("val", "test")):
        index, takes = indexes[part], split[part]
        bounds = index.database.take_bounds
        if part == "test":
            chosen, rule = _choose_k(_val_share(per, seeds, args.lengths_s, ks), ks)
            growth_choice = _choose_growth(per, used, seeds, args.lengths_s, candidates, DEFAULT_K)
            candidates = _test_variants(growth_choice["chosen"], refine_options)
        for seed in seeds:
            for seconds in args.lengths_s:
                m = int(round(seconds * bandai.fps))
                rng = np.random.default_rng([seed, p, m])
                for t, start in random_segments([tk.num_frames for tk in takes], m, args.lng_queries, rng):
                    clip = np.asarray(takes[t].positions[start:start + m])
                    features = index.features_of(clip)
                    cache = NeighbourCache(index, features, bounds, top=max(1, *refine_options))
                    cache(max(ks))
                    variants = {}
                    for grow, km, sf, n in candidates:
                        name = _growth_name(grow, km, sf, n)
                        variants[name], k_used = cache.grown(DEFAULT_K, km, grow, sf, n)
                        used[(part, seed, seconds, name)].append(k_used)
                    # LNG costs bound DTW's from above; refined ones are DTW costs within windows (skips priced
                    # over the windows), so they stay out of the pruning
                    bounding = [name for (grow, km, sf, n), name in zip(candidates, variants) if not n]
                    if part == "test":
                        variants.update(_test_extras(features, index, cache, seconds, args, growth_choice["chosen"],
                                                     DEFAULT_K, costs, used, seed, verified_takes))
                        bounding += [v for v in variants if v.startswith(("eps", "radius"))]
                    result = compare_lng_dtw(features, index, bounds, ks, variants, cache, bounding)
                    swept.append(result.takes_swept)
                    still = "still" if mean_joint_speed(clip, bandai.fps) < STILL_SPEED_M_S else "moving"
                    classes[(part, seconds)].append(still)
                    for key in result.lng:
                        per[(part, seed, seconds, key)].append(result.record(key))
    keys = sorted({key[3] for key in per}, key=str)
    summaries = [{"split": part, "seed": seed, "query_s": seconds, "k": key,
                  **summarize_lng(per[(part, seed, seconds, key)])}
                 for part in ("val", "test") for seed in seeds for seconds in args.lengths_s for key in keys
                 if per.get((part, seed, seconds, key))]
    val_share = _val_share(per, seeds, args.lengths_s, ks)
    pooled = []
    for part in ("val", "test"):
        for seconds in args.lengths_s:
            for key in keys:
                records = [r for seed in seeds for r in per.get((part, seed, seconds, key), [])]
                if not records:
                    continue
                labels = classes[(part, seconds)]
                row = {"split": part, "query_s": seconds, "k": key, **summarize_lng(records)}
                ks_used = [u for seed in seeds for u in used.get((part, seed, seconds, key), [])]
                if ks_used:
                    row["k_used"] = {"mean": float(np.mean(ks_used)), **quantiles(ks_used),
                                     "counts": {str(k): int(n) for k, n in sorted(Counter(ks_used).items())}}
                for label in ("still", "moving"):
                    chosen_records = [r for r, c in zip(records, labels) if c == label]
                    row[label] = summarize_lng(chosen_records) if chosen_records else {"queries": 0}
                pooled.append(row)
    timing = {f"{seconds:g}|{key}": {"ratio": spread(v), **quantiles(v)} for (seconds, key), v in costs.items()}

    # 2. Retrieval precision@10 by content, test takes against train + val, chosen k.
    retrieval = retrieval_by_content(indexes["test"], split["test"], seeds, args.retrieval_s, chosen)

    # 3. Other captures against all of Bandai with the command's defaults.
    captures = _captures(bandai, seeds, args.capture_windows, args.capture_lengths_s, DEFAULT_K,
                         growth_choice["chosen"])

    # 4. Rank agreement between feature sets (Fig. 2.5/2.7) on the train + val database.
    from stylemotion.search import feature_names

    feature_indexes = _feature_indexes(indexes["test"], [*(args.rank_features or feature_names()),
                                                         *args.turn_features])
    ranks = _ranks(feature_indexes, seeds, args.rank_frames, args.rank_k, args.rank_features)

    # 5. Left and right turns per feature set (§2.6.2): test turn takes against train + val, the chosen k.
    turn_takes = [t for t in split["test"] if t.content in ("walk-turn-left", "walk-turn-right")]
    turns = {name: retrieval_by_content(feature_indexes[name], turn_takes, seeds, args.retrieval_s, chosen)
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
            "growth": growth_choice, "refine_options": refine_options, "time_ratio": timing,
            "approx": {"eps": args.eps, "radii": args.radii, "lengths_s": args.approx_lengths_s,
                       "note": "evaluated on test with the chosen growth; not tuned, defaults eps=0, radius=None"},
            "dtw_takes_swept": {"mean": float(np.mean(swept)), "max": int(np.max(swept))},
            "verify_takes_swept": {f"{sec:g}": {"mean": float(np.mean(v)), **quantiles(v)}
                                   for sec, v in verified_takes.items()},
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


def retrieval_by_content(index: Any, takes: list[Any], seeds: list[int], seconds: float, k: int,
                         **options: Any) -> dict[str, Any]:
    """Precision@10 by content of one random ``seconds`` window of each take per seed (``options``: further
    :func:`stylemotion.search.search_features` settings, e.g. the command's growth, refinement and verification)."""
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
            found = search_features(index.features_of(take.positions[start:start + m]), index, k, 10,
                                    **options).matches
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


def _captures(bandai: Any, seeds: list[int], windows: int, lengths_s: list[float], k: int,
              growth: list[Any]) -> dict[str, Any]:
    """Windows of the other-skeletons walks against all of Bandai: from the command's k, growing by the rule
    chosen on validation (``growth``: grow, k_max, stable_for), and, beside it, the fixed k alone (the search before
    growth); each against exact subsequence DTW."""
    from stylemotion.search import FrameIndex, search_features
    from stylemotion.search.command import load_query
    from stylemotion.search.dtw import best_subsequence_match
    from stylemotion.search.evaluation import precision_at, spearman_with_misses

    grow, k_max, stable_for, refine = _rule(growth)
    index = FrameIndex.build(bandai, "E15")
    bounds = index.database.take_bounds
    folder = DATA_ROOT / "other-skeletons"
    files = {name: load_query(str(folder / name), bandai, index.database) for name in CAPTURES}
    rows = []
    for seconds in lengths_s:
        per_seed: dict[str, list[float]] = defaultdict(list)
        contents: Counter = Counter()
        answered = answered_fixed = queries = same = same_fixed = same_verified = 0
        lng_costs, fixed_costs, dtw_costs, ks_used, ratios, verify_ratios = [], [], [], [], [], []
        for seed in seeds:
            rng = np.random.default_rng([seed, 3, int(seconds * 1000)])
            p10, walk10, near_walk = [], [], []
            for name, whole in files.items():
                rate, total = whole.record["file_fps"], whole.record["file_frames"]
                span = int(round(seconds * rate))
                for _ in range(windows):
                    start = int(rng.integers(0, total - span + 1))
                    query = load_query(f"{folder / name}:{start}-{start + span}", bandai, index.database)
                    features = index.features_of(query.positions)
                    t0 = time.perf_counter()
                    fixed = search_features(features, index, k, 10)
                    t1 = time.perf_counter()
                    result = search_features(features, index, k, 10, k_max=k_max, grow=grow, stable_for=stable_for,
                                             refine=refine)
                    t2 = time.perf_counter()
                    verified = search_features(features, index, k, 10, k_max=k_max, grow=grow,
                                               stable_for=stable_for, refine=refine, verify=True)
                    ratios.append((t2 - t1) / (t1 - t0))
                    verify_ratios.append((time.perf_counter() - t2) / (t1 - t0))
                    ks_used.append(result.k)
                    found = result.matches
                    upper = found[0].cost if found else None
                    best, _ = best_subsequence_match(features, index.features, bounds, upper_bound=upper)
                    dtw_costs.append(best.cost)
                    lng_costs.append(found[0].cost if found else None)
                    fixed_costs.append(fixed.matches[0].cost if fixed.matches else None)
                    same += bool(found) and (found[0].global_start, found[0].global_end - 1) == (best.start, best.end)
                    same_fixed += bool(fixed.matches) and (fixed.matches[0].global_start,
                                                           fixed.matches[0].global_end - 1) == (best.start, best.end)
                    same_verified += bool(verified.matches) and (verified.matches[0].global_start,
                                                                 verified.matches[0].global_end - 1) == (best.start,
                                                                                                         best.end)
                    labels = [x.content for x in found]
                    nearest = [index.database.contents[t] for t in index.database.take_id[fixed.indices[:, 0]]]
                    near_walk.append(sum(c in LOCOMOTION for c in nearest) / len(nearest))
                    contents.update(labels)
                    queries += 1
                    answered += bool(found)
                    answered_fixed += bool(fixed.matches)
                    p10.append(precision_at(labels, "walk", 10))
                    walk10.append(sum(c in LOCOMOTION for c in labels[:10]) / 10)
            per_seed["p10_walk"].append(float(np.mean(p10)))
            per_seed["p10_walk_or_turn"].append(float(np.mean(walk10)))
            per_seed["nearest_walk_or_turn"].append(float(np.mean(near_walk)))
        total_matches = sum(contents.values())
        rows.append({"query_s": seconds, "queries": queries, "answered": answered, "matches": total_matches,
                     "answered_fixed_k": answered_fixed, "same_segment": same / queries,
                     "same_segment_fixed_k": same_fixed / queries, "same_segment_verified": same_verified / queries,
                     "time_ratio_verified": {"mean": float(np.mean(verify_ratios)), **quantiles(verify_ratios)},
                     "spearman_rho": spearman_with_misses(lng_costs, dtw_costs),
                     "spearman_rho_fixed_k": spearman_with_misses(fixed_costs, dtw_costs),
                     "k_used": {"mean": float(np.mean(ks_used)), **quantiles(ks_used)},
                     "time_ratio": {"mean": float(np.mean(ratios)), **quantiles(ratios)},
                     "contents": {c: n for c, n in contents.most_common()},
                     "p10_walk": spread(per_seed["p10_walk"]),
                     "p10_walk_or_turn": spread(per_seed["p10_walk_or_turn"]),
                     "nearest_walk_or_turn": spread(per_seed["nearest_walk_or_turn"])})
    return {"files": list(CAPTURES), "k": k, "k_max": k_max, "grow": grow, "stable_for": stable_for,
            "refine": refine, "defaults": [SearchSettings.grow, SearchSettings.k_max, SearchSettings.stable_for,
                                           SearchSettings.refine], "verify_default": SearchSettings.verify, "top": 10,
            "features": "E15", "windows_per_file_length_seed": windows,
            "database_takes": index.database.num_takes, "database_frames": index.database.num_frames,
            "file_fps": {n: q.record["file_fps"] for n, q in files.items()},
            "file_frames": {n: q.record["file_frames"] for n, q in files.items()}, "rows": rows}


# --- rendering ---------------------------------------------------------------------------------------------------


def _growth_blocks(r: dict[str, Any], seeds: int, prov: str) -> dict[str, str]:
    """Blocks ``growth_choice`` (val), ``growth`` (test: every query answers?) and ``approx`` (ε, radius)."""
    growth = r["growth"]
    name, start = growth["chosen_name"], growth["start_k"]
    crow = []
    for cname, c in growth["candidates"].items():
        by_length = c.get("same_segment_by_length", {})
        crow.append([c["grow"], f"{c['k_max']:,}", str(c.get("stable_for", 1)) if c["grow"] == "stable" else "—",
                     str(c.get("refine", 0)),
                     _pct(float(np.mean(c["same_segment"]))),
                     ", ".join(f"{sec} s {_pct(v)}" for sec, v in by_length.items()) or "—",
                     ", ".join(_pct(v) for v in c["same_segment"]), f"{c['no_path']} of {c['queries']}",
                     fmt(c["mean_k_used"], 0), f"{c['max_k_used']:,}", "**chosen**" if cname == name else ""])
    default = growth["default_at_run"]
    note = ("the command's default (grow, k_max, stable_for, refine)" if _rule(default) == _rule(growth["chosen"])
            else f"**differs from the command's default at the run {_rule(default)}**")
    choice_block = (md_table(["grow", "k_max", "stable for (doublings)", "refine (LNG candidates re-ranked by DTW)",
                              "val: same best segment (mean)",
                              "per length", "per seed", "no path", "mean k used", "max k used", ""], crow)
                    + f"\n\nEvery val query of {', '.join(f'{x:g}' for x in growth['lengths_s'])} s (all seeds) from "
                      f"the val takes against the train takes, k starting at {start} (the command's k) and doubled: "
                      f"`stable` until the best segment has held over `stable_for` doublings in a row (1: the same "
                      f"at k and 2k; 2: at k, 2k and 4k), `path` until a path exists, never past k_max (nor the "
                      f"database's frames); refine N: the LNG's N best candidates re-ranked by exact subsequence "
                      f"DTW in windows widened by the query's length (0: the LNG's ranking). Chosen on "
                      f"{growth.get('chosen_on', 'val')}. Rule: {growth['rule']} (aim "
                      f"{_pct(growth['aim'])}); chosen {name}: {note}. {prov}")
    lengths = sorted({p["query_s"] for p in r["lng_pooled"]})
    tested = [_growth_name(*v) for v in _test_variants(growth["chosen"], r.get("refine_options"))]
    variants = [start, tested[0], _verified_name(growth["chosen"]), *tested[1:], f"gaps at {start}"]
    verify_takes = r.get("verify_takes_swept") or {}
    rows = []
    for seconds in lengths:
        for v in variants:
            p = _pooled(r, "test", seconds, v, missing_ok=True)
            if p is None:
                continue
            ratio = r["time_ratio"].get(f"{seconds:g}|{v}", {})
            ku = p.get("k_used") or {}
            label = (f"k = {v} alone (before)" if isinstance(v, int) else
                     f"{v} (**chosen**)" if v == name else
                     f"{v} (**the command's default**: swept {fmt(verify_takes[f'{seconds:g}']['mean'], 1)} takes "
                     f"on mean, {fmt(verify_takes[f'{seconds:g}']['p100'], 0)} at most)"
                     if v == _verified_name(growth["chosen"]) and f"{seconds:g}" in verify_takes else
                     f"{v} (the default before the stricter stop)" if v == _growth_name(*PREVIOUS_GROWTH) else str(v))
            rows.append([f"{seconds:g} s", label, f"{p['queries'] - p['no_path']} of {p['queries']}",
                         fmt_spread(_seed_spread(r, "test", seconds, v, "same_segment")),
                         fmt_spread(_seed_spread(r, "test", seconds, v, "spearman_rho"), 3),
                         f"{fmt(p['cost_ratio_mean'], 3)} / {fmt(p['cost_ratio_max'], 3)}",
                         f"{fmt(ku.get('p50'), 0)} / {fmt(ku.get('p95'), 0)} / {fmt(ku.get('p100'), 0)}"
                         if ku else f"{v}" if isinstance(v, int) else "—",
                         (f"{fmt(ratio['ratio']['mean'], 2)} / {fmt(ratio['p95'], 2)} / {fmt(ratio['p100'], 2)}"
                          if ratio else "1 (reference)" if isinstance(v, int) else "—")])
    growth_block = (md_table(["query", "search", "answered", "same best segment", "Spearman ρ (no path = worst rank)",
                              "LNG / DTW cost: mean / max", "k used: median / p95 / max",
                              f"time × k = {start} alone: mean / p95 / max"], rows)
                    + f"\n\nTest queries (random windows of the test takes, 3 lengths × "
                      f"{r['lng_pooled'][0]['queries'] // max(seeds, 1)} per seed) against the train + val takes, "
                      f"against exact subsequence DTW with the thesis' steps; a query without a path is a miss "
                      f"everywhere. `gaps at {start}`: the gap-tolerant steps (thesis + the online skips (1,2), "
                      f"(2,1), (2,2), a skipped query frame costing its k-th distance) at k = {start}, compared with "
                      f"the same thesis-step DTW (their cheaper skipping paths are not DTW's). `+ verify`: the chosen "
                      f"search, then exact DTW over every take whose lower bound (each query frame's nearest frame in "
                      f"it, summed) does not exceed the best cost found (`verify=true`, the command's default): its "
                      f"best segment is DTW's by construction, and the row checks that against the reference DTW, "
                      f"computed on its own; the LNG's share is the chosen row's. Time: the whole search "
                      f"(k-NN + LNG, every k tried, and the verification) over the search at k = {start} alone, timed "
                      f"back to back per query on a shared machine (ratios only). {prov}")
    approx = r["approx"]
    arows = []
    for seconds in approx["lengths_s"]:
        for v in [name, *(f"eps {e:g}" for e in approx["eps"]), *(f"radius {x:g}" for x in approx["radii"])]:
            p = _pooled(r, "test", seconds, v, missing_ok=True)
            if p is None:
                continue
            ratio = r["time_ratio"].get(f"{seconds:g}|{v}", {})
            ku = p.get("k_used") or {}
            arows.append([f"{seconds:g} s", "exact k-NN" if v == name else v,
                          f"{p['queries'] - p['no_path']} of {p['queries']}",
                          fmt_spread(_seed_spread(r, "test", seconds, v, "same_segment")),
                          fmt_spread(_seed_spread(r, "test", seconds, v, "spearman_rho"), 3),
                          f"{fmt(ku.get('p50'), 0)} / {fmt(ku.get('p100'), 0)}",
                          f"{fmt(ratio['ratio']['mean'], 2)} / {fmt(ratio['p100'], 2)}" if ratio else "—"])
    approx_block = (md_table(["query", "k-NN search", "answered", "same best segment", "Spearman ρ",
                              "k used: median / max", f"time × k = {start} alone: mean / max"], arows)
                    + f"\n\nThe chosen growth ({name} from k = {start}) with cKDTree's ε-approximate search (each "
                      f"distance within 1 + ε of the true one) and with a fixed radius (feature units; only neighbours "
                      f"within it, at most k; a frame with none left ends every path through it), on the test "
                      f"queries above, against the same exact DTW. Not tuned: the command keeps eps = 0 and no "
                      f"radius. {prov}")
    return {"growth_choice": choice_block, "growth": growth_block, "approx": approx_block}


def _pct(value: float | None) -> str:
    return "—" if value is None else f"{100 * value:.1f} %"


def _seed_spread(r: dict[str, Any], split: str, seconds: float, k: int, key: str) -> dict[str, Any]:
    return spread(s[key] for s in r["lng_per_seed"] if s["split"] == split and s["query_s"] == seconds and s["k"] == k)


def _pooled(r: dict[str, Any], split: str, seconds: float, k: Any, missing_ok: bool = False) -> dict[str, Any] | None:
    """The pooled LNG figures of one split, query length and search (``k`` or a variant's name); None for a
    combination the run did not measure when ``missing_ok``."""
    found = (p for p in r["lng_pooled"] if p["split"] == split and p["query_s"] == seconds and p["k"] == k)
    return next(found, None) if missing_ok else next(found)


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    choice = r["k_choice"]
    k = choice["chosen"]
    lengths = sorted({p["query_s"] for p in r["lng_pooled"]})
    seeds = len(record.get("seeds", []))
    prov = provenance_line(record)

    # headline
    rows = []
    growth = r.get("growth")
    for seconds in lengths:
        p = _pooled(r, "test", seconds, k)
        rows.append([f"LNG vs exact DTW, {seconds:g} s test queries (k = {k}, chosen on val)",
                     f"same best segment {fmt_spread(_seed_spread(r, 'test', seconds, k, 'same_segment'))}; "
                     f"ρ {fmt_spread(_seed_spread(r, 'test', seconds, k, 'spearman_rho'), 3)}; "
                     f"no path {p['no_path']} of {p['queries']}"])
        if growth:
            g = growth["chosen_name"]
            p = _pooled(r, "test", seconds, g)
            ratio = r["time_ratio"].get(f"{seconds:g}|{g}", {})
            rows.append([f"LNG vs exact DTW, {seconds:g} s test queries, k from {growth['start_k']} {g} "
                         f"(chosen on val)",
                         f"same best segment {fmt_spread(_seed_spread(r, 'test', seconds, g, 'same_segment'))}; "
                         f"ρ {fmt_spread(_seed_spread(r, 'test', seconds, g, 'spearman_rho'), 3)}; "
                         f"answered {p['queries'] - p['no_path']} of {p['queries']}; k used median "
                         f"{fmt(p['k_used']['p50'], 0)}, max {fmt(p['k_used']['p100'], 0)}; time × "
                         f"{fmt(ratio.get('ratio', {}).get('mean'), 1)} of k = {growth['start_k']} alone"])
            v = _verified_name(growth["chosen"])
            p = _pooled(r, "test", seconds, v, missing_ok=True)
            if p is not None:
                ratio = r["time_ratio"].get(f"{seconds:g}|{v}", {})
                rows.append([f"the same, then the best segment verified by exact DTW (`verify=true`, the command's "
                             f"default), {seconds:g} s test queries",
                             f"same best segment {fmt_spread(_seed_spread(r, 'test', seconds, v, 'same_segment'))} "
                             f"(exact by construction, checked); answered {p['queries'] - p['no_path']} of "
                             f"{p['queries']}; time × {fmt(ratio.get('ratio', {}).get('mean'), 1)} of k = "
                             f"{growth['start_k']} alone"])
    ret = r["retrieval"]
    rows.append([f"precision@10 by content, {ret['query_s']:g} s test queries (missing matches wrong)",
                 f"{fmt_spread(ret['all']['p10'])}; no match for {fmt(ret['all']['none']['mean'], 1)} of "
                 f"{ret['queries_per_seed']} queries per seed"])
    for row in r["captures"]["rows"]:
        extra = (f"; same best segment as DTW {_pct(row['same_segment'])}, ρ {fmt(row['spearman_rho'], 3)}"
                 if "same_segment" in row else "")
        if "same_segment_verified" in row:
            extra += (f" (LNG alone); with `verify=true` {_pct(row['same_segment_verified'])} at × "
                      f"{fmt(row['time_ratio_verified']['mean'], 1)} the time of k = {r['captures']['k']} alone")
        rows.append([f"other captures, {row['query_s']:g} s walk queries vs all of Bandai (command defaults)",
                     f"answered {row['answered']} of {row['queries']}{extra}; precision@10 walk or turn "
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
    grown = "k_max" in cap
    for row in cap["rows"]:
        top = ", ".join(f"{c} {n}" for c, n in row["contents"].items()) or "none"
        cells = [f"{row['query_s']:g} s", str(row["queries"]), str(row["answered"])]
        if grown:
            cells += [f"{row['answered_fixed_k']}",
                      f"{_pct(row['same_segment'])} ({_pct(row['same_segment_fixed_k'])})",
                      f"{fmt(row['spearman_rho'], 3)} ({fmt(row['spearman_rho_fixed_k'], 3)})",
                      (f"{_pct(row['same_segment_verified'])} (× {fmt(row['time_ratio_verified']['mean'], 1)} / "
                       f"{fmt(row['time_ratio_verified']['p100'], 1)})" if "same_segment_verified" in row else "—"),
                      f"{fmt(row['k_used']['p50'], 0)} / {fmt(row['k_used']['p100'], 0)}",
                      f"{fmt(row['time_ratio']['mean'], 1)} / {fmt(row['time_ratio']['p100'], 1)}"]
        cells += [fmt(row["matches"] / row["queries"], 1), top, fmt_spread(row["p10_walk"]),
                  fmt_spread(row["p10_walk_or_turn"]), fmt_spread(row["nearest_walk_or_turn"])]
        caprow.append(cells)
    fixed_head = ([f"answered at k = {cap['k']} alone", "same best segment as DTW (k alone)", "Spearman ρ vs DTW "
                   "(k alone)", "same best segment with verify (time × k alone: mean / max)", "k used: median / max",
                   "time × k alone: mean / max"] if grown else [])
    cap_block = (md_table(["query", "queries", "answered (≥ 1 match)", *fixed_head, "matches per query",
                           "contents of the matches", "precision@10 walk", "precision@10 walk or turn",
                           "query frames whose nearest frame is a walk or turn"], caprow)
                 + f"\n\nOther captures: {cap['windows_per_file_length_seed']} random windows per file, length and "
                   f"seed of the three other-skeletons walks (two 21-joint 60 fps, one Xia 31-joint 120 fps), read and "
                   f"put on Bandai's skeleton as `stylemotion-search query=<file>:<start>-<end>` does, against all "
                   f"{cap['database_takes']:,} Bandai takes ({cap['database_frames']:,} frames) with the command's "
                   f"defaults (E15, k = {cap['k']}"
                   + (f" growing to k_max = {cap['k_max']} by grow = {cap['grow']}, as chosen on validation"
                      + (f" over {cap['stable_for']} doublings" if cap.get("stable_for", 1) > 1 else "")
                      + (f", the LNG's {cap['refine']} best candidates re-ranked by exact DTW" if cap.get("refine")
                         else "")
                      + ("" if _rule(cap.get("defaults") or ()) == _rule([cap["grow"], cap["k_max"],
                                                                         cap.get("stable_for", 1),
                                                                         cap.get("refine", 0)]) else
                         f" (**the command's default at the run was {cap.get('defaults')}**)") if grown else "")
                   + f", top {cap['top']}); precision counts missing matches wrong, mean ± sd over seeds"
                   + ("; same best segment and ρ against exact subsequence DTW over all of Bandai (thesis steps), "
                      "no path counted as a miss, pooled over seeds; with verify: the same search, then exact DTW over "
                      "the takes whose lower bound does not exceed its best cost (`verify=true`, the command's "
                      "default), exact by construction and checked here; time: the growing search's seconds over "
                      "the fixed k's, timed back to back on each query" if grown else "") + f". {prov}")
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
    blocks = _growth_blocks(r, seeds, prov) if growth else {}
    return {**blocks, "headline": headline, "turns": turn_block, "ranks": rank_block, "k_choice": k_block,
            "lng": lng_block, "lng_still": still_block, "retrieval": ret_block, "captures": cap_block}
