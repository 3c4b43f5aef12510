"""Suite ``search_actors``: retrieval by content across actors inside Bandai (issue 24 item 6: search figures with
the query's actor out of the database beside the same-actor ones).

    python scripts/benchmarks.py run search_actors

Bandai dataset-2's three actors are told apart by the rest poses of their files
(:func:`stylemotion.datasets.actors.actor_groups`, suite ``actors``), and every actor performed every content.
Per left-out actor: the queries are one random 2 s window of each of that actor's **test** takes (Bandai's split,
``configs/data/bandai.yaml``), per seed; each is searched

* **cross-actor**: against the train + val takes of the *other* actors (the query's actor, its styles and its
  takes out of the database);
* **same-actor**: against the train + val takes of every actor (suite ``search``'s database: easier, the query's
  actor, content and style are in it),

with E15 features and 10 matches, by suite ``search``'s :func:`suites.search.retrieval_by_content`, searched two ways:

* **LNG, k = 1024**: the LNG alone at the command's first ``k`` (:data:`stylemotion.search.DEFAULT_K`, chosen on
  validation queries by suite ``search``), as suite ``search``'s retrieval figure;
* **the command's defaults**: as ``stylemotion-search`` searches (:class:`stylemotion.search.settings.SearchSettings`:
  ``k`` growing until the best match holds, re-ranking by exact DTW, the best match verified).

Precision@10 by content counts a missing match as a wrong one. Nothing is chosen here.
"""

from __future__ import annotations

import argparse
from typing import Any

from suites.common import (
    DATA_ROOT,
    bandai_split_settings,
    fmt,
    fmt_spread,
    md_table,
    provenance_line,
    take_split_record,
)
from suites.search import retrieval_by_content

DESCRIPTION = ("search retrieval by content across Bandai's actors: the query's actor out of the database, beside "
               "the same queries against every actor")
DEFAULT_SEEDS = (0, 1, 2)
#: The two databases of each left-out actor.
ARMS = ("cross_actor", "same_actor")
#: The two ways of searching (see the module doc).
SEARCHES = {"lng": "LNG, k = 1024", "command": "the command's defaults"}


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--query-s", type=float, default=2.0, help="query length, s (suite search's retrieval)")


def command_options() -> dict[str, Any]:
    """``stylemotion-search``'s defaults beyond ``k`` (:class:`~stylemotion.search.settings.SearchSettings`)."""
    from stylemotion.search.settings import SearchSettings

    d = SearchSettings()
    return {"k_max": d.k_max, "grow": d.grow, "stable_for": d.stable_for, "refine": d.refine, "verify": d.verify}


def run(args: argparse.Namespace, seeds: list[int]) -> dict[str, Any]:
    from stylemotion.datasets import TakeSet, load_dataset
    from stylemotion.datasets.actors import actor_groups
    from stylemotion.search import DEFAULT_K, FrameIndex

    bandai = load_dataset("bandai", root=str(DATA_ROOT / "bandai-namco-motion-2" / "data.zip"), workers=2)
    settings = bandai_split_settings()
    split = bandai.split(seed=settings["seed"], val_fraction=settings["val_fraction"],
                         test_fraction=settings["test_fraction"])
    groups = actor_groups(bandai.takes)
    database = split["train"] + split["val"]
    same = FrameIndex.build(TakeSet("bandai-train+val", database, bandai.fps), "E15")
    options = {"lng": {}, "command": command_options()}
    actors = []
    for g in sorted(groups.styles):
        styles = groups.styles[g]
        queries = [t for t in split["test"] if t.style in styles]
        others = [t for t in database if t.style not in styles]
        cross = FrameIndex.build(TakeSet(f"bandai-train+val-without-{'+'.join(styles)}", others, bandai.fps), "E15")
        indexes = {"cross_actor": cross, "same_actor": same}
        actors.append({"styles": styles, "query_takes": len(queries), "database_frames": {
            arm: int(index.database.num_frames) for arm, index in indexes.items()},
            **{arm: {way: retrieval_by_content(index, queries, seeds, args.query_s, DEFAULT_K, **options[way])
                     for way in SEARCHES} for arm, index in indexes.items()}})
        print(f"actor {'/'.join(styles)}: p@10 cross " + ", ".join(
            f"{way} {actors[-1]['cross_actor'][way]['all']['p10']['mean']:.3f}" for way in SEARCHES)
              + ", same " + ", ".join(f"{way} {actors[-1]['same_actor'][way]['all']['p10']['mean']:.3f}"
                                      for way in SEARCHES), flush=True)
    return {"k": DEFAULT_K, "command_options": options["command"], "features": "E15", "query_s": args.query_s,
            "actors": actors,
            "splits": {"kind": "Bandai's take split (configs/data/bandai.yaml); actors by rest pose",
                       "queries": "the left-out actor's test takes", "database": "train + val takes",
                       "parts": take_split_record(split, settings["seed"], settings["val_fraction"],
                                                  settings["test_fraction"])}}


def render(record: dict[str, Any]) -> dict[str, str]:
    r = record["results"]
    rows = []
    for actor in r["actors"]:
        for arm, text in (("cross_actor", "other actors only"), ("same_actor", "every actor (the query's too)")):
            for way, name in SEARCHES.items():
                ret = actor[arm][way]
                rows.append(["/".join(actor["styles"]), text, f"{actor['database_frames'][arm]:,}", name,
                             f"{ret['queries_per_seed']} of {actor['query_takes']}", fmt_spread(ret["all"]["p10"], 3),
                             fmt(ret["all"]["none"]["max"], 0), fmt_spread(ret["all"]["found_precision"], 3)])
    lowest = {way: min(actor["cross_actor"][way]["all"]["p10"]["mean"] for actor in r["actors"]) for way in SEARCHES}
    contents = sorted(r["actors"][0]["cross_actor"]["command"]["by_content"])
    content_rows = [[c, *(fmt_spread(actor[arm]["command"]["by_content"][c]["p10"], 2) for actor in r["actors"]
                          for arm in ARMS)] for c in contents]
    by_content = md_table(["content", *(f"{'/'.join(actor['styles'])}: {arm.replace('_', '-')}"
                                        for actor in r["actors"] for arm in ARMS)], content_rows)
    opts = r["command_options"]
    n = len(record.get("seeds") or [])
    text = (md_table(["left-out actor (styles)", "database", "database frames", "search",
                      "queries per seed (test takes ≥ the query length, of all)",
                      "precision@10", "queries without a match (max per seed)", "precision of the matches found"],
                     rows)
            + f"\n\nOne random {fmt(r['query_s'], 0)} s window of each of the actor's test takes per seed ({n} "
            f"seeds), E15 features, 10 matches; LNG: k = {r['k']} alone (chosen on validation by suite `search`); "
            f"the command's defaults: k from {r['k']} growing ({opts['grow']}) up to {opts['k_max']:,}, refine "
            f"{opts['refine']}, verify {str(opts['verify']).lower()}. Precision@10 by content counts a missing match "
            f"as a wrong one; mean ± sd over seeds. Lowest cross-actor precision@10 of an actor: "
            + ", ".join(f"{SEARCHES[way]} {fmt(v, 3)}" for way, v in lowest.items())
            + f". {provenance_line(record)}\n\nPrecision@10 by content with the command's defaults, mean ± sd over "
            f"seeds.\n\n{by_content}")
    return {"headline": text}
